"""R-7.0-15's marking counts from the last character on the line the wake-up or the probe holds,
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


def _wake_up(third: str) -> Exchange:
    """0! at 0 s, its reply taken at 0.104 s (met the retry); ``third``: "none" (no third
    try), "silent" (a third try at 0.160 s, unanswered) or "late" (that try's late reply
    begins 0.256 s and ends 0.281 s)."""
    first = chars(TOOL, "0!", 0.0)
    retry = chars(TOOL, "0!", 0.080)
    reply = chars(DUT, "0\r\n", 0.104)
    attempts = [
        Attempt(None, first, [], NO_REPLY, first[-1].end + 0.03, 0, 0),
        Attempt(None, retry, reply, OK, reply[-1].end, 0, 1),
    ]
    if third != "none":
        sent = chars(TOOL, "0!", 0.160)
        late = chars(DUT, "0\r\n", 0.256) if third == "late" else []
        attempts.append(Attempt(None, sent, [], NO_REPLY, sent[-1].end + 0.03, 0, 2, late))
    return Exchange(cmds.parse_command("0!"), "0!", attempts)


def _probe(at: float) -> Exchange:
    sent = chars(TOOL, "0!", at)
    return Exchange(cmds.parse_command("0!"), "0!", [Attempt(None, sent, [], NO_REPLY, at + 0.05)])


def test_a_late_reply_after_the_judged_one_ends_the_quiet() -> None:
    wake, probe = _wake_up("late"), _probe(0.280)
    assert _marking_since_sensor([wake, probe], probe) < 0.0  # the LF still on the line


def test_a_quiet_line_counts_from_the_reply() -> None:
    wake, probe = _wake_up("none"), _probe(0.230)
    assert abs(_marking_since_sensor([wake, probe], probe) - (0.230 - (0.104 + 3 * 0.00833))) < 1e-3


def test_characters_met_by_the_probe_count_when_begun_before_it() -> None:
    """The sensor's characters the probe's own try met (bus contention), begun before it."""
    sent = chars(TOOL, "0!", 0.300)
    met = chars(DUT, "\n", 0.295)
    probe = Exchange(
        cmds.parse_command("0!"), "0!", [Attempt(None, sent, [], NO_REPLY, 0.35, 0, 0, met)]
    )
    wake = _wake_up("none")
    assert _marking_since_sensor([wake, probe], probe) < 0.0


def test_a_later_try_of_the_wake_up_ends_the_quiet() -> None:
    """Behind ``--echo --jitter 2`` a third try went 73 ms before the probe, "115.94 ms after
    a reply": the line's activity is the tool's command too, and the sensor answered it."""
    wake, probe = _wake_up("silent"), _probe(0.2505)
    third_end = wake.attempts[2].command_events[-1].end
    assert abs(_marking_since_sensor([wake, probe], probe) - (0.2505 - third_end)) < 1e-9
