"""The recorder's wire rules judged a window at a time (issue 22's windowed judge): each
window's view, read from its own events alone (``view.windows``), added in order to the
judges of ``testcases/passive/test_recorder_7_wire.py`` (``Breaks``, ``BreakRules``,
``CommandText``, ``CharacterGaps``, ``CommandBitRate``) gives the findings of the whole
recording's view, detail for detail and evidence for evidence.

The cases a wrong merge gets wrong: a count over the whole run (R-7.0-17's "all N commands",
R-7.0-13's gaps, R-4.1-01's spacings), a worst value in an early window (R-7.0-02's short
break), the first few quoted and the count of R-7.0-01's leaning gaps across windows, and
what one window leaves the next (R-7.1-01's service request in the window before its aD0!,
R-7.0-17's marking before a command sent without a break timed from the window before)."""

from __future__ import annotations

from dataclasses import replace

from conformance.protocol.commands import parse_command
from conformance.transcript import Event, EventKind
from conformance.verdicts import Finding, Verdict
from conformance.view.segments import TranscriptView, read_view
from conformance.view.windows import stream_windows, window_events, window_starts
from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors, concurrent_round
from tests.support.windowed_judges import at_every_break, recorder_wire, recorder_wire_windowed

U = 1e-6  # a 1 MHz capture's stamps


def _whole(view: TranscriptView) -> list[Finding]:
    return recorder_wire(view, U)


def _windowed(windows: list[list[Event]]) -> list[Finding]:
    return recorder_wire_windowed(windows, U)


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def _round() -> list[Event]:
    """Each sensor identified, a concurrent round, each identified again."""
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES:
        recorder.identify(a)
    concurrent_round(recorder)
    for a in ADDRESSES:
        recorder.identify(a)
    return as_heard(bus)


def test_windows_of_a_bus_round_judge_as_the_whole_recording():
    events = _round()
    whole = read_view(events)
    windows = list(window_events(events, whole, window_starts(whole)))
    assert len(windows) >= 7
    streamed = list(stream_windows(iter(sorted(events, key=lambda e: e.start)), uncertainty=U))
    assert _windowed(windows) == _whole(whole)
    assert _windowed(streamed) == _whole(whole)


def test_every_command_of_every_window_is_counted():
    """R-7.0-17's PASS counts the commands of every window (each identify one of its own)."""
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES * 3:
        recorder.identify(a)
    events = as_heard(bus)
    whole = read_view(events)
    windows = list(window_events(events, whole, window_starts(whole)))
    assert len(windows) == 9
    got = _by_rule(_windowed(windows))["R-7.0-17"]
    assert got == _by_rule(_whole(whole))["R-7.0-17"]
    assert got.detail == "all 9 commands were sent after a break"


def test_a_short_break_in_the_first_window_is_the_whole_runs_worst():
    events = _round()
    first = next(e for e in events if e.kind is EventKind.BREAK)
    events = [replace(e, end=e.start + 0.010) if e is first else e for e in events]
    whole = read_view(events)
    expected = _by_rule(_whole(whole))["R-7.0-02"]
    assert expected.verdict is Verdict.FAIL
    assert _by_rule(_windowed(at_every_break(events)))["R-7.0-02"] == expected


def test_leaning_gaps_in_two_windows_are_counted_together():
    """R-7.0-01: a 1.80 ms gap before the '!' of the first and the last command (each in a
    window of its own): the finding quotes both and counts two."""
    events = sorted(_round(), key=lambda e: e.start)
    whole = read_view(events)
    bangs = [t.chars[-1] for t in (whole.transmissions[0], whole.transmissions[-1])]
    moved = {id(b): replace(b, start=b.start + 0.0018, end=b.end + 0.0018) for b in bangs}
    events = [moved.get(id(e), e) for e in events]
    whole = read_view(events)
    expected = _by_rule(_whole(whole))
    assert expected["R-7.0-01"].verdict is Verdict.FAIL
    assert "(2 such gap(s))" in expected["R-7.0-01"].detail
    got = _by_rule(_windowed(at_every_break(events)))
    assert got["R-7.0-01"] == expected["R-7.0-01"]
    assert got["R-7.0-13"] == expected["R-7.0-13"]
    assert got["R-4.1-01"] == expected["R-4.1-01"]


def _service_request_then_data(*, force_break: bool) -> list[Event]:
    """0M! answered with a service request, then its aD0! (with a break or not)."""
    bus, recorder = bus_of_sensors()
    recorder.identify("0")
    m = recorder.measure(parse_command("0M!"), collect=False)
    recorder.collect(m, force_break=force_break)
    recorder.identify("1")
    return sorted(as_heard(bus), key=lambda e: e.start)


def test_a_service_request_in_the_window_before_its_d0_is_carried():
    """R-7.1-01: the aD0! after a break opens a window of its own here; whether it follows
    a service request is read from the transmission the window before ended with."""
    events = _service_request_then_data(force_break=True)
    expected = _by_rule(_whole(read_view(events)))["R-7.1-01"]
    assert expected.verdict is Verdict.PASS
    assert "after the service request" in expected.detail
    windows = at_every_break(events)
    assert any(read_view(w).transmissions[0].text == "0D0!" for w in windows)
    assert _by_rule(_windowed(windows))["R-7.1-01"] == expected


def test_a_command_without_a_break_first_in_its_window_is_timed_from_the_window_before():
    """R-7.0-17: aD0! sent without a break 9 ms after the service request; cut right before
    it, its marking is timed from the end of the window before (without the carry the
    quiet is infinite and it FAILs), and it is still the same sensor's command."""
    events = _service_request_then_data(force_break=False)
    whole = read_view(events)
    d0 = next(t for t in whole.transmissions if t.text == "0D0!")
    assert d0.break_event is None
    expected = _by_rule(_whole(whole))
    assert expected["R-7.0-17"].verdict is Verdict.PASS
    cut = events.index(d0.chars[0])
    got = _by_rule(_windowed([events[:cut], events[cut:]]))
    assert read_view(events[cut:]).transmissions[0].text == "0D0!"
    assert got["R-7.0-17"] == expected["R-7.0-17"]
    assert got["R-7.1-01"] == expected["R-7.1-01"]


def test_the_shortest_command_spacing_of_an_early_window_is_the_whole_runs():
    """R-4.1-01: the characters of every command but the first start 0.05 ms further apart
    (the shortest start-to-start spacing of the recording is the first command's, in its
    first window); the finding names it and counts the spacings of every window."""
    events = sorted(_round(), key=lambda e: e.start)
    whole = read_view(events)
    late = {id(c): k * 5e-5 for t in whole.transmissions[1:] for k, c in enumerate(t.chars)}
    events = [
        replace(e, start=e.start + late[id(e)], end=e.end + late[id(e)]) if id(e) in late else e
        for e in events
    ]
    whole = read_view(events)
    expected = _by_rule(_whole(whole))["R-4.1-01"]
    spacings = sum(len(t.chars) - 1 for t in whole.transmissions)
    assert expected.detail.endswith(f"over {spacings} spacings")
    assert expected.evidence == [f"in {whole.transmissions[0].at()}"]
    assert _by_rule(_windowed(at_every_break(events)))["R-4.1-01"] == expected
