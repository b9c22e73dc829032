"""The retention, extended-command and service-request judges read a record the tool's own
host stalled over as the others do (truth29; conformance.judges.stalled).

Hand-typed runs of this tool, judged as its recording is (the sensor pass over its windows,
which marks the reads and the measurement waits from the link's NOTEs alone): with the NOTE
of a stall over the decisive stamp, the rule is INCONCLUSIVE with the stall named; the same
deviation without it FAILs as ever. Each stalled case FAILed on base-s66."""

from __future__ import annotations

from conformance.judges import extended
from conformance.judges import measurements as judge
from conformance.judges.retention import retained
from conformance.links import host_stall
from conformance.links.base import LinkInfo
from conformance.offline.sensor_windows import SensorRecords, bus_windows, sensor_records
from conformance.protocol.commands import parse_command
from conformance.replay.recording_link import RecordingLink, RecordingSpec
from conformance.tool_recorder.records import OK, Attempt, Exchange
from conformance.tool_recorder.stalled_reads import mark_reads
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript
from conformance.verdicts import Verdict
from tests.support.hand_events import chars

U = 1e-3
STALL = 0.15  # s: the pause the link measured
WHY = "the tool's host stalled 150 ms during this read"


class Run:
    """Exchanges typed at given times: a break, the command, its reply 9 ms after it, and
    the sensor's other text (a service request) and the link's NOTEs where asked."""

    def __init__(self) -> None:
        self.events: list[Event] = []
        self.t = 0.0

    def exchange(self, command: str, reply: str, *, stalled: bool = False) -> float:
        """``command`` after a break, ``reply`` 9 ms after it; ``stalled``: the NOTE of a
        stall just after the reply's last character (the burst it held back). Returns the
        reply's end."""
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + 0.0125, uncertainty=U))
        cmd = chars(TOOL, command, self.t + 0.0215, uncertainty=U)
        rep = chars(DUT, reply, cmd[-1].end + 0.009, uncertainty=U)
        self.events += cmd + rep
        if stalled:
            self.note(rep[-1].end + 0.001)
        self.t = rep[-1].end + 0.3
        return rep[-1].end

    def sensor(self, text: str, at: float) -> float:
        """The sensor's ``text`` from ``at`` (a service request); returns its end."""
        got = chars(DUT, text, at, uncertainty=U)
        self.events += got
        self.t = max(self.t, got[-1].end + 0.05)
        return got[-1].end

    def note(self, at: float) -> None:
        text = host_stall.note_text(STALL)
        self.events.append(Event(EventKind.NOTE, TOOL, at, at, text=text))

    def recorded(self, *, noted: bool = True) -> SensorRecords:
        kept = sorted(
            (e for e in self.events if noted or e.kind is not EventKind.NOTE),
            key=lambda e: e.start,
        )
        info = LinkInfo(kind="transcript", can_break=True, timing_uncertainty=U)
        link = RecordingLink(RecordingSpec("t.jsonl", "jsonl"), info, Transcript(kept), U)
        return sensor_records(link, bus_windows(link), "0")


VALUES = "0+22.15+1013.2+45.7\r\n"


def _retention(stalled: bool) -> Run:
    """0D0! read twice, the second read cut by a stall after two values."""
    run = Run()
    run.exchange("0D0!", VALUES)
    run.exchange("0D0!", "0+22.15+1013.2", stalled=stalled)
    return run


def test_a_retained_read_cut_by_a_stall_is_no_lost_buffer():
    """R-4.4.5-10: 'D0 changed from ... to ...' FAILed on base-s66."""
    first, second = _retention(True).recorded().exchanges
    found = retained([first], [second])
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "D0 changed" in found.detail and WHY in found.detail


def test_the_same_change_outside_any_stall_fails():
    first, second = _retention(True).recorded(noted=False).exchanges
    assert retained([first], [second]).verdict is Verdict.FAIL


def test_a_change_outside_any_stall_fails_beside_a_stalled_one():
    a, b = _retention(True).recorded().exchanges
    c, d = _retention(False).recorded().exchanges  # D1's pair changed outside any stall
    found = retained([a, c], [b, d])
    assert found.verdict is Verdict.FAIL and found.detail.startswith("D1 changed")


def test_an_extended_reply_cut_by_a_stall_is_inconclusive():
    """R-4.4.13-01 "reply '0SN12' does not run from the address to CR LF" on a cut read."""
    for noted, verdict in ((True, Verdict.INCONCLUSIVE), (False, Verdict.FAIL)):
        run = Run()
        run.exchange("0XSN!", "0SN12", stalled=True)
        (ex,) = run.recorded(noted=noted).exchanges
        found = {f.requirement: f for f in extended.extended_replies([ex], "0")}
        assert found["R-4.4.13-01"].verdict is verdict, found["R-4.4.13-01"].detail
        assert (WHY in found["R-4.4.13-01"].detail) is noted


