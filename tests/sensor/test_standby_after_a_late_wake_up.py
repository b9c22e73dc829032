"""R-7.0-15's marking counts from the last sensor character the wake-up or the probe heard,
not from the wake-up's judged reply alone (outside28): replies-after-retry + parity-error +
no-recovery-after-abort behind ``emulate --echo --usb-latency 16``. The wake-up 0!'s reply
(80 ms late) met its retry; its third try was answered 71 ms after it, past its window, and
that '0<CR><LF>' was still on the line when the probe went "150.91 ms after a reply": the
sensor, awake, answered it, and R-7.0-15 FAILed "answered although ... put it in standby".
The sim's exact stamps never put a late reply there (R-7.0-15 PASSed)."""

from __future__ import annotations

from conformance.protocol import commands as cmds
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from testcases.sensor.test_7_timing import _marking_since_sensor
from tests.support.hand_events import chars


def _wake_up(late_third: bool) -> Exchange:
    """0! at 0 s, its reply taken at 0.104 s (met the retry), a third try at 0.160 s whose
    late reply (``late_third``) begins 0.256 s and ends 0.281 s."""
    first = chars(TOOL, "0!", 0.0)
    retry = chars(TOOL, "0!", 0.080)
    reply = chars(DUT, "0\r\n", 0.104)
    third = chars(TOOL, "0!", 0.160)
    late = chars(DUT, "0\r\n", 0.256) if late_third else []
    attempts = [
        Attempt(None, first, [], NO_REPLY, first[-1].end + 0.03, 0, 0),
        Attempt(None, retry, reply, OK, reply[-1].end, 0, 1),
        Attempt(None, third, [], NO_REPLY, third[-1].end + 0.03, 0, 2, late),
    ]
    return Exchange(cmds.parse_command("0!"), "0!", attempts)


def _probe(at: float) -> Exchange:
    sent = chars(TOOL, "0!", at)
    return Exchange(cmds.parse_command("0!"), "0!", [Attempt(None, sent, [], NO_REPLY, at + 0.05)])


def test_a_late_reply_after_the_judged_one_ends_the_quiet() -> None:
    wake, probe = _wake_up(late_third=True), _probe(0.280)
    assert _marking_since_sensor([wake, probe], probe) < 0.0  # the LF still on the line


def test_a_quiet_line_counts_from_the_reply() -> None:
    wake, probe = _wake_up(late_third=False), _probe(0.230)
    assert abs(_marking_since_sensor([wake, probe], probe) - (0.230 - (0.104 + 3 * 0.00833))) < 1e-3


def test_characters_met_by_the_probe_count_when_begun_before_it() -> None:
    """The sensor's characters the probe's own try met (bus contention), begun before it."""
    sent = chars(TOOL, "0!", 0.300)
    met = chars(DUT, "\n", 0.295)
    probe = Exchange(
        cmds.parse_command("0!"), "0!", [Attempt(None, sent, [], NO_REPLY, 0.35, 0, 0, met)]
    )
    wake = _wake_up(late_third=False)
    assert _marking_since_sensor([wake, probe], probe) < 0.0
