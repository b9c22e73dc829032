"""A reply that came after the tool's retries is no "got no reply" (R-4.4.8.1-01, R-6.2-01,
R-6.2-05, R-6.2-07): a sensor whose every reply starts 80 ms after its command and which is
deaf until then (fault replies-after-retry, an Arduino Due's ``delay(80)``) answers into the
retry, which the engine sets aside as bus contention; the reply is there on the wire, late.
Its lateness is R-7.0-10's: these rules are INCONCLUSIVE, and a truly silent sensor still
FAILs them."""

from __future__ import annotations

from types import SimpleNamespace

from conformance.case import Case
from conformance.judges import exchanges as xjudge
from conformance.judges import metadata
from conformance.preconditions import declared_on
from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME
from conformance.results import CaseRecord
from conformance.tool_recorder.records import NO_REPLY, Attempt, Exchange, Measurement
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict
from testcases.sensor.test_5_high_volume import test_high_volume_optional as high_volume_case
from testcases.sensor.test_6_metadata import test_continuous_metadata as continuous_metadata_case
from testcases.sensor.test_7_timing import (
    test_data_after_service_request_without_break as sr_case,
)


def _chars(text: str, start: float, origin: str) -> list[Event]:
    return [
        Event(
            EventKind.CHAR,
            origin,
            start + i * CHAR_TIME,
            start + (i + 1) * CHAR_TIME,
            wire=to_wire_7e1(ord(c)),
        )
        for i, c in enumerate(text)
    ]


def _unanswered(command: str, late: str, t: float = 0.0) -> Exchange:
    """Three tries of ``command`` none answered in its window; ``late`` (if any) arrives
    80 ms after the first, during the retry, and is kept as the retries' stray characters."""
    attempts = []
    for retry in range(3):
        cmd = _chars(command, t, TOOL)
        stray = _chars(late, t - 0.01, DUT) if retry == 1 and late else []
        attempts.append(Attempt(None, cmd, [], NO_REPLY, cmd[-1].end + 0.03, 0, retry, stray))
        t = cmd[-1].end + 0.05
    return Exchange(parse_command(command), command, attempts)


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def test_r_4_4_8_1_01_continuous_reply_after_the_retries_is_inconclusive() -> None:
    pair = (_unanswered("0RC0!", "0+22.1+45.6Hxm\r\n"), _unanswered("0RC0!", "0+22.1Hxm\r\n"))
    found = _by_rule(xjudge.continuous({0: pair}, ["R-4.4.8.1-01"]))["R-4.4.8.1-01"]
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "answered only after the reply window" in found.detail
    assert "got no reply" not in found.detail


def test_r_4_4_8_1_01_silent_continuous_still_fails() -> None:
    pair = (_unanswered("0RC0!", ""), _unanswered("0RC0!", ""))
    found = _by_rule(xjudge.continuous({0: pair}, ["R-4.4.8.1-01"]))["R-4.4.8.1-01"]
    assert found.verdict is Verdict.FAIL
    assert "got no reply" in found.detail


def test_r_4_4_12_02_03_crc_of_a_continuous_reply_after_the_retries_is_not_judged() -> None:
    """A late aRCn! reply without its CRC (continuous-crc-missing + replies-after-retry, seed
    4262) was skipped, so R-4.4.12-02 PASSed on the D replies alone: now undecided, counted
    against their PASS; likewise R-4.4.12-03 for a late aRn!."""
    pair = (_unanswered("0R0!", "0+22.1\r\n"), _unanswered("0RC0!", "0+22.1\r\n"))
    ids = ["R-4.4.8.1-01", "R-4.4.12-02", "R-4.4.12-03"]
    found = _by_rule(xjudge.continuous({0: pair}, ids))
    for rid, command in (("R-4.4.12-02", "0RC0!"), ("R-4.4.12-03", "0R0!")):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid].detail
        assert f"{command} -> late" in found[rid].detail, found[rid].detail


IDS = ("R-6.2-01", "R-6.2-05", "R-6.2-07")


def test_r_6_2_01_05_07_metadata_replies_after_the_retries_are_inconclusive() -> None:
    items = [
        (_unanswered("0IM_001!", "0,TA,degC;\r\n"), False, True),
        (_unanswered("0IM_004!", "0\r\n"), False, False),
    ]
    found = _by_rule(metadata.records(items, IDS))
    for rid in IDS:
        assert found[rid].verdict is Verdict.INCONCLUSIVE, (rid, found[rid].detail)
        assert "answered only after the reply window" in found[rid].detail
        assert "got no reply" not in found[rid].detail


def test_r_6_2_01_05_07_silent_metadata_still_fails() -> None:
    items = [
        (_unanswered("0IM_001!", ""), False, True),
        (_unanswered("0IM_004!", ""), False, False),
    ]
    found = _by_rule(metadata.records(items, IDS))
    for rid in IDS:
        assert found[rid].verdict is Verdict.FAIL, (rid, found[rid].detail)