def _multiline(stalled: bool) -> Exchange:
    """0XHELP!'s two lines, the second read 200 ms after the first (limit 150 ms): the
    stall held it back, its NOTE after the burst; the read marked from the NOTEs alone."""
    cmd = chars(TOOL, "0XHELP!", 0.0215, uncertainty=U)
    first = chars(DUT, "0\x02line one\r\n", cmd[-1].end + 0.009, uncertainty=U)
    second = chars(DUT, "line two\r\n\x03", first[-1].end + 0.2, uncertainty=U)
    attempt = Attempt(None, cmd, first + second, OK, second[-1].end)
    ex = Exchange(parse_command("0XHELP!"), "0XHELP!", [attempt])
    at = second[-1].end + 0.001
    note = Event(EventKind.NOTE, TOOL, at, at, text=host_stall.note_text(STALL))
    mark_reads([ex], host_stall.stalls([note] if stalled else []))
    return ex


def test_lines_apart_across_a_stall_are_inconclusive():
    """R-4.4.13.1-03 '200 ms between lines' read across the stall; outside it, a FAIL."""
    for stalled, verdict in ((True, Verdict.INCONCLUSIVE), (False, Verdict.FAIL)):
        found = {f.requirement: f for f in extended.multiline([_multiline(stalled)], "0", U)}
        assert found["R-4.4.13.1-03"].verdict is verdict, found["R-4.4.13.1-03"].detail
        assert (WHY in found["R-4.4.13.1-03"].detail) is stalled


def _late_request(noted: bool) -> SensorRecords:
    """aM! announcing ttt=1 s; its service request dated 1.3 s after the reply (the stall
    held it back: the NOTE just after it), then D0."""
    run = Run()
    reply_end = run.exchange("0M!", "00012\r\n")
    sr_end = run.sensor("0\r\n", reply_end + 1.3)
    if noted:
        run.note(sr_end + 0.001)
    run.t = sr_end + 0.05
    run.exchange("0D0!", "0+1+2\r\n")
    return run.recorded(noted=noted)


def _missed_request(noted: bool) -> SensorRecords:
    """aM! announcing ttt=1 s, no service request in the wait, D0 1.2 s after the reply:
    the NOTE of a stall over the wait's end (a request delivered after it lies in D0's
    record, not the wait's)."""
    run = Run()
    reply_end = run.exchange("0M!", "00012\r\n")
    run.t = reply_end + 1.2
    if noted:
        run.note(run.t + 0.02)
    run.exchange("0D0!", "0+1+2\r\n")
    return run.recorded(noted=noted)


def _wait_rule(records: SensorRecords, rid: str):
    (found,) = judge.judge(records.measurements, [rid], "14")
    return found


def test_a_service_request_dated_late_by_a_stall_is_inconclusive():
    found = _wait_rule(_late_request(True), "R-4.4.6-04")
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "past ttt" in found.detail and WHY in found.detail


def test_a_late_service_request_outside_any_stall_fails():
    assert _wait_rule(_late_request(False), "R-4.4.6-04").verdict is Verdict.FAIL


def test_a_service_request_missed_across_a_stall_is_not_the_sensor_s():
    found = _wait_rule(_missed_request(True), "R-4.4.6-02")
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "no service request" in found.detail and WHY in found.detail


def test_a_service_request_missed_outside_any_stall_fails():
    assert _wait_rule(_missed_request(False), "R-4.4.6-02").verdict is Verdict.FAIL


def test_a_stall_early_in_the_wait_changes_nothing():
    """A stall before any character of the wait, well before its end, moved nothing."""
    run = Run()
    reply_end = run.exchange("0M!", "00012\r\n")
    run.note(reply_end + 0.4)
    run.t = reply_end + 1.2
    run.exchange("0D0!", "0+1+2\r\n")
    assert _wait_rule(run.recorded(), "R-4.4.6-02").verdict is Verdict.FAIL


def test_the_stall_notes_are_read_once_per_stimulus(monkeypatch):
    """The engine's records and the view's of one stimulus ask the notes since its first
    event with nothing added between: read once; a note added since is read."""
    from types import SimpleNamespace

    from conformance.sensor import buffer_watch
    from conformance.sensor.buffer_watch import WatchedToolRecorder

    reads = []
    real = host_stall.stalls_since
    monkeypatch.setattr(
        buffer_watch.host_stall,
        "stalls_since",
        lambda ev, first: reads.append(first) or real(ev, first),
    )
    run = Run()
    run.exchange("0D0!", VALUES, stalled=True)
    link = SimpleNamespace(transcript=Transcript(run.events), reader_caught_up=lambda: None)
    engine = SimpleNamespace(link=link, _stalls_read=((0, -1, -1), []))
    first = WatchedToolRecorder.stalls_since(engine, 0)  # type: ignore[arg-type]
    assert WatchedToolRecorder.stalls_since(engine, 0) is first and len(first) == 1  # type: ignore[arg-type]
    link.transcript.note(run.t, host_stall.note_text(STALL))
    assert len(WatchedToolRecorder.stalls_since(engine, 0)) == 2  # type: ignore[arg-type]
    assert reads == [0, 0]
