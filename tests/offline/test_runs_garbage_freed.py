"""A passive judgement of a bus (one run per sensor, then the recorder's) frees each run's
cyclic garbage before the next run (issue 22, bounded memory). Each run's pytest objects
are cyclic garbage once it ends; ``gc_pace.slow_down`` froze them with everything else at
the next run's start, so none was collected: about 0.85 MB a run held to the end, the peak
of an 11-run judgement of a busy bus 7-8 MB higher (``benchmarks/capture_decode.py
--judge-only``, glibc's arenas capped at one: 2 minutes 69.1 MB against 61.7, 10 minutes
82.4 against 74.6, 14 minutes 92.0 against 80.6; from 30 minutes on the peak comes in the
first sensor's run, before any run's garbage exists: 30 minutes 113.3 against 111.9, 60
168.0 against 166.2)."""

from __future__ import annotations

import gc
from pathlib import Path

from conformance import gc_pace
from conformance.cli import main

#: cyclic garbage a judgement may leave: the ten sensors' and the recorder's runs left 57,800
#: objects together before (some 5,000 a run); what is left after the last collection (the
#: recording let go, the console's lines about the sensors) is some 600
LEFT_AT_MOST = 3000


def test_R_issue22_no_run_garbage_left_after_a_bus_is_judged(capture: Path, tmp_path: Path):
    """The collector is off around the judgement (as a whole ``sdi12-conform`` process has
    it outside its runs), so only what the judgement itself collects is gone."""
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        assert gc.get_freeze_count() == 0  # nothing frozen: the judgement may freeze
        code = main(["judge", str(capture), "--report-dir", str(tmp_path / "reports")])
        left = gc.collect()
    finally:
        if was_enabled:
            gc.enable()
    assert code == 2  # incomplete: no aI!, no measurement seen
    assert len(list((tmp_path / "reports").glob("*/verdicts.json"))) == 11
    assert gc.get_freeze_count() == 0  # what was frozen for the runs is thawed
    assert left <= LEFT_AT_MOST, f"{left} objects of cyclic garbage left by the runs"


def test_nothing_frozen_or_collected_when_something_else_froze_objects():
    """A caller's frozen objects stay frozen (a thaw would thaw them too), and no collection
    is made, which would walk every object loaded. The automatic collector is off while the
    collections are counted: one of its own (under xdist, a worker's other tests left enough
    garbage) was counted as the judgement's once."""
    was_enabled = gc.isenabled()
    gc.disable()
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        with gc_pace.runs_over_held_data() as collect:
            assert gc.get_freeze_count() == frozen
            before = gc.get_stats()[2]["collections"]
            collect()
            assert gc.get_stats()[2]["collections"] == before
        assert gc.get_freeze_count() == frozen
    finally:
        gc.unfreeze()
        if was_enabled:
            gc.enable()
