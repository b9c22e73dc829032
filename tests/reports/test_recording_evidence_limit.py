"""A judged recording's evidence is held in bounded memory (issue 22): a case keeps the
first exchanges of a piece of evidence up to :data:`~conformance.plugin.RECORDING_EVIDENCE`
events (its label says how many of how many), and the reports' locator cuts no stretch of a
recording wider than :data:`~conformance.reports.evidence.WIDE_POOL` events (a wider one is
searched in the whole cut, read window by window). Before, a case's evidence of every
measurement of an hour's capture, and the locator's cut of its stretch, were held through
every run of the judgement (48 MB kept at 30 minutes of a measuring bus)."""

from __future__ import annotations

import re

import pytest

from conformance.case import Case, head_of
from conformance.results import CaseRecord
from conformance.transcript import BUS, TOOL, Event, EventKind


def _exchange(t: float, chars: int = 5) -> list[Event]:
    """A break at ``t`` then ``chars`` characters: one exchange's events."""
    brk = Event(EventKind.BREAK, TOOL, t, t + 0.012)
    return [brk] + [
        Event(EventKind.CHAR, BUS, t + 0.02 + i * 0.00833, t + 0.02 + (i + 1) * 0.00833, 0x30)
        for i in range(chars)
    ]


def _exchanges(n: int, chars: int = 5) -> list[Event]:
    return [e for k in range(n) for e in _exchange(k * 1.0, chars)]


def test_the_head_ends_before_the_exchange_the_limit_would_split():
    events = _exchanges(10)  # 6 events each
    assert head_of(events, 20) == events[:18]  # three whole exchanges, not 2 events of a 4th
    assert head_of(events, 18) == events[:18]  # the next exchange starts at the limit
    assert head_of(events, 100) == events


def test_a_head_with_no_break_past_its_first_event_is_cut_at_the_limit():
    events = _exchanges(1, chars=50)
    assert head_of(events, 20) == events[:20]


def test_an_exchange_longer_than_half_the_limit_is_shown_in_part():
    """A short command then a long binary packet: cutting before the packet's exchange
    would keep 6 of 40 events; all 40 are kept, the packet shown in part."""
    events = _exchange(0.0, 5) + _exchange(1.0, 100)
    assert head_of(events, 40) == events[:40]
    assert head_of(events, 12) == events[:6]  # the break at 6 is at half the limit: cut


def test_a_case_keeps_at_most_its_limit_and_says_so():
    events = _exchanges(10)
    record = CaseRecord(nodeid="x::y", name="y", requirements=("R-4.4.12-05",))
    Case(record, evidence_limit=20).evidence("recorded measurements", events)
    ((label, kept),) = record.evidence
    assert kept == events[:18]
    assert "the first 18 of 60 events" in label and label.startswith("recorded measurements")
    assert f"t={events[17].end:.4f} s" in label
    assert not record.evidence_whole  # the reports then search the whole recording
    whole = CaseRecord(nodeid="x::y", name="y", requirements=("R-4.4.12-05",))
    Case(whole, evidence_limit=60).evidence("recorded measurements", events)
    assert whole.evidence == [("recorded measurements", events)] and whole.evidence_whole
    Case(whole).evidence("again", events)  # a live run's case: no limit
    assert whole.evidence[1] == ("again", events)


def _judge(folder, name: str):
    from conformance.conduct import conduct
    from conformance.replay.recording_link import recording_port
    from conformance.run import RunOptions

    port = recording_port(folder / "run" / "transcript.jsonl", "jsonl")
    options = RunOptions(port=port, role="sensor", report_dir=str(folder / name))
    result = conduct(options, cases="testcases.passive", html=False, rootdir=folder)
    assert result.run is not None and result.run.link is not None
    return result.run


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A simulated run's transcript (faults that leave FAILs to place), as a recording."""
    from conformance.conduct import run_into

    folder = tmp_path_factory.mktemp("limit")
    run_into(
        folder / "run",
        "sim://?faults=inter-char-gap,crc-wrong-encoding",
        keyword="measurement or crc",
    )
    return folder


def _verdicts(run) -> list[tuple[str, str, str]]:
    return [(r.nodeid, f.requirement, str(f.verdict)) for r in run.cases for f in r.findings]


