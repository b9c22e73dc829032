"""R-4.3-03: an address change answered with what may be the command before's late reply.

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then) beside
parity-error and concurrent-zero (seed 6202, truth22): a 0! poll's second try drew
'0<CR><LF>' with a bad-parity LF, so the tool tried a third time, unanswered in its window;
that try's '0<CR><LF>' came 80 ms later, inside 0A2!'s window, and was read as 0A2!'s answer
naming the old address: "refused or lost address(es) 2" FAILed R-4.3-03, though the restore
found the sensor at '2'. The sweep's judge took only replies after the window as late
(``late_answer``), not a reply taken that may be the command before's (``earlier_reply``).
Hand-typed wire events; the first test fails on base-s61.
"""

from __future__ import annotations

from conformance.protocol import commands as cmds
from conformance.sensor.session import Sweep
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from testcases.sensor.test_4_addressing import _late_refusals
from tests.support.hand_events import chars

LATE = 0.080  # the sensor's reply start after the command it heard


def _exchange(text: str, t: float) -> Exchange:
    """``text`` sent once at ``t``, unanswered in its window."""
    sent = chars(TOOL, text, t)
    attempt = Attempt(None, sent, [], NO_REPLY, sent[-1].end + 0.03)
    return Exchange(cmds.parse_command(text), text, [attempt])


def _change_taking(reply: str, *, linked: bool) -> Exchange:
    """0! unanswered at 0 s, then 0A2! 30 ms after it ended taking ``reply``, begun 80 ms
    after 0! ended; linked to 0! as the session's engine links a sensor seen late."""
    before = _exchange("0!", 0.0)
    end = before.last.command_end
    assert end is not None
    change = _exchange("0A2!", end + 0.030)
    change.attempts[0].reply_events = chars(DUT, reply, end + LATE)
    change.attempts[0].reason = OK
    if linked:
        change.late_before = before
    return change


def _sweep(change: Exchange) -> Sweep:
    return Sweep([change], refused=["2"], restore_note="restored to '0'")


def test_a_change_taking_the_poll_before_s_late_reply_is_not_refused() -> None:
    change = _change_taking("0\r\n", linked=True)
    assert _late_refusals(["2"], [change], _sweep(change)) == {"2"}  # set() before


def test_a_sensor_never_seen_late_refuses_on_its_words() -> None:
    """No link (a sensor never seen late): '0<CR><LF>' is 0A2!'s own answer, a refusal."""
    change = _change_taking("0\r\n", linked=False)
    assert _late_refusals(["2"], [change], _sweep(change)) == set()


def test_a_reply_naming_the_new_address_is_the_change_s_own() -> None:
    """'2<CR><LF>' names 0A2!'s address and not 0!'s: its own answer, whatever came before
    (a refusal judged on it stands, here none: the sweep would not list '2')."""
    change = _change_taking("2\r\n", linked=True)
    assert _late_refusals(["2"], [change], _sweep(change)) == set()
