"""A capture cut into windows (issue 22's windowed judge, ``conformance.view.windows``),
checked against the whole recording and timed.

    python benchmarks/capture_windows.py CAPTURE [CAPTURE ...]

For each capture: its events decoded, the whole view and records, where windows may begin,
then each window's view read from its own events alone (its transmissions, breaks,
characters, unanswerable and undirected characters must be the whole view's, the same
objects), the records rebuilt window by window with the CRC expectation carried (the whole
bus's and each sensor's alone: every exchange's attempts and every measurement's data must
be the whole run's), and the windows cut as the events come (``stream_windows``: the same
events in the same windows). Prints the windows, the largest, and the CPU of the whole cut
and of the streamed one; exits 1 on any difference. The same checks as
``tests/view/test_windows.py`` (the fields compared are ``tests/support/records_alike.py``'s),
on a recording too long for a test.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from conformance.capture import decode_capture
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view
from conformance.view.windows import (
    rebuild_windowed,
    stream_windows,
    window_events,
    window_starts,
)

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the tree's tests.support
from tests.support.records_alike import records_fields, view_differences  # noqa: E402


def check(path: str) -> bool:
    decoded = decode_capture(path)
    events, u = decoded.events, decoded.uncertainty_s
    cpu = time.process_time()
    whole = read_view(events)
    starts = window_starts(whole, rebuild_records(whole, uncertainty=u))
    windows = list(window_events(events, whole, starts))
    whole_cpu = time.process_time() - cpu
    wrong = view_differences(whole, [read_view(w) for w in windows])
    for only in (None, *sorted({t.text[:1] for t in whole.transmissions})):
        expected = records_fields([rebuild_records(whole, uncertainty=u, only=only)])
        if (
            records_fields(list(rebuild_windowed(events, whole, uncertainty=u, only=only)))
            != expected
        ):
            wrong.append(f"records of {only or 'the bus'}")
    cpu = time.process_time()
    streamed = list(stream_windows(iter(events), uncertainty=u))
    stream_cpu = time.process_time() - cpu
    if [list(map(id, w)) for w in streamed] != [list(map(id, w)) for w in windows]:
        wrong.append("streamed windows")
    print(
        f"{path}: {len(events)} events, {len(whole.transmissions)} transmissions, "
        f"{len(windows)} windows (largest {max(map(len, windows), default=0)} events); "
        f"whole cut {whole_cpu:.2f} s CPU, streamed {stream_cpu:.2f} s; "
        + ("differs: " + ", ".join(wrong) if wrong else "views, records and streamed windows equal")
    )
    return not wrong


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("captures", nargs="+")
    args = p.parse_args(argv)
    return 0 if all([check(c) for c in args.captures]) else 1


if __name__ == "__main__":
    sys.exit(main())
