"""R-7.0-05 (decision A18): an answered early command whose timing the link cannot decide.

The early-address sensor (it takes an address right after the break) behind an echoing
interface with a 16 ms USB latency timer (``emulate --echo --usb-latency 16``, two CPU
burners beside, truth22): the "2 ms" probe's command was stamped 9.11 ms after the break,
±15.42 ms, and the sensor answered it. The case PASSed "ignored a command 9.11 ms after the
break": the branch for an ignored probe took every probe neither surely early and answered
nor surely late. An answer there is undecided. Hand-typed wire events; the first test's
verdict was PASS on base-s61 (its branch inline in ``test_marking_after_break``).
"""

from __future__ import annotations

from conformance.protocol import commands as cmds
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict
from testcases.sensor.test_7_timing import _early_probe
from tests.support.hand_events import chars

U = 15.42e-3  # the run's stamp uncertainty behind the 16 ms latency timer


def _probe(answered: bool) -> Exchange:
    """a! sent at 0 s, answered 9 ms after it (or not)."""
    sent = chars(TOOL, "0!", 0.0)
    got = chars(DUT, "0\r\n", sent[-1].end + 0.009) if answered else []
    end = got[-1].end if got else sent[-1].end + 0.03
    attempt = Attempt(None, sent, got, OK if got else NO_REPLY, end)
    return Exchange(cmds.parse_command("0!"), "0!", [attempt])


def test_an_answer_to_a_probe_not_surely_early_is_undecided() -> None:
    found = _early_probe(_probe(answered=True), 9.11e-3, 25.12e-3, U)
    assert found.verdict is Verdict.INCONCLUSIVE, found  # PASS "ignored a command" before
    assert "9.11 ± 15.42 ms" in found.detail


def test_an_answer_to_a_probe_surely_early_warns() -> None:
    found = _early_probe(_probe(answered=True), 2e-3, 9e-3, 0.5e-3)
    assert found.verdict is Verdict.WARN, found


def test_silence_to_an_early_probe_passes() -> None:
    found = _early_probe(_probe(answered=False), 9.11e-3, 25.12e-3, U)
    assert found.verdict is Verdict.PASS, found
    assert "ignored a command 9.11 ms after the break" in found.detail


def test_a_probe_surely_late_is_not_judged() -> None:
    found = _early_probe(_probe(answered=True), 9.5e-3, 25.12e-3, 0.5e-3)
    assert found.verdict is Verdict.PASS and "not judged" in found.detail, found
