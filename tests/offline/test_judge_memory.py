"""How a passive judgement's memory grows with the recording (issue 22: one hour of a busy 1
MHz capture judged in bounded memory). Since branch window15 no event is held as an object
and no whole view is cut; since memory17 the loaded recording's compact store and the
decode's per-character bit-rate errors are written to a temporary file a chunk at a time
(``conformance.event_store``); since memory19 a sensor's run holds no event as an object
either: what still grows is each sensor's records (their positions, texts and derived
values) while its run holds them and the bus pass's few bytes a window. What is held to a
figure here is the growth: the peak resident memory of ``sdi12-conform judge`` over a busy
bus (ten sensors polled back to back, ``benchmarks/capture_decode.busy_bus``) may grow by at
most :data:`MB_PER_MINUTE` per minute of capture.

Measured by this test on the project's 2-core machine (the child's own peak, ``VmHWM``;
glibc's malloc arenas capped at one; the lower of two short runs), issue 22's ninth round:
2 minutes 75 MB, 14 minutes 96 MB, so 1.73 and 1.76 MB a minute in two runs; fef5b8a, the
tree before it, 76 and 102-104 MB, 2.19 and 2.32 MB a minute, which this limit fails.
Earlier rounds read ``ru_maxrss``, which held this test's own peak (below): b999a88 2.5 MB
a minute, 57aa7db 3.8. The cap makes the figure repeatable: without it the decode's
read-ahead thread gets an arena of its own, and the short run's peak was 75 or 81 MB from
one run to the next; with it, runs of one length differ by 3 MB at most (0.25 MB a minute
over the 12 minutes between the two lengths), and the limit stands 0.4 MB a minute (5 MB)
above this tree's figure, so that noise cannot fail CI. The short one is judged twice and
its lower peak taken (the steeper slope).

Issue 22's tenth round (the view's transmissions a third smaller, the whole-run timing index
built without an array of every interval): 2 minutes 69.2-69.5 MB, 14 minutes 87.8-92.2 in
single runs, so 1.54-1.89 MB a minute; 689a849, the tree before, 69.3-70.0 and 91.3-94.6,
1.81-2.10. So the long capture is judged twice too now, and the lower of each pair taken:
1.56, 1.58 and 1.61 MB a minute in three runs of this test, 689a849 1.77, 1.77 and 2.10,
which a limit of 1.75 would fail by a thin
margin (0.02 MB a minute in its best runs): the limit is set above CI's noise instead.

Issue 22's eleventh round (each run's cyclic garbage collected before the next,
``tests/offline/test_runs_garbage_freed.py``): 2 minutes 61.8-62.5 MB, 14 minutes 80.6-81.1,
the lower of each pair 1.57 MB a minute; base-s44, the tree before, 69.1-69.2 and 88.2-91.1,
1.59. The cut lowers both lengths alike (7-8 MB), so the slope, which this test holds, is
unchanged and the limit stays. A decode's freed heap pages given back
(``tests/capture/test_heap_trim.py``) took away a second mode of this figure: the same
14-minute capture peaked at 80.6 or 87.8 MB by chance (the slope 1.57 or ~2.2, which failed
this test once in a loaded run), now 80.5-81.7 in 10 runs and 61.4-61.9 at 2 minutes.

Issue 22's twelfth round (each sensor's records rebuilt alone, none held whole): 2 minutes
61.9 MB, 14 minutes 80.1 (1.51 MB a minute); base-s45, the tree before, 62.0 and 80.8-82.0
(1.57). The cut grows with the capture (9 MB at 60 minutes) but is 1-2 MB at 14, inside
this test's noise, so the limit stays: no bound is claimed yet.

Issue 22's thirteenth round (no whole-run list of segments held by a bus's judgement,
``tests/offline/test_segments_per_sensor.py``): 10 minutes 72.4-72.5 MB, 30 minutes
101.8-102.4, 60 minutes 148.1-148.6; base-s46, the tree before, 73.6-73.9, 104.8-108.8 and
155.4-157.0 (1.52 against 1.65 MB a minute between 10 and 60). The cut is 1-2 MB at 14
minutes, inside this test's noise: the limit stays.

Issue 22's round on branch ``window10`` (R-7.0-12's observations in arrays and a passive
run's gaps judged in parts, a recording in time order read without a sorted copy, the
evidence positions without an array of every start, the heap's freed pages given back once
the recording is loaded): 2 minutes 61.7 MB, 14 minutes 76.8, so 1.26 MB a minute; base-s57,
the tree before, 62.4 and 79.2 in the same run, 1.40 (10, 30, 60 minutes: 71.9, 97.0, 135.2
against 73.4, 103.0, 150.9). The limit comes down to 1.65, the measured figure and the 0.4
MB a minute of noise this test allows. Still not bounded: the events and their view are
held whole.

Issue 22's round on branch ``window11`` (a transmission's derived values kept without a
tuple each, its text interned; a loaded capture's problems its characters' alone): 2
minutes 61.8 MB, 14 minutes 75.6, so 1.15 MB a minute; base-s58, the tree before, 62.4 and
77.8 in the same run, 1.28. The limit comes down to 1.55, the measured figure and the same
0.4 of noise. Still not bounded: the events and their view are held whole.

Issue 22's round on branch ``window15`` (the events in a compact store the decoder appends
to, the windows read again from it, the reports' whole-run search read window by window, no
whole view cut): 2 minutes 60.3-61.0 MB, 14 minutes 64.2-64.5, the lower of each 0.33 MB a
minute; base-s62, the tree before, 62.4-62.8 and 76.9-76.9, 1.21, in the same alternated
runs. The limit comes down to 0.75, the measured figure and the same 0.4 of noise, which
base-s62 fails by 0.46 MB a minute.

Issue 22's round on branch ``memory17`` (the store's full chunks written to a temporary file
and read back a block at a time, ``conformance.event_store.Column``; the decode's bit-rate
errors such a column; the decode-quality notes' errors a tally of distinct values,
``RateTally``): 2 minutes 60.8-60.9 MB, 14 minutes 63.2-63.3, the lower of each 0.20 MB a
minute; base-s64, the tree before, 60.3-60.3 and 64.7-64.7, 0.36, in the same alternated
runs. The limit comes down to 0.60, the measured figure and the same 0.4 of noise (base-s64
passes it: this round's cuts have their own tests, ``tests/test_event_store.py``'s spilled
chunks and ``tests/offline/test_rate_tally.py``). Between 10 and 60 minutes
(``benchmarks/compare.py --only capture``, base-s64 and this tree alternated, two runs each,
twice): 63 and 70-71 MB against 63 and 78-79, 0.16 against 0.31 MB a minute, the hour's CPU
14.8 and 13.7 s against 14.7 and 13.1 (0.99x, 0.96x; 1.02x and 0.94x at 10 minutes). What
still grows: each sensor's exchanges and measurements, held for its run (its tenth of the
events made as objects, ~150 bytes each: 4.3 MB traced at an hour against 0.9 at 10
minutes), and the bus pass's bounds, sides and windows (~40 bytes a window and 1 an event).

Issue 22's round on branch ``memory18`` (the bus pass's per-window numbers 4 bytes each, its
events' inferred sides an ``event_store.Column`` written out a chunk at a time,
``tests/offline/test_bus_pass_compact.py``): 2 minutes 60.3-60.6 MB, 14 minutes 63.0-63.5,
the lower of each 0.225 and 0.234 MB a minute in two runs; base-s65, the tree before,
60.4-60.5 and 63.4-63.6, 0.252 and 0.250, in the same alternated runs. The cut is 0.2 MB at
14 minutes, inside this test's noise (memory17 read base-s65's code at 0.20): the limit
stays 0.60 (the measured figure and the same 0.4 of noise would be 0.63). Between 10 and 60
minutes the bus pass's held bytes went from 0.85 MB to 0.28 at an hour (0.14 to 0.10 at 10
minutes). What still grows (traced at 60 against 10 minutes, at the last sensor's run): the
sensor's exchanges and measurements, 5.2 MB more (its 35,000 events as objects, 4.3 MB of
them, 150 bytes each with their two stamps; the attempts, replies and exchanges 0.9). The
loaded state traces the same bytes at both lengths (19.7 MB in pymalloc blocks), but the
decode leaves 4 more of pymalloc's 1 MiB arenas held by a few long-lived blocks (310 empty
pools against 77, RSS 3 MB higher); the first sensor's records fill those pools (75 empty at
both lengths after its run), so they add nothing to the peak while the records are held as
objects: ``malloc_trim`` after every run was measured too (no lower peak: those pools are
not malloc's).

Issue 22's round on branch ``memory19`` (a sensor pass's records hold their events as
positions into the loaded store, ``event_store.StoredEvents`` and ``offline.stored_records``;
the reply-start fold's evidence lines hold their few values, not the segments,
``judges.wire._StartWhere``; ``tests/offline/test_records_stored.py``): 2 minutes 60.3-60.9
MB, 14 minutes 62.3-62.4, the lower of each 0.167 MB a minute; base-s66, the tree before,
60.9-61.0 and 64.0-64.0, 0.255, in the same alternated runs. What memory18 traced as the
records' events was held twice: by the records and by ``ResponseStarts``' observations,
each of which kept its reply's segment for an evidence line made on demand (5 MB of events
at an hour); either cut alone left the hour's peak at 70-71 MB, both 65.6 (base-s66 71.2;
10 minutes 63.0 against 63.7, ``benchmarks/judge_phases.py``). The limit comes down to
0.57, the measured figure and the same 0.4 of noise (base-s66 passes it: the cuts have
their own tests, which fail on it).
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

MB_PER_MINUTE = 0.57  # 0.167 measured on branch memory19 (base-s66 0.255), + 0.4 of noise.
# Before: 0.60 (memory17 0.20, base-s64 0.36; memory18 0.225-0.234, base-s65 0.250);
# 0.75 (window15 0.33, base-s62 1.21); 1.55 (window11 1.15, base-s58 1.28); 1.65
# (window10 1.26, base-s57 1.40); 1.90,
# 1.56-1.61 measured (issue 22's tenth round), 689a849 1.77-2.10; the lower of two runs of
# each length (one long run alone varied by 4.4 MB, 0.37 a minute). Not 1.75, which fails
# 689a849's best runs by 0.02 only: too thin for a CI under load. The rounds' cuts have
# their own tests that fail on the tree before (tests/view/test_view_memory.py,
# test_timing_diagram's long index, test_loaded_problems, tests/test_event_store.py,
# test_windowed_transmissions); this one guards the slope against regressions.
SHORT, LONG = 2.0, 14.0  # minutes

#: the benchmark that makes the busy bus and judges a capture in a child process, which prints
#: its own peak resident memory: the high-water mark of its own address space (``VmHWM``),
#: not ``ru_maxrss``, which Linux carries over an exec from the address space before it: a
#: child started by vfork (as subprocess does) reported this test's own peak (the busy bus it
#: had just generated: 104 MB at 14 minutes whatever the judgement took, and 75 at 2)
BENCH = Path(__file__).parents[2] / "benchmarks" / "capture_decode.py"


def busy_capture(path: Path, minutes: float) -> None:
    """The benchmark's busy bus (break, ``aD0!``, an 18-character reply, addresses 0-9),
    written as a 1 MHz sigrok session."""
    spec = importlib.util.spec_from_file_location("capture_decode_bench", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    from conformance.capture import export_events

    export_events(module.busy_bus(minutes * 60), str(path), sample_rate=1e6)


def judged_peak(capture: Path, reports: Path) -> float:
    env = {**os.environ, "MALLOC_ARENA_MAX": "1"}  # a repeatable peak (see above)
    done = subprocess.run(
        [sys.executable, str(BENCH), "--judge-only", str(capture), str(reports)],
        capture_output=True, text=True, check=True, env=env,
    )  # fmt: skip
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["code"] == 2, done.stdout[-2000:]  # incomplete: no aI!, no measurement seen
    assert len([p for p in reports.iterdir() if p.is_dir()]) == 11  # ten sensors, the recorder
    return float(found["peak_mb"])


def growth_of(short: float, long: float) -> float:
    """MB a minute of capture between the two lengths' peaks."""
    return (long - short) / (LONG - SHORT)


