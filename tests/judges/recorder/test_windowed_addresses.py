"""The addresses the recorder polled judged a window at a time (issue 22's windowed judge):
:class:`~conformance.judges.recorder.capabilities.Addresses` given each window's view, read
from its own events alone, in order gives :func:`judge_addresses`' findings of the whole
recording (``testcases/passive/test_recorder_4_4_measurement.py::test_addresses``), detail
for detail and evidence for evidence.

What a wrong merge gets wrong: an address answered in an early window (R-4.3-03's polled
set), the polls R-4.3-03 cites, from several windows (the first eight, in order), the span
of what the recorder sent when it sent none of them (count, first and last time, the kinds
of command), and R-4.3-04's commands to what is no address (count and first eight)."""

from __future__ import annotations

from conformance.judges.recorder.capabilities import Addresses, judge_addresses
from conformance.judges.recorder.common import record_of
from conformance.transcript import Event
from conformance.verdicts import Finding, Verdict
from conformance.view.segments import read_view
from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors, concurrent_round
from tests.support.windowed_judges import at_every_break, product_cuts

U = 1e-6  # a 1 MHz capture's stamps


def _windowed(windows: list[list[Event]]) -> list[Finding]:
    judge = Addresses(U)
    for window in windows:
        judge.add(read_view(window))
    return judge.findings()


def _all_cuts(events: list[Event]) -> list[list[list[Event]]]:
    """The windows :func:`window_starts` cuts, streamed, and a cut at every break."""
    return [*product_cuts(events, U), at_every_break(events)]


def test_a_bus_rounds_addresses_judge_as_the_whole_recording():
    """Sensors 0, 1, 3 identified, a concurrent round: the seven other digits never sent,
    so R-4.3-03 FAILs on the span of what was sent (every window's count and kinds)."""
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES:
        recorder.identify(a)
    concurrent_round(recorder)
    events = as_heard(bus)
    whole = judge_addresses(read_view(events), U)
    r3, r4 = whole
    assert r3.verdict is Verdict.FAIL and r3.detail.endswith("2, 4, 5, 6, 7, 8, 9")
    assert r3.evidence[0].startswith(f"{len(read_view(events).transmissions)} transmissions")
    assert r4.verdict is Verdict.NA
    for windows in _all_cuts(events):
        assert len(windows) >= 4
        assert _windowed(windows) == whole


def test_polls_never_answered_are_cited_from_every_window():
    """``2!`` and ``4!`` (no sensor there) polled over and over, each after a break: the
    polls cited are the first eight of both, in order, across windows; 0's valid reply in
    the first window keeps 0 polled to the end."""
    bus, recorder = bus_of_sensors("0")
    recorder.acknowledge("0")
    for _ in range(5):
        for a in "24":
            recorder.transact(f"{a}!", retries=False, force_break=True)
    events = as_heard(bus)
    whole = judge_addresses(read_view(events), U)
    r3 = whole[0]
    assert r3.detail.startswith("addresses never polled successfully: 1, 2, 3, 4,")
    assert [e.split(" ")[0] for e in r3.evidence] == ["2!", "4!"] * 4
    for windows in _all_cuts(events):
        assert len(windows) >= 11
        assert _windowed(windows) == whole


def test_commands_to_no_address_are_counted_and_cited_from_every_window():
    """R-4.3-04 (MAY, so a WARN): ``*I!`` sent nine times, each in a window of its own: the
    count of all nine, the first eight quoted."""
    bus, recorder = bus_of_sensors("0")
    recorder.identify("0")
    for _ in range(9):
        recorder.raw("*I!", break_first=True)
    events = as_heard(bus)
    whole = judge_addresses(read_view(events), U)
    r4 = whole[1]
    assert r4.verdict is Verdict.WARN and r4.observed == 9 and len(r4.evidence) == 8
    for windows in _all_cuts(events):
        assert _windowed(windows) == whole


def test_record_of_one_window_is_its_whole_evidence():
    """:func:`record_of` (the whole-run evidence of what the recorder did not do) is one add
    of :class:`Record`: cited transmissions, or the span when none is cited."""
    bus, recorder = bus_of_sensors("0")
    recorder.identify("0")
    recorder.acknowledge("0")
    sent = read_view(as_heard(bus)).transmissions
    assert [e.split(" ")[0] for e in record_of(sent, ["0!"])] == ["0!"]
    assert record_of(sent, ["5!"]) == [
        f"2 transmissions from t={sent[0].first_char:.3f} s to t={sent[1].first_char:.3f} s, "
        "of 2 kinds: 0! 0I!"
    ]
    assert record_of([], ["5!"]) == ["the recorder transmitted nothing"]


def test_an_address_polled_in_an_early_window_stays_polled():
    """Sensors at 0-8; ``9!`` polled first (nobody there), then each sensor identified in
    windows of their own: every digit was sent to, so R-4.3-03 is undecided on 9 ("each was
    polled, never validly answered"), not a FAIL for a poll the recorder never sent."""
    bus, recorder = bus_of_sensors("012345678")
    recorder.transact("9!", retries=False, force_break=True)
    for a in "012345678":
        recorder.identify(a)
    events = as_heard(bus)
    whole = judge_addresses(read_view(events), U)
    r3 = whole[0]
    assert r3.verdict is Verdict.INCONCLUSIVE
    assert r3.detail == (
        "addresses never polled successfully: 9 (each was polled, never validly answered)"
    )
    for windows in _all_cuts(events):
        assert len(windows) >= 10
        assert _windowed(windows) == whole
