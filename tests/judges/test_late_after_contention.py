"""A late reply to a D whose last try met contention, taken as aC!'s start reply (truth28).

Behind ``emulate --echo --jitter 2`` (faults no-recovery-after-abort, replies-after-retry,
parity-error; ±1.96 ms stamps) 0D0!'s last try met the sensor's reply to the try before
(bus contention), the sensor's late reply to that last try was held by the next command,
0C!, on the line and began 96 ms after the try, 0.00 ms after 0C! ended, and R-4.4.7-01
FAILed "0C!: reply '0+1+0+12.6' does not have the form atttnn": the engine linked no
``late_before`` after a try with reply characters, and the 87 ms counted from the held
start with no uncertainty. Hand-typed events, failing on main-s65d.
"""

from __future__ import annotations

from types import SimpleNamespace

from conformance.judges import measurements as mjudge
from conformance.judges.late_before import earlier_reply
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.sensor.buffer_watch import WatchedToolRecorder
from conformance.tool_recorder.records import (
    CONTENTION,
    NO_REPLY,
    OK,
    Attempt,
    Exchange,
    Measurement,
)
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict
from tests.support.hand_events import chars

LATE = 0.080  # replies-after-retry: every reply 80 ms after the command heard
JITTER = 1.96e-3  # the bench's measured stamp uncertainty
D_REPLY = "0+1+0+12.6\r\n"


def _d_after_contention(u: float) -> Exchange:
    """0D0!: its first try unanswered in its window, its retry met by the first try's late
    reply (begun while the retry was still on the line)."""
    first = chars(TOOL, "0D0!", 0.0, uncertainty=u)
    retry = chars(TOOL, "0D0!", 0.095, uncertainty=u)
    met = chars(DUT, D_REPLY, first[-1].end + LATE, uncertainty=u)
    tries = [
        Attempt(None, first, [], NO_REPLY, 0.06),
        Attempt(None, retry, met, f"{CONTENTION} (hand-typed)", met[-1].end, retry=1),
    ]
    return Exchange(cmds.parse_command("0D0!"), "0D0!", tries)


def _c_taking(d: Exchange, u: float, after_c: float = 0.0) -> Exchange:
    """0C! sent so that it ends 96 ms after ``d``'s last try, taking ``D_REPLY`` begun
    ``after_c`` s after 0C! ended (0: held by 0C!, as on the bench)."""
    end = d.last.command_end
    assert end is not None
    sent = chars(TOOL, "0C!", end + 0.096 - 3 * CHAR_TIME, uncertainty=u)
    got = chars(DUT, D_REPLY, sent[-1].end + after_c, uncertainty=u)
    return Exchange(cmds.parse_command("0C!"), "0C!", [Attempt(None, sent, got, OK, got[-1].end)])


def _linked(d: Exchange, c: Exchange) -> Exchange:
    """``c`` as the session's engine leaves it after ``d``, the sensor seen late."""
    engine = SimpleNamespace(watch=SimpleNamespace(late=SimpleNamespace(start=LATE)))
    return WatchedToolRecorder._link_late_before(engine, d, c, True)  # type: ignore[arg-type]


def _r_4_4_7_01(c: Exchange) -> Verdict:
    (found,) = mjudge.judge([Measurement(c.command, c)], ["R-4.4.7-01"], "14")
    return found.verdict


def test_the_engine_links_a_command_after_a_last_try_that_met_contention() -> None:
    d = _d_after_contention(JITTER)
    c = _linked(d, _c_taking(d, JITTER))
    assert c.late_before is d  # None on main-s65d


def test_r_4_4_7_01_a_held_late_d_reply_behind_a_jittery_bench_is_not_c_s() -> None:
    d = _d_after_contention(JITTER)
    c = _linked(d, _c_taking(d, JITTER))
    assert "is 0D0!'s late reply (96.00 ms after it)" in earlier_reply(c)
    assert _r_4_4_7_01(c) is Verdict.INCONCLUSIVE  # FAIL on main-s65d


def test_r_4_4_7_01_a_wrong_reply_begun_well_after_c_is_c_s_own() -> None:
    """The same words begun 9 ms after 0C! ended: 105 ms after 0D0!'s last try, past the
    87 ms and the stamps' uncertainty, so they answer 0C! (wrongly)."""
    d = _d_after_contention(JITTER)
    c = _linked(d, _c_taking(d, JITTER, after_c=0.009))
    assert earlier_reply(c) == ""
    assert _r_4_4_7_01(c) is Verdict.FAIL


def test_in_virtual_time_the_87_ms_are_not_widened() -> None:
    """On the sim (no uncertainty) the held start was due 87.67 ms after the last try: past
    the 87 ms, the reply is 0C!'s."""
    d = _d_after_contention(0.0)
    c = _linked(d, _c_taking(d, 0.0))
    assert earlier_reply(c) == ""
    assert _r_4_4_7_01(c) is Verdict.FAIL


def test_a_sensor_never_seen_late_links_nothing_after_contention() -> None:
    d = _d_after_contention(JITTER)
    engine = SimpleNamespace(watch=SimpleNamespace(late=SimpleNamespace(start=None)))
    c = WatchedToolRecorder._link_late_before(engine, d, _c_taking(d, JITTER), False)  # type: ignore[arg-type]
    assert c.late_before is None
    assert _r_4_4_7_01(c) is Verdict.FAIL
