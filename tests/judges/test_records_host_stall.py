"""A record whose read the tool's own host stalled over is no evidence against the sensor
(truth27; conformance.links.host_stall, conformance.judges.stalled).

Behind RFC 2217 with the tool's process paused 80-200 ms every 0.3-0.9 s, a clean emulator
FAILed R-4.4.12-02/R-5.1-03 "lacks the 3-character CRC", R-4.4.8-03 "97 values were
returned for 99 announced" and WARNed R-4.4.8.3-03 "D6 had room for '+18.750' returned by
D7" and R-4.4.8-02 "value '+18.' ends with '.'": the D reply read was cut by the pause (its
rest came in a burst after the read ended) and the rebuilt record judged holds the cut
reply. Here each is a transcript of that shape, judged as a recording of a run of this tool
is (the sensor pass over its windows, then the cases' judges): with the link's NOTE of the
stall after the cut reply, the rule is INCONCLUSIVE with the stall named; without it, or
with the stall elsewhere, the judges FAIL or WARN as ever."""

from __future__ import annotations

import pytest

from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.judges import metadata
from conformance.judges.exploration import Observation, held_findings
from conformance.judges.exploration import judge as explore_judge
from conformance.links import host_stall
from conformance.links.base import LinkInfo
from conformance.offline.sensor_windows import bus_windows, sensor_records
from conformance.protocol.crc import ascii_crc
from conformance.replay.recording_link import RecordingLink, RecordingSpec
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript
from conformance.verdicts import Finding, Verdict
from tests.support.hand_events import chars

U = 1e-3
STALL = 0.15  # s: the pause the link measured
WHY = "the tool's host stalled 150 ms during this read"


class Bus:
    """A run of this tool typed by hand: exchanges one after another, each a break (or
    not), the command and the sensor's reply, and the link's NOTE of a stall where asked."""

    def __init__(self) -> None:
        self.events: list[Event] = []
        self.t = 0.0

    def exchange(self, command: str, reply: str, *, stalled: bool = False) -> None:
        """``command`` after a break, ``reply`` 9 ms after it; ``stalled``: the host stalled
        just as the reply's last character came (its reader back ``STALL`` s later, the
        note after the burst it held back; the burst, the reply's rest, is not typed)."""
        self.events.append(Event(EventKind.BREAK, TOOL, self.t, self.t + 0.0125, uncertainty=U))
        cmd = chars(TOOL, command, self.t + 0.0215, uncertainty=U)
        rep = chars(DUT, reply, cmd[-1].end + 0.009, uncertainty=U)
        self.events += cmd + rep
        self.t = rep[-1].end + 0.3
        if stalled:
            at = rep[-1].end + STALL
            text = host_stall.note_text(STALL)
            self.events.append(Event(EventKind.NOTE, TOOL, at, at, text=text))

    def measurements(self) -> list:
        info = LinkInfo(kind="transcript", can_break=True, timing_uncertainty=U)
        link = RecordingLink(RecordingSpec("t.jsonl", "jsonl"), info, Transcript(self.events), U)
        return sensor_records(link, bus_windows(link), "0").measurements


def _with_crc(text: str) -> str:
    return text + ascii_crc(text) + "\r\n"


def _judged(bus: Bus, *ids: str) -> dict[str, Finding]:
    return {f.requirement: f for f in judge.judge(bus.measurements(), ids, "14")}


def _crc_cut(stalled: bool) -> Bus:
    """aMC! for two values; D0's reply cut after the first CRC character."""
    bus = Bus()
    bus.exchange("0MC!", "00002\r\n")
    full = _with_crc("0+1.50+2.25")
    bus.exchange("0D0!", full[: full.index("\r") - 2], stalled=stalled)
    return bus


def _high_volume(stalled: bool) -> Bus:
    """aHA! for four values; D0's reply cut before its CRC, D1 whole."""
    bus = Bus()
    bus.exchange("0HA!", "0000004\r\n")
    bus.exchange("0D0!", "0+1000.000+1001.062+", stalled=stalled)
    bus.exchange("0D1!", _with_crc("0+1002.125+1003.188"))
    return bus


#: a D reply whose CRC the cut took, after aMC! (R-4.4.12-02) and aHA! (R-5.1-03)
CRC_CUTS = pytest.mark.parametrize(
    ("build", "rid"), [(_crc_cut, "R-4.4.12-02"), (_high_volume, "R-5.1-03")]
)


@CRC_CUTS
def test_a_crc_cut_by_a_stall_is_inconclusive(build, rid):
    found = _judged(build(True), rid)[rid]
    assert found.verdict is Verdict.INCONCLUSIVE
    assert "lacks the 3-character CRC" in found.detail and WHY in found.detail


@CRC_CUTS
def test_the_same_crc_missing_without_a_stall_fails(build, rid):
    assert _judged(build(False), rid)[rid].verdict is Verdict.FAIL


def _values_cut(stalled: bool) -> Bus:
    """aC! for three values; D0's reply cut in the second value ('+2.'), D1 the third."""
    bus = Bus()
    bus.exchange("0C!", "000003\r\n")
    bus.exchange("0D0!", "0+1.50+2.", stalled=stalled)
    bus.exchange("0D1!", "0+3.50\r\n")
    return bus


RULES = ("R-4.4.8-02", "R-4.4.8.3-03")


