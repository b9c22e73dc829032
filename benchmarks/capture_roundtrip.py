"""CPU of a fault-matrix row's capture round trip (issue 22), split as the matrix pays it.

One simulated run (``--port``, default ``sim://?faults=wrong-crc``), then ``--repeat`` times,
every cache cleared and the run's transcript written again as the run writes it: reading that
transcript back, exporting it as .sr with the tool's TX channel, decoding the capture, the
whole non-replay part of :func:`conformance.matrices.roundtrip.judged_through_capture`
(the replay stubbed out) and :func:`conformance.matrices.roundtrip.capture_changes` itself.
Medians of CPU seconds
(``time.process_time``) as one JSON line, so two checkouts compare side by side::

    PYTHONPATH=OLD python benchmarks/capture_roundtrip.py --tag old
    PYTHONPATH=NEW python benchmarks/capture_roundtrip.py --tag new
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--port", default="sim://?faults=wrong-crc")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--tag", default="")
    args = p.parse_args(argv)

    import conformance.capture.decode as decode_mod
    import conformance.matrices.roundtrip as rt
    import conformance.replay.recording as rec
    from conformance.capture.decode import decode_capture
    from conformance.capture.export import export_events
    from conformance.conduct import run_into
    from conformance.transcript import EventKind

    base = Path(tempfile.mkdtemp(prefix="sdi12-bench-"))
    live = base / "live"
    data = run_into(live, args.port)
    events = rec.read_recording(live).events

    def fresh() -> None:
        decode_mod._LAST = None
        rec._READ.clear()
        rec.write_recording(live / "transcript.jsonl", events)

    def replay_stub(*_a, **_k) -> dict:
        return {"run": {"link": {"kind": "replay"}}, "requirements": []}

    cpu: dict[str, list[float]] = {
        k: [] for k in ("read", "export", "decode", "nonreplay", "whole")
    }
    changes: tuple[str, ...] = ()
    run_replay = rt.run_into
    for i in range(args.repeat):
        fresh()
        t = time.process_time()
        recording = rec.read_recording(live)
        cpu["read"].append(time.process_time() - t)
        notes = [e for e in recording.events if e.kind is EventKind.NOTE]
        capture = base / f"run{i}.sr"
        t = time.process_time()
        export_events(recording.events, str(capture), "sr", tool_channel=True, notes=notes)
        cpu["export"].append(time.process_time() - t)
        fresh()
        t = time.process_time()
        decode_capture(str(capture), tx_channel="TOOL_TX")
        cpu["decode"].append(time.process_time() - t)
        fresh()
        rt.run_into = replay_stub
        try:
            t = time.process_time()
            rt.judged_through_capture(live, base / f"stub{i}")
            cpu["nonreplay"].append(time.process_time() - t)
        finally:
            rt.run_into = run_replay
        fresh()
        t = time.process_time()
        changes = rt.capture_changes(live, data, base / f"whole{i}")
        cpu["whole"].append(time.process_time() - t)
    medians = {k: round(statistics.median(v), 3) for k, v in cpu.items()}
    print(
        json.dumps(
            {"tag": args.tag, "port": args.port, "events": len(events), "changes": list(changes)}
            | medians
        )
    )
    return 0 if not changes else 1


if __name__ == "__main__":
    raise SystemExit(main())