def test_r_6_2_01_one_late_one_silent_still_fails() -> None:
    """A late reply does not hide another command's silence."""
    items = [
        (_unanswered("0IM_001!", "0,TA,degC;\r\n"), False, True),
        (_unanswered("0IM_002!", ""), False, True),
    ]
    found = _by_rule(metadata.records(items, IDS))
    assert found["R-6.2-01"].verdict is Verdict.FAIL
    assert "0IM_002!" in found["R-6.2-01"].detail


def test_r_4_4_4_01_address_change_answered_after_the_retries_is_inconclusive() -> None:
    """Seen on the whole sim run with replies-after-retry: '9<CR><LF>' began during the
    retry of 0A9!, and R-4.4.4-01 FAILed '0A9! got no reply'."""
    from testcases.sensor.test_4_4_basic import unanswered_change

    found = unanswered_change(_unanswered("0A9!", "9\r\n"), "0A9!", "restored", [])
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "late '9<CR><LF>'" in found.detail
    silent = unanswered_change(_unanswered("0A9!", ""), "0A9!", "restored", ["t=0"])
    assert silent.verdict is Verdict.FAIL and "0A9! got no reply" in silent.detail


def test_late_only_names_the_late_reply_and_leaves_silence_alone() -> None:
    """R-4.4.5-03, R-4.4.8.1-02 and R-5.4-02 ask what a reply holds: one that came after the
    retries was not read, so they are INCONCLUSIVE, not "gave no values: '(silence)'"."""
    late = xjudge.late_only("R-4.4.8.1-02", _unanswered("0R1!", "0+1013.25\r\n"), "R1 alone")
    assert late is not None and late.verdict is Verdict.INCONCLUSIVE
    assert "late '0+1013.25<CR><LF>'" in late.detail
    assert xjudge.late_only("R-4.4.8.1-02", _unanswered("0R1!", ""), "R1 alone") is None


class _HighVolumeSensor:
    """aHA!/aHB! as the replies-after-retry sensor met them in the whole run."""

    def __init__(self, late: dict[str, str]) -> None:
        self.late = late

    def measurement(self, code: str) -> SimpleNamespace:
        return SimpleNamespace(start=_unanswered(f"0{code}!", self.late[code]))


def _r_5_4_02(late: dict[str, str]) -> Finding:
    record = CaseRecord("hv", "hv", ("R-5.4-02",))
    case = Case(record, preconditions=declared_on(high_volume_case, ("R-5.4-02",)))
    high_volume_case(_HighVolumeSensor(late), case)
    return _by_rule(record.findings)["R-5.4-02"]


def test_r_5_4_02_high_volume_answered_after_the_retries_is_inconclusive() -> None:
    found = _r_5_4_02({"HA": "0006120\r\n", "HB": "0006120\r\n"})
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "(silence)" not in found.detail


def test_r_5_4_02_silent_high_volume_still_warns() -> None:
    found = _r_5_4_02({"HA": "", "HB": "0006120\r\n"})
    assert found.verdict is Verdict.WARN and "0HA! -> '(silence)'" in found.detail, found.detail


def _answered(command: str, reply: str, t: float = 0.0) -> Exchange:
    cmd = _chars(command, t, TOOL)
    rep = _chars(reply, cmd[-1].end + 0.009, DUT)
    return Exchange(parse_command(command), command, [Attempt(None, cmd, rep, "ok", rep[-1].end)])


class _ContinuousMetadataSensor:
    """aR0! answered in time; each aIR0_001!/aIRC0_001! answered only after the retries (the
    whole replies-after-retry run: R-6.2-06 FAILed 'no record for 0IR0_001!')."""

    def __init__(self, record: str) -> None:
        self.record = record

    def exchange(self, code: str) -> Exchange:
        if code == "R0":
            return _answered("0R0!", "0+22.1\r\n")
        if code.startswith("I"):
            return _unanswered(f"0{code}!", self.record)
        return _answered(f"0{code}!", "0\r\n")


def _r_6_2_06(record: str) -> Finding:
    record_ = CaseRecord("irn", "irn", ("R-6.2-06",))
    case = Case(record_, preconditions=declared_on(continuous_metadata_case, ("R-6.2-06",)))
    continuous_metadata_case(_ContinuousMetadataSensor(record), case)
    return _by_rule(record_.findings)["R-6.2-06"]


def test_r_6_2_06_continuous_metadata_after_the_retries_is_inconclusive() -> None:
    found = _r_6_2_06("0,TA,degC;\r\n")
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "no record for" not in found.detail


def test_r_6_2_06_silent_continuous_metadata_still_fails() -> None:
    found = _r_6_2_06("")
    assert found.verdict is Verdict.FAIL and "no record for 0IR0_001!" in found.detail


