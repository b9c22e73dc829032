"""Issue 22, round 8: a D reply's framing and parse are read once a process for each reply
text and command (``measurements._read_data_reply``) and shared by every case that judges
the run's measurements. The findings must be those of reading each reply afresh: the same
text after a measurement that asks for a CRC and one that does not is two readings, the
reply's text still names it in a finding, and judging twice changes nothing."""

from __future__ import annotations

from conformance.judges import measurements
from conformance.tool_recorder.records import Measurement
from conformance.verdicts import Verdict

from .test_judges import exchange

IDS = ("R-4.4.12-02", "R-4.4.12-03", "R-4.4.8-02", "R-4.4-05", "R-4.4.8-03", "R-5.1-02")


def _measured(command: str, reply: str, data: list[tuple[str, str]]) -> Measurement:
    start = exchange(command, reply, 0.0)
    m = Measurement(start.command, start, ttt=int(reply[1:4]), count=int(reply[4:-2]))
    m.reply_end = start.reply_events[-1].end
    t = m.reply_end + 0.02
    for code, text in data:
        ex = exchange(code, text, t)
        m.data.append(ex)
        t = ex.end + 0.02
    return m


def _seen(findings) -> list[tuple[str, Verdict, str]]:
    return sorted((f.requirement, f.verdict, repr(f)) for f in findings)


def test_one_text_after_M_and_after_MC_is_read_twice_R_4_4_12_02() -> None:
    """'0+1.5' is right after aM! and lacks its CRC after aMC!: read after aM! first, the
    aMC! reading must still FAIL R-4.4.12-02 (a reading keyed by the text alone PASSed it)."""
    plain = _measured("0M!", "00011\r\n", [("0D0!", "0+1.5\r\n")])
    with_crc = _measured("0MC!", "00011\r\n", [("0D0!", "0+1.5\r\n")])
    first = {f.requirement: f.verdict for f in measurements.judge([plain], IDS, "14")}
    second = {f.requirement: f.verdict for f in measurements.judge([with_crc], IDS, "14")}
    assert first["R-4.4.12-03"] is Verdict.PASS
    assert second["R-4.4.12-02"] is Verdict.FAIL


def test_a_text_refused_past_d9_is_named_in_the_finding_R_5_1_02() -> None:
    """aHA!'s aD10! answered with text: R-5.1-02 FAILs naming the reply's body, which the
    shared reading hands back with the parse."""
    m = _measured("0HA!", "000120\r\n", [("0D10!", "0UNKN\r\n")])
    found = [f for f in measurements.judge([m], IDS, "14") if f.requirement == "R-5.1-02"]
    assert found and found[0].verdict is Verdict.FAIL
    assert "answered '0UNKN'" in repr(found[0])


def test_shared_readings_judge_as_fresh_ones(monkeypatch) -> None:
    """Judging the same measurements again (the readings held) and judging them with every
    reply read afresh give the same findings, word for word."""
    runs = [
        _measured("0M!", "00013\r\n", [("0D0!", "0+1.5-2+3\r\n")]),
        _measured("0MC!", "00012\r\n", [("0D0!", "0+1.5-2.25Ipv\r\n")]),
        _measured("0C!", "000202\r\n", [("0D0!", "0+1.5\r\n"), ("0D1!", "0+1.5\r\n")]),
        _measured("0M!", "00012\r\n", [("0D0!", "0+1.234567890123456789012345678901234\r\n")]),
    ]
    once = _seen(measurements.judge(runs, IDS, "14"))
    assert _seen(measurements.judge(runs, IDS, "14")) == once
    fresh = measurements._read_data_reply_once.__wrapped__
    monkeypatch.setattr(measurements, "_read_data_reply_once", fresh)
    assert _seen(measurements.judge(runs, IDS, "14")) == once
