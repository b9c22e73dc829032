"""A passive judgement gives the C heap's freed pages back once the recording is loaded
(issue 22): after the view's cut (its transients, the lists of every event ``no_traffic``
made meanwhile, are let go) and after the pre-scans of the sensors on the bus, before the
first run. The runs' peak then does not sit on the loading's freed pages (an hour's busy
capture: RSS 134 -> 121 MB before the first sensor's run); and ``no_traffic`` holds no list
of the events while the view is cut. What is judged does not change: only pages malloc
counts free are returned (``capture/heap.py``)."""

from __future__ import annotations

import contextlib
import importlib.util
from pathlib import Path

from conformance.capture import export_events
from conformance.cli import main
from conformance.commands import passive
from conformance.offline import heard

BENCH = Path(__file__).parents[2] / "benchmarks" / "capture_decode.py"


def _busy_capture(path: Path, seconds: float) -> None:
    spec = importlib.util.spec_from_file_location("capture_decode_bench", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    export_events(module.busy_bus(seconds), str(path), sample_rate=1e6)


def test_freed_pages_are_given_back_after_the_view_and_the_bus_prescan(tmp_path, monkeypatch):
    capture = tmp_path / "busy.sr"
    _busy_capture(capture, 3.0)
    said: list[str] = []
    settle = heard.settle_bus

    def settled(link):  # type: ignore[no-untyped-def]
        assert "_bus_windows" in link.__dict__  # the bus pass was made before (no_traffic)
        said.append("settle")
        settle(link)

    def given_back() -> bool:
        said.append("give back")
        return True

    def ran(job, port, args, console):  # type: ignore[no-untyped-def]
        said.append("run")
        raise SystemExit(0)

    monkeypatch.setattr(heard, "settle_bus", settled)
    monkeypatch.setattr(passive, "give_back_freed_heap", given_back)
    monkeypatch.setattr(passive, "_run_role", ran)
    with contextlib.suppress(SystemExit):
        main(["judge", str(capture), "--report-dir", str(tmp_path / "reports")])
    assert said[:4] == ["give back", "settle", "give back", "run"]