def test_values_cut_by_a_stall_are_inconclusive_not_warned():
    """R-4.4.8-02 (value '+2.' ends with '.') and R-4.4.8.3-03 (D0 had room for D1's
    value): both WARNs rest on the cut read alone."""
    found = _judged(_values_cut(True), *RULES)
    for rid in RULES:
        assert found[rid].verdict is Verdict.INCONCLUSIVE, rid
        assert WHY in found[rid].detail


def test_the_same_values_without_a_stall_warn():
    found = _judged(_values_cut(False), *RULES)
    assert [found[rid].verdict for rid in RULES] == [Verdict.WARN, Verdict.WARN]


def _count_cut(first_stalled: bool, second_stalled: bool) -> Bus:
    """Two aC! measurements for three values whose D0 came cut after two: R-4.4.8-03's
    count is short in each."""
    bus = Bus()
    for stalled in (first_stalled, second_stalled):
        bus.exchange("0C!", "000003\r\n")
        bus.exchange("0D0!", "0+1.50+2.50", stalled=stalled)
    return bus


def test_a_count_short_by_a_stalled_read_is_inconclusive():
    found = _judged(_count_cut(True, True), "R-4.4.8-03")["R-4.4.8-03"]
    assert found.verdict is Verdict.INCONCLUSIVE
    assert "2 values were returned for 3 announced" in found.detail and WHY in found.detail


def test_a_count_short_outside_any_stall_still_fails_beside_a_stalled_one():
    found = _judged(_count_cut(True, False), "R-4.4.8-03")["R-4.4.8-03"]
    assert found.verdict is Verdict.FAIL
    assert WHY not in found.detail


def test_a_stall_before_the_read_changes_nothing():
    """A stall noted before the measurement began held up no read of it."""
    bus = _crc_cut(False)
    early = Event(EventKind.NOTE, TOOL, -1.0, -1.0, text=host_stall.note_text(STALL))
    bus.events.insert(0, early)
    assert _judged(bus, "R-4.4.12-02")["R-4.4.12-02"].verdict is Verdict.FAIL


def test_an_identification_cut_by_a_stall_is_inconclusive():
    """aI!'s reply cut after 13 characters (the passive judgement of the paused run:
    "identification '014CONFORM EM' is 13 characters long")."""
    for stalled, verdict in ((True, Verdict.INCONCLUSIVE), (False, Verdict.FAIL)):
        bus = Bus()
        bus.exchange("0I!", "014CONFORM EM", stalled=stalled)
        info = LinkInfo(kind="transcript", can_break=True, timing_uncertainty=U)
        link = RecordingLink(RecordingSpec("t.jsonl", "jsonl"), info, Transcript(bus.events), U)
        (ex,) = sensor_records(link, bus_windows(link), "0").exchanges
        _, findings = xjudge.identification(ex, "0")
        assert findings[0].requirement == "R-4.4.2-01"
        assert findings[0].verdict is verdict


def test_the_exploration_s_breach_in_a_stalled_read_is_inconclusive():
    """test_random_command_sequences FAILed R-4.2-03 "reply to 0D0! '0-5.00...+' does not
    end in CR LF" on a read the pause cut: a breach seen in a stalled read neither ends the
    exploration nor FAILs, and the rule is no PASS either; one outside a stall still is."""
    cut = Observation("framing", "0D0!", "0-5.00-3.75+", "0", stalled=WHY)
    whole = Observation("framing", "0D1!", "0+1.25\r\n", "0")
    assert explore_judge(cut).breach is None and explore_judge(cut).undecided is not None
    found = {f.requirement: f for f in held_findings([whole, cut, whole], 3)}
    assert found["R-4.2-03"].verdict is Verdict.INCONCLUSIVE
    assert "does not end in CR LF" in found["R-4.2-03"].detail and WHY in found["R-4.2-03"].detail
    unstalled = Observation("framing", "0D0!", "0-5.00-3.75+", "0")
    assert explore_judge(unstalled).breach is not None


def _one_exchange(command: str, reply: str, stalled: bool):
    bus = Bus()
    bus.exchange(command, reply, stalled=stalled)
    info = LinkInfo(kind="transcript", can_break=True, timing_uncertainty=U)
    link = RecordingLink(RecordingSpec("t.jsonl", "jsonl"), info, Transcript(bus.events), U)
    (ex,) = sensor_records(link, bus_windows(link), "0").exchanges
    return ex


def test_a_metadata_record_cut_by_a_stall_is_inconclusive():
    """wrong-crc under the pauses FAILed R-6.2-02 "0ICC_020!: reply '0,TW,' lacks the CRC"
    and R-6.2.2-01 "reply '0,' has no units field": records cut by the pause."""
    ids = ("R-6.2-01", "R-6.2-02", "R-6.2.2-01")
    for stalled in (True, False):
        ex = _one_exchange("0ICC_020!", "0,TW,", stalled)
        found = {f.requirement: f for f in metadata.records([(ex, True, True)], ids)}
        verdicts = {found[rid].verdict for rid in ids}
        if stalled:
            assert not verdicts & {Verdict.FAIL, Verdict.WARN}, found
            assert found["R-6.2-02"].verdict is Verdict.INCONCLUSIVE
            assert WHY in found["R-6.2-02"].detail
        else:
            assert Verdict.FAIL in verdicts