def _d0_after_service_request(reply_after_retry: float) -> Measurement:
    """0M! with a service request ending at 1.0 s; 0D0! 9 ms later unanswered, its retry
    (no break) answered ``reply_after_retry`` s after the retry's end."""
    start = _answered("0M!", "00013\r\n")
    m = Measurement(start.command, start, ttt=1, count=3)
    m.service_request_end = 1.0
    first = _chars("0D0!", 1.009, TOOL)
    retry = _chars("0D0!", first[-1].end + 0.055, TOOL)
    reply = _chars("0+1+2+3\r\n", retry[-1].end + reply_after_retry, DUT)
    m.data.append(
        Exchange(
            parse_command("0D0!"),
            "0D0!",
            [
                Attempt(None, first, [], NO_REPLY, first[-1].end + 0.03, 0, 0),
                Attempt(None, retry, reply, "ok", reply[-1].end, 0, 1),
            ],
        )
    )
    return m


class _ServiceRequestSensor:
    uncertainty = 0.0

    def __init__(self, m: Measurement) -> None:
        self.m = m

    def defined(self, _codes: tuple[str, ...]) -> list[Measurement]:
        return [self.m]


def _r_7_1_02(reply_after_retry: float) -> Finding:
    record = CaseRecord("sr", "sr", ("R-7.1-02",))
    case = Case(record, preconditions=declared_on(sr_case, ("R-7.1-02",)))
    sr_case(_ServiceRequestSensor(_d0_after_service_request(reply_after_retry)), case)
    return _by_rule(record.findings)["R-7.1-02"]


def test_r_7_1_02_reply_at_the_retry_may_be_the_first_d0s_late_reply() -> None:
    """The whole replies-after-retry run: the reply began 0 ms after the retry (80 ms after
    the first aD0!), and R-7.1-02 FAILed 'no reply'."""
    found = _r_7_1_02(0.0)
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "answered only after its reply window" in found.detail


def test_r_7_1_02_a_retry_answered_in_time_is_the_retrys_and_still_fails() -> None:
    found = _r_7_1_02(0.009)
    assert found.verdict is Verdict.FAIL and "no reply" in found.detail, found.detail


def test_r_4_4_2_01_identification_answered_after_the_retries_is_inconclusive() -> None:
    """replies-after-retry + parity-error behind ``emulate --echo --usb-latency 16``: the
    late '014CONFORM...' met the retry, was set aside as contention, and "aI! got no reply"
    FAILed R-4.4.2-01/-02, which the sim's exact stamps never showed (outside28)."""
    ex = _unanswered("0I!", "014CONFORM EMU001100SN0001\r\n")
    ident, findings = xjudge.identification(ex, "0")
    assert ident is None
    for rid, found in _by_rule(findings).items():
        assert found.verdict is Verdict.INCONCLUSIVE, (rid, found.detail)
        assert "answered only after the reply window" in found.detail
        assert "got no reply" not in found.detail


def test_r_4_4_2_01_silent_identification_still_fails() -> None:
    _, findings = xjudge.identification(_unanswered("0I!", ""), "0")
    assert [f.verdict for f in findings] == [Verdict.FAIL, Verdict.FAIL]
    assert all("aI! got no reply" in f.detail for f in findings)


def _binary_findings(late: str) -> dict[str, Finding]:
    """0HB! answered '0002033', its 0DB0! unanswered in three windows, ``late`` (if any) its
    packet met by the retry; R-5.2-02 and R-5.2-07 as the binary data judge leaves them."""
    from conformance.judges.measurements import data_violations
    from conformance.judges.tally import Tally

    start = _answered("0HB!", "0002033\r\n")
    m = Measurement(start.command, start, ttt=2, count=33)
    m.data.append(_unanswered("0DB0!", late, t=3.0))
    tally = Tally(("R-5.2-02", "R-5.2-07"))
    data_violations(m, tally)
    return _by_rule(tally.findings())


def test_r_5_2_02_binary_packet_after_the_retries_is_inconclusive() -> None:
    """replies-after-retry + parity-error behind ``emulate --echo --usb-latency 16``: 0DB0!'s
    packet came 80 ms late, met the retry and was set aside as contention; "no packet
    returned for 0DB0!" FAILed R-5.2-02, where the sim's stamps left it INCONCLUSIVE
    (outside28)."""
    found = _binary_findings("0\x04\x00\x01\x00\x7f\x00\x7f#\x04")
    assert found["R-5.2-02"].verdict is Verdict.INCONCLUSIVE, found["R-5.2-02"].detail
    assert "answered only after the reply window" in found["R-5.2-02"].detail
    assert found["R-5.2-07"].verdict is Verdict.INCONCLUSIVE, found["R-5.2-07"].detail


def test_r_5_2_02_silent_binary_data_still_fails() -> None:
    found = _binary_findings("")
    assert found["R-5.2-02"].verdict is Verdict.FAIL
    assert "no packet returned for 0DB0!" in found["R-5.2-02"].detail
