"""A capture cut into windows (issue 22's windowed judge, ``conformance.view.windows``),
checked against the whole recording and timed.

    python benchmarks/capture_windows.py CAPTURE [CAPTURE ...]

For each capture: its events decoded, the whole view and records, where windows may begin,
then each window's view read from its own events alone (its transmissions, breaks,
characters, unanswerable and undirected characters must be the whole view's, the same
objects), the records rebuilt window by window with the CRC expectation carried (the whole
bus's and each sensor's alone: every exchange's attempts and every measurement's data must
be the whole run's), and the windows cut as the events come (``stream_windows``: the same
events in the same windows). Then, over the streamed windows, each window's view read and
let go (``tests/support/windowed_judges.py``): the sensors on the bus (``SensorsOn``: the
same addresses and identifications), each sensor's decode-quality note (``Quality``: the
same counts, min, median and max), each sensor's reply timing and framing
(``ResponseStarts``, ``ReplyGaps``, ``ReplyBitRate``, ``Framing``), the recorder's wire
rules (``Breaks``, ``BreakRules``, ``CommandText``, ``CharacterGaps``, ``CommandBitRate``)
and its measurement, retry and address rules (``ObservedMeasurements``, ``Retries``,
``Addresses``): every finding, detail and evidence must be the whole view's. Prints the
windows, the largest, and the CPU of the whole cut, of the streamed one and of the
recorder's rules judged both ways; exits 1 on any difference. The same
checks as ``tests/view/test_windows.py``, ``tests/offline/test_sensors_on_windowed.py``,
``tests/offline/test_decode_quality_windowed.py``,
``tests/judges/test_windowed_sensor_timing.py``, ``tests/judges/test_windowed_framing.py`` and
``tests/judges/recorder/test_windowed_wire.py``,
``test_windowed_observed_measurements.py``, ``test_windowed_retries.py`` and
``test_windowed_addresses.py`` (the fields compared are
``tests/support/records_alike.py``'s), on a recording too long for a test.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from conformance.capture import decode_capture
from conformance.offline.heard import BusSensor, SensorsOn, sensors_on
from conformance.transcript import Event
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
from tests.support.windowed_judges import (  # noqa: E402
    qualities,
    qualities_windowed,
    recorder_measurements,
    recorder_measurements_windowed,
    recorder_wire,
    recorder_wire_windowed,
    sensor_timing,
    sensor_timing_windowed,
)


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
    cpu = time.process_time()
    expected = recorder_wire(whole, u)
    judge_cpu = time.process_time() - cpu
    cpu = time.process_time()
    found = recorder_wire_windowed(stream_windows(iter(events), uncertainty=u), u)
    windowed_cpu = time.process_time() - cpu
    if found != expected:
        wrong.append("recorder wire findings")
    cpu = time.process_time()
    expected = recorder_measurements(whole, u)
    measure_cpu = time.process_time() - cpu
    cpu = time.process_time()
    found = recorder_measurements_windowed(stream_windows(iter(events), uncertainty=u), u)
    measure_windowed_cpu = time.process_time() - cpu
    if found != expected:
        wrong.append("recorder measurement, retry and address findings")
    if sensors_streamed(events, u) != sensors_on(rebuild_records(whole, uncertainty=u).exchanges):
        wrong.append("sensors on the bus")
    if sensor_timing_windowed(stream_windows(iter(events), uncertainty=u), u) != sensor_timing(
        whole, u
    ):
        wrong.append("sensors' reply timing and framing findings")
    streamed_notes = qualities_windowed(decoded, stream_windows(iter(events), uncertainty=u), u)
    if streamed_notes != qualities(decoded, events, u):
        wrong.append("decode-quality notes")
    print(
        f"{path}: {len(events)} events, {len(whole.transmissions)} transmissions, "
        f"{len(windows)} windows (largest {max(map(len, windows), default=0)} events); "
        f"whole cut {whole_cpu:.2f} s CPU, streamed {stream_cpu:.2f} s; recorder wire rules "
        f"judged whole {judge_cpu:.2f} s, streamed and windowed {windowed_cpu:.2f} s; its "
        f"measurement, retry and address rules whole {measure_cpu:.2f} s, streamed and "
        f"windowed {measure_windowed_cpu:.2f} s; "
        + (
            "differs: " + ", ".join(wrong)
            if wrong
            else "views, records, streamed windows, sensors, decode-quality notes, sensors' "
            "reply timing and framing, recorder wire, measurement, retry and address findings "
            "equal"
        )
    )
    return not wrong


def sensors_streamed(events: list[Event], u: float) -> list[BusSensor]:
    """The sensors on the bus found window by window as the windows are cut (each window's
    records rebuilt alone, the CRC expectations carried), each window let go."""
    found, carried = SensorsOn(), {}
    for window in stream_windows(iter(events), uncertainty=u):
        found.add(rebuild_records(read_view(window), uncertainty=u, carried=carried).exchanges)
    return found.sensors()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("captures", nargs="+")
    args = p.parse_args(argv)
    return 0 if all([check(c) for c in args.captures]) else 1


if __name__ == "__main__":
    sys.exit(main())
