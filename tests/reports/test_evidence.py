"""Evidence where the FAIL is (issue 19): every FAIL, WARN and INCONCLUSIVE of a faulty run
points at the transcript events of the exchange it rests on (verdicts.json ``wire``), and the
HTML report shows that exchange, not another rule's (an R-4.2-03 FAIL on a D reply once came
with a ``?!`` diagram and "the run's other replies are in transcript.jsonl")."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

import jsonschema
import pytest

from conformance import cli
from conformance.reports.evidence import Locator, _named
from conformance.results import CaseRecord
from conformance.transcript import Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict
from tests.support.shared_runs import copied_run

NOTEWORTHY = ("FAIL", "WARN", "INCONCLUSIVE")
SCHEMA = json.loads(
    (Path(cli.__file__).parent / "schemas" / "verdicts-1.json").read_text(encoding="utf-8")
)


def faulty_run(tmp_path_factory, fault: str) -> tuple[Path, dict, list[dict]]:
    """The main command's run of ``fault``, made once a session (``wrong-crc`` is judged in
    tests/commands/test_passive.py too: tests/support/shared_runs.py), in a copy of its own."""
    into = tmp_path_factory.mktemp(fault) / "run"
    out, code = copied_run(tmp_path_factory, into, f"sim://?faults={fault}")
    assert code == cli.EXIT_NON_COMPLIANT
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    lines = (out / "transcript.jsonl").read_text(encoding="utf-8").splitlines()
    return out, data, [json.loads(line) for line in lines]


@pytest.fixture(scope="module")
def late(tmp_path_factory):
    """A sensor replying 20 ms after the command: timing FAILs, found by the measured value."""
    return faulty_run(tmp_path_factory, "response-too-late")


@pytest.fixture(scope="module")
def no_crlf(tmp_path_factory):
    """D replies without CR LF: R-4.2-03 FAILs on D replies, some INCONCLUSIVEs besides."""
    return faulty_run(tmp_path_factory, "missing-crlf")


@pytest.fixture(scope="module")
def bad_crc(tmp_path_factory):
    """CRCs that do not match: R-4.4.12-05 FAILs naming a measurement and its D read."""
    return faulty_run(tmp_path_factory, "wrong-crc")


def noteworthy(data: dict) -> list[tuple[str, dict]]:
    return [
        (r["id"], f)
        for r in data["requirements"]
        for f in r["findings"]
        if f["verdict"] in NOTEWORTHY
    ]


def wire_text(events: list[dict], origin: str | None = None) -> str:
    return "".join(
        chr(e["wire"] & 0x7F)
        for e in events
        if e["kind"] == "char" and (origin is None or e["origin"] == origin)
    )


@pytest.mark.parametrize("which", ["late", "no_crlf", "bad_crc"])
def test_every_noteworthy_finding_points_at_transcript_events(which, request):
    _, data, transcript = request.getfixturevalue(which)
    found = noteworthy(data)
    assert found
    jsonschema.Draft202012Validator(SCHEMA).validate(data)
    for rid, f in found:
        wire = f["wire"]
        assert wire is not None, (rid, f["detail"])
        first, last = wire["transcript_events"]
        assert 0 <= first <= last < len(transcript)
        span = [e for e in transcript[first : last + 1] if e["kind"] != "note"]
        assert span, (rid, wire)
        assert wire["start_s"] == pytest.approx(min(e["start"] for e in span), abs=1e-6)
        assert wire["end_s"] == pytest.approx(max(e["end"] for e in span), abs=1e-6)
        if wire["exchange"] is not None:  # the exchange is the command the finding names
            sent = wire_text(span, "tool")  # "0MC! 0D0!": those commands, in that order
            assert sent.startswith(wire["exchange"].split()[0]), (rid, wire)
            assert re.search(".*".join(map(re.escape, wire["exchange"].split())), sent)
            named = " ".join([*f["evidence"], f["detail"]])
            assert wire["located_by"] == "measured" or wire["exchange"] in named, (rid, wire)


def test_a_framing_fail_points_at_the_d_reply_without_cr_lf(no_crlf):
    _, data, transcript = no_crlf
    framing = [
        f for rid, f in noteworthy(data) if rid == "R-4.2-03" and "test_reply_framing" in f["test"]
    ]
    assert framing
    wire = framing[0]["wire"]
    assert wire["exchange"] == "0D0!" and wire["located_by"] == "command"
    first, last = wire["transcript_events"]
    reply = wire_text(transcript[first : last + 1], "dut")
    assert reply.startswith("0+") and "\r\n" not in reply[:40]


def test_a_timing_fail_points_at_the_exchange_it_measured(late):
    _, data, transcript = late
    fails = [f for rid, f in noteworthy(data) if rid == "R-7.0-10"]
    assert fails
    for f in fails:
        wire = f["wire"]
        assert "measured" in wire["located_by"]
        first, last = wire["transcript_events"]
        span = transcript[first : last + 1]
        command = [e for e in span if e["kind"] == "char" and e["origin"] == "tool"]
        reply = [e for e in span if e["kind"] == "char" and e["origin"] == "dut"]
        delay_ms = (reply[0]["start"] - command[-1]["end"]) * 1e3
        assert delay_ms == pytest.approx(f["measured_ms"], abs=0.05)


def test_a_crc_fail_reaches_the_d_reply_that_carried_the_crc(bad_crc):
    """The CRC FAIL names '0MC! 0D0!': its reference used to stop at 0MC!'s service request,
    before the D reply whose CRC was wrong (the evidence was the unmarked line after it)."""
    _, data, transcript = bad_crc
    (fail,) = [
        f for rid, f in noteworthy(data)
        if rid == "R-4.4.12-05" and "test_crc_value_and_encoding" in f["test"]
    ]  # fmt: skip
    wire = fail["wire"]
    assert wire["exchange"] == "0MC! 0D0!" and wire["located_by"] == "command"
    first, last = wire["transcript_events"]
    crc = re.search(r"CRC '(...)' does not match", fail["detail"]).group(1)
    assert crc + "\r\n" in wire_text(transcript[first : last + 1], "dut"), wire


def test_the_html_marks_the_d_reply_a_crc_fail_rests_on(bad_crc):
    out, _, _ = bad_crc
    shown = case_extras(out, "test_crc_value_and_encoding")
    where = shown.split("Where: R-4.4.12-05 FAIL", 1)[1].split("<p><b>Wire:", 2)[1]
    hits = [line for line in where.splitlines() if "▶ " in line]
    assert any("→ sensor  0D0!" in h for h in hits), hits
    assert any("← sensor  0+22.15+1013.2+45.7DOm" in h for h in hits), hits


def case_extras(out: Path, name: str) -> str:
    """The HTML pytest-html shows for the case ``name`` (kept in the page's JSON blob)."""
    page = (out / "report.html").read_text(encoding="utf-8")
    blob = json.loads(html.unescape(re.search(r'data-jsonblob="([^"]*)"', page).group(1)))
    (runs,) = [v for k, v in blob["tests"].items() if k.endswith(f"::{name}")]
    return "".join(x["content"] for run in runs for x in run["extras"])


def test_the_html_shows_the_exchange_a_fail_rests_on(no_crlf):
    out, data, _ = no_crlf
    shown = case_extras(out, "test_reply_framing")
    assert "Where: R-4.2-03 FAIL</b> rests on the exchange 0D0!" in shown
    hits = [line for line in shown.splitlines() if '<span class="hit">' in line and "▶ " in line]
    assert any("→ sensor  0D0!" in h for h in hits), hits
    # the whole-run framing case no longer shows a diagram of some other exchange instead
    assert "other replies are in transcript.jsonl" not in shown


def test_the_html_of_a_timing_fail_draws_and_lists_its_exchange(late):
    out, _, _ = late
    shown = case_extras(out, "test_response_start_window")
    where = shown.split("Where: R-7.0-10", 1)[1].split('<div class="sdi12-where', 1)[0]
    assert "by command and measured" in where
    assert "<svg" in where and "→ sensor  ?!" in where


def _chars(origin: str, text: str, start: float) -> list[Event]:
    out = []
    for i, c in enumerate(text):
        t = start + i * 0.00833
        out.append(Event(EventKind.CHAR, origin, t, t + 0.00833, wire=to_wire_7e1(ord(c))))
    return out


def test_a_finding_naming_a_command_gets_that_exchange_not_a_neighbour():
    events = (
        _chars("tool", "0D0!", 0.0) + _chars("dut", "0+1\r\n", 0.045)
        + _chars("tool", "0D3!", 1.0) + _chars("dut", "0+2", 1.045)
        + _chars("tool", "?!", 2.0) + _chars("dut", "0\r\n", 2.03)
    )  # fmt: skip
    record = CaseRecord("t::c", "c", ("R-4.2-03",), window=(0, len(events)))
    record.evidence.append(("?!", events[-5:]))  # the case attached another rule's exchange
    finding = Finding("R-4.2-03", Verdict.FAIL, "no CR LF", evidence=["reply to 0D3!"], observed=1)
    ref = Locator(events).locate(finding, record)
    assert ref is not None and ref.exchange == "0D3!" and ref.how == "command"
    assert (ref.first, ref.last) == (9, 15)


def test_a_line_naming_a_measurement_and_its_read_spans_both():
    events = (
        _chars("tool", "0M!", 0.0) + _chars("dut", "00011\r\n", 0.04)
        + _chars("dut", "0\r\n", 1.1) + _chars("tool", "0D0!", 1.2)
        + _chars("dut", "0+1\r\n", 1.245) + _chars("tool", "0D0!", 2.0)
        + _chars("dut", "0+1\r\n", 2.045)
    )  # fmt: skip
    record = CaseRecord("t::c", "c", ("R-4.4.12-05",), window=(0, len(events)))
    finding = Finding("R-4.4.12-05", Verdict.FAIL, "0M! 0D0!: bad", evidence=["0M! 0D0!"])
    ref = Locator(events).locate(finding, record)
    assert ref is not None and ref.exchange == "0M! 0D0!" and ref.how == "command"
    assert (ref.first, ref.last) == (0, 21)  # through the first D reply's LF, not the second
    alone = Finding("R-4.4.12-05", Verdict.FAIL, "bad", evidence=["0M! 0D9!"])  # not on the wire
    assert Locator(events).locate(alone, record).exchange == "0M!"


def test_a_finding_naming_nothing_rests_on_its_cases_traffic():
    events = _chars("tool", "0D0!", 0.0) + _chars("dut", "0+1\r\n", 0.045)
    record = CaseRecord("t::c", "c", ("R-4.0-01",), window=(4, 9))
    finding = Finding("R-4.0-01", Verdict.INCONCLUSIVE, "no step exercised it")
    ref = Locator(events).locate(finding, record)
    assert ref is not None and (ref.first, ref.last, ref.exchange, ref.how) == (4, 8, None, "case")
    assert Locator(events).locate(finding, CaseRecord("t::d", "d", ("R-4.0-01",))) is None


def test_a_command_is_named_only_as_a_whole():
    assert _named("0M!", "reply to 0M! at t=1 s")
    assert not _named("0M!", "reply to 10M!")
    assert _named("?!", "?!")
