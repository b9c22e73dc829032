"""A passive run's reports place its findings on the wire without the recording's list of
events (issue 22): the locator of a recording (``Locator.streamed``) reads the events again
as they come, for exactly the events a finding cites, and must give every finding the
reference the locator over the list gives; the wire excerpts report.html shows around each
are cut from the events read again the same way. The oracle is the list's locator (the
base tree's), over the same recording and findings."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conformance.reports.evidence import (
    NEEDS_EVIDENCE,
    Locator,
    Positions,
    StreamedPositions,
    locator_of,
    wire_refs,
)
from conformance.reports.html import where_html, where_html_around
from conformance.transcript import Event
from tests.reports.test_evidence_positions import asked, event, first_index


@given(st.lists(event, max_size=30), st.lists(event, max_size=5), st.booleans())
def test_streamed_positions_are_the_list_s(events, others, in_order):
    if in_order:
        events.sort(key=lambda e: e.start)
    listed = Positions(events)
    listed.index()
    streamed = StreamedPositions(lambda: iter(events))
    query = asked(events, others)
    reference = first_index(events)
    assert list(streamed.of(query)) == list(listed.of(query))
    assert list(streamed.of(query)) == [reference[e] for e in query if e in reference]
    assert streamed.reads <= 1  # placed once, asked again from what the read found
    assert all(streamed.at[i] == e for e, i in streamed.first.items())


def test_a_read_stops_at_the_last_event_asked_about():
    from conformance.transcript import BUS, EventKind

    events = [Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, 0x30) for i in range(1000)]
    read: list[int] = []

    def again() -> Iterator[Event]:
        for e in events:
            read.append(1)
            yield e

    streamed = StreamedPositions(again)
    assert list(streamed.of([events[41], events[7]])) == [41, 7]
    assert len(read) == 42


class Unlisted(list):
    """A transcript's events that may be counted and nothing else: what a report reads of
    them otherwise fails."""

    def _refuse(self, *args: object) -> None:
        raise AssertionError("a report read the recording's whole list of events")

    __iter__ = __getitem__ = __contains__ = __reversed__ = index = count = _refuse  # type: ignore


@pytest.fixture(scope="module")
def judged(tmp_path_factory) -> object:
    """A passive sensor run over a simulated run's transcript with two faults: FAILs and
    INCONCLUSIVEs whose exchanges the reports place (wire refs and where blocks)."""
    from conformance.conduct import conduct, run_into
    from conformance.replay.recording_link import recording_port
    from conformance.run import RunOptions

    folder = tmp_path_factory.mktemp("streamed")
    run_into(
        folder / "run",
        "sim://?faults=inter-char-gap,crc-wrong-encoding",
        keyword="measurement or crc",
    )
    port = recording_port(folder / "run" / "transcript.jsonl", "jsonl")
    options = RunOptions(port=port, role="sensor", report_dir=str(folder / "passive"))
    result = conduct(options, cases="testcases.passive", html=False, rootdir=folder)
    assert result.run is not None and result.run.link is not None
    return result.run


def test_every_finding_is_placed_as_the_list_places_it(judged):
    run = judged
    link = run.link
    assert link.reads_again  # a recording: its reports read it again
    events = list(link.transcript.events)
    listed = Locator(events, link.transcript)
    found = {}
    for record in run.cases:
        for f in record.findings:
            if f.verdict in NEEDS_EVIDENCE:
                found[id(f)] = (listed.locate(f, record), record, f)
    assert sum(ref is not None for ref, _, _ in found.values()) >= 3  # exchanges placed
    link.transcript.__dict__.pop("_locator", None)
    link.transcript.events = Unlisted(events)  # counted, never read whole from here on
    link.events_again = lambda: iter(events)  # as a recording read from its file gives them
    try:
        streamed = locator_of(link)
        for ref, record, f in found.values():
            assert streamed.locate(f, record) == ref
        refs = wire_refs(run.cases, link)
        assert refs == {k: ref for k, (ref, _, _) in found.items() if ref is not None}
        for ref, _, f in found.values():
            if ref is not None:
                lo = max(0, ref.first - 60)
                around = streamed.slice(lo, ref.last + 61)
                assert where_html_around([f], ref, around, lo, True) == where_html(
                    [f], ref, events, True
                )
    finally:
        link.transcript.events = events
        del link.events_again
        link.transcript.__dict__.pop("_locator", None)


def test_a_live_run_s_locator_reads_the_list(judged):
    """A bus end that is not a recording keeps the list's locator (it may still grow)."""
    from conformance.transcript import Transcript

    class Live:
        reads_again = False
        transcript = Transcript(list(judged.link.transcript.events))

    locator = locator_of(Live())  # type: ignore[arg-type]
    assert isinstance(locator.position, Positions) and locator.again is None


def test_the_transcript_file_is_written_from_the_events_read_again(judged, tmp_path: Path):
    """transcript.jsonl of a recording: the bytes the list gave, written with the list
    unread (``write_recording`` of the base tree as the oracle)."""
    from conformance.replay.recording import write_recording
    from conformance.reports.verdicts_json import write_transcript

    link = judged.link
    events = list(link.transcript.events)
    write_recording(tmp_path / "oracle.jsonl", events, keep=False)
    link.transcript.__dict__.pop("_written_to", None)
    link.transcript.events = Unlisted(events)
    link.events_again = lambda: iter(events)
    try:
        written = write_transcript(judged, tmp_path)
    finally:
        link.transcript.events = events
        del link.events_again
        link.transcript.__dict__.pop("_written_to", None)
    assert written.read_bytes() == (tmp_path / "oracle.jsonl").read_bytes()