def test_a_judged_recording_keeps_each_piece_of_evidence_to_the_limit(recorded, monkeypatch):
    from conformance import plugin

    monkeypatch.setattr(plugin, "RECORDING_EVIDENCE", None)
    whole = _judge(recorded, "whole")
    assert all(r.evidence_whole for r in whole.cases)
    longest = max(len(evs) for r in whole.cases for _, evs in r.evidence)
    assert longest > 40, "the recording must give evidence past the limit tried"
    monkeypatch.setattr(plugin, "RECORDING_EVIDENCE", 40)
    limited = _judge(recorded, "limited")
    assert _verdicts(limited) == _verdicts(whole)  # what is judged does not change
    cut = 0
    assert not all(r.evidence_whole for r in limited.cases)
    for r, w in zip(limited.cases, whole.cases, strict=True):
        for (label, evs), (whole_label, whole_evs) in zip(r.evidence, w.evidence, strict=True):
            assert len(evs) <= 40
            if len(whole_evs) > 40:
                cut += 1
                assert not r.evidence_whole
                assert evs == whole_evs[: len(evs)] and evs
                m = re.search(r"the first (\d+) of (\d+) events", label)
                assert m and (int(m[1]), int(m[2])) == (len(evs), len(whole_evs))
            else:
                assert (label, evs) == (whole_label, whole_evs)
    assert cut >= 1
    # each finding placed where the whole evidence placed it (the case's stretch: its
    # first events to the last of each piece, in the recording)
    from conformance.reports.evidence import NEEDS_EVIDENCE, locator_of

    def placed(run) -> list[object]:
        locator = locator_of(run.link)
        return [
            locator.locate(f, r)
            for r in run.cases
            for f in r.findings
            if f.verdict in NEEDS_EVIDENCE
        ]

    assert placed(limited) == placed(whole)
    assert sum(ref is not None for ref in placed(whole)) >= 3


def test_the_locator_cuts_no_stretch_of_a_recording_wider_than_its_limit(recorded, monkeypatch):
    from conformance.reports import evidence

    run = _judge(recorded, "narrow")
    link = run.link
    count = len(link.transcript.events)
    listed = evidence.Locator(list(link.transcript.events), link.transcript)
    wanted = [
        (record, f)
        for record in run.cases
        for f in record.findings
        if f.verdict in evidence.NEEDS_EVIDENCE
    ]
    placed_before = sum(listed.locate(f, record) is not None for record, f in wanted)
    assert placed_before >= 3
    monkeypatch.setattr(evidence, "WIDE_POOL", 10)
    link.transcript.__dict__.pop("_locator", None)
    cuts: list[tuple[int, int]] = []
    segments = evidence.Locator._segments

    def noted(self, lo, hi):  # type: ignore[no-untyped-def]
        cuts.append((lo, hi))
        return segments(self, lo, hi)

    monkeypatch.setattr(evidence.Locator, "_segments", noted)
    try:
        streamed = evidence.locator_of(link)
        assert streamed.again is not None
        placed = sum(streamed.locate(f, record) is not None for record, f in wanted)
    finally:
        link.transcript.__dict__.pop("_locator", None)
    assert cuts and all(hi - lo <= 10 or (lo, hi) == (0, count) for lo, hi in cuts)
    assert any((lo, hi) == (0, count) for lo, hi in cuts)  # the wide ones: the whole cut
    assert placed == placed_before  # every finding placed still


def test_a_case_s_own_traffic_is_shown_from_its_first_events_alone():
    """The where block of a finding resting on a case's own traffic (no exchange) shows its
    first CASE_EXCERPT events and counts the rest: it reads no more of the recording than
    those, and says what reading its whole stretch said."""
    from conformance.reports.evidence import WireRef
    from conformance.reports.html import CASE_EXCERPT, around_end, where_html_around
    from conformance.verdicts import Finding, Verdict

    events = _exchanges(40)
    f = Finding("R-4.4.12-02", Verdict.INCONCLUSIVE, "nothing observed")
    ref = WireRef(70, 200, events[70].start, events[200].end, None, "case")
    lo = max(0, ref.first - 60)
    assert around_end(ref) == ref.first + CASE_EXCERPT
    whole = where_html_around([f], ref, events[lo : ref.last + 61], lo, False)
    part = where_html_around([f], ref, events[lo : around_end(ref)], lo, False)
    assert part == whole
    assert f"{200 + 1 - 70 - CASE_EXCERPT} more events in transcript.jsonl" in part
    exchange = WireRef(70, 75, events[70].start, events[75].end, "0M!", "command")
    assert around_end(exchange) == 75 + 61  # an exchange's: 60 events past it, as before


def test_the_head_of_a_record_s_events_is_events_of_s_without_the_list():
    """events_head: the first n of events_of, its count and last, for records of several
    parts whose events interleave in time (concurrent measurements), equal starts kept in
    join order, a list of events as it is, and a NaN start (events_of's own order)."""
    from conformance.case import events_head, events_of
    from conformance.tool_recorder.records import Attempt, Exchange

    def exchange(t: float, n: int) -> Exchange:
        evs = _exchange(t, n)
        attempt = Attempt(evs[0], evs[1:2], evs[2:], reason="", end=evs[-1].end)
        return Exchange(command=None, text="0M!", attempts=[attempt])

    records = [exchange(t, n) for t, n in ((0.0, 9), (0.05, 4), (0.05, 6), (3.0, 5), (0.01, 3))]
    whole = events_of(records)
    for n in (1, 5, 12, len(whole), len(whole) + 3):
        assert events_head(records, n) == (whole[:n], len(whole), whole[-1])
    shuffled = _exchanges(3)[::-1]  # events alone, out of order: kept as given
    assert events_head(shuffled, 4) == (shuffled[:4], len(shuffled), shuffled[-1])
    assert events_head(None, 4) == ([], 0, None)
    odd = [exchange(0.0, 3), exchange(float("nan"), 2)]
    assert events_head(odd, 3)[0] == events_of(odd)[:3]