def lowest_long_peak(short: float, judge_long: Callable[[int], float], times: int = 2) -> float:
    """The lower of ``times`` judgements of the long capture, judged only while they are
    needed: once one of them is within :data:`MB_PER_MINUTE`, the lower of all of them is
    too (it is at most that one), so the test's verdict is the one the lower of all would
    give. The short capture is not cut like this: its lower peak makes the slope steeper.
    A passing run judges the 14 minutes once (~7 s of CPU in CI, issue 22's ci9 round)."""
    lowest = judge_long(0)
    for i in range(1, times):
        if growth_of(short, lowest) <= MB_PER_MINUTE:
            break
        lowest = min(lowest, judge_long(i))
    return lowest


@pytest.mark.slow
def test_peak_memory_grows_at_most_its_figure_with_the_capture(tmp_path: Path):
    peaks = {}
    for minutes in (SHORT, LONG):
        busy_capture(tmp_path / f"busy{minutes:g}.sr", minutes)

    def judged(minutes: float, i: int) -> float:
        return judged_peak(tmp_path / f"busy{minutes:g}.sr", tmp_path / f"reports{minutes:g}-{i}")

    peaks[SHORT] = min(judged(SHORT, i) for i in range(2))
    peaks[LONG] = lowest_long_peak(peaks[SHORT], lambda i: judged(LONG, i))
    growth = growth_of(peaks[SHORT], peaks[LONG])
    assert growth <= MB_PER_MINUTE, (
        f"peak RSS {peaks[SHORT]:.0f} MB at {SHORT:g} min, {peaks[LONG]:.0f} MB at {LONG:g} "
        f"min: {growth:.2f} MB a minute of capture, more than {MB_PER_MINUTE}"
    )


@given(
    short=st.floats(40, 120),
    longs=st.lists(st.floats(40, 160), min_size=1, max_size=4),
)
def test_judging_the_long_capture_lazily_gives_the_verdict_of_all_its_runs(short, longs):
    """:func:`lowest_long_peak`'s verdict is the lower of every judgement's (the test's
    verdict before the ci9 round, every run judged), and it judges past the first only when
    that one is over the limit."""
    judged: list[int] = []

    def judge(i: int) -> float:
        judged.append(i)
        return longs[i]

    lazy = lowest_long_peak(short, judge, times=len(longs))
    every = min(longs)
    assert (growth_of(short, lazy) <= MB_PER_MINUTE) == (growth_of(short, every) <= MB_PER_MINUTE)
    assert judged == list(range(len(judged)))  # in order, none twice
    assert (len(judged) == 1) == (growth_of(short, longs[0]) <= MB_PER_MINUTE or len(longs) == 1)
