"""Silence to tries none of which the sensor was awake to hear is no evidence (truth23).

slow-wake (110 ms after a break before it hears a start bit) behind ``emulate --echo
--jitter 2`` with two CPU burners: the tool came back more than 87 ms after each try, the
break rule put a break in front of every retry, and the 9 tries of 0IM_000! each began 9-20
ms after a break of its own: R-6.2-05 FAILed "0IM_000! got no reply". After the aborting
break 0M! went 11 and 107 ms after it, the next retry behind a break of its own, and the
third sequence showed the sensor needed more than 109 ms: R-4.4.5.1-03 FAILed "ignored the
M sent right after the aborting break". The tries here are the run's, hand-built."""

from __future__ import annotations

from conformance.judges import exchanges as xjudge
from conformance.judges import metadata
from conformance.judges.wake_heard import (
    first_sequence_unheard,
    unheard,
    wake_shown,
    woken_unheard,
)
from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import CONTENTION, NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Finding, Verdict
from tests.support.hand_events import chars

BREAK = 13e-3


def _break(end: float, u: float = 0.0) -> Event:
    return Event(EventKind.BREAK, TOOL, end - BREAK, end, uncertainty=u)


def _exchange(command: str, tries: list[tuple[float | None, float, int, int]], reply=None):
    """``tries``: (break end or None, command start, sequence, retry) each; ``reply`` the
    index of the try answered '0\\r\\n'-like text (None: none)."""
    attempts = []
    for i, (brk, start, sequence, retry) in enumerate(tries):
        cmd = chars(TOOL, command, start)
        answered = reply is not None and i == reply
        got = chars(DUT, f"{command[0]}\r\n", cmd[-1].end + 0.01) if answered else []
        end = (got[-1].end if got else cmd[-1].end + 0.03) + 0.001
        a = Attempt(
            None if brk is None else _break(brk),
            cmd,
            got,
            OK if answered else NO_REPLY,
            end,
            sequence,
            retry,
        )
        attempts.append(a)
    return Exchange(parse_command(command), command, attempts)


def _own_breaks(command: str, t: float = 10.0, n: int = 9) -> Exchange:
    """Every try after a break of its own, 9-20 ms before it, ~190 ms apart (the run's)."""
    tries = []
    for i in range(n):
        brk = t + i * 0.19
        tries.append((brk, brk + 0.009 + (i % 3) * 0.005, i // 3, i % 3))
    return _exchange(command, tries)


def _sim_schedule(command: str, t: float = 10.0) -> Exchange:
    """One break a sequence, its retries without one, the last 169 ms after it (the sim's)."""
    tries = []
    for s in range(3):
        brk = t + s * 0.4
        tries += [(brk, brk + 0.009, s, 0), (None, brk + 0.089, s, 1), (None, brk + 0.169, s, 2)]
    return _exchange(command, tries)


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def test_invalid_index_unheard_behind_breaks_of_its_own_is_inconclusive() -> None:
    ex = _own_breaks("0IM_000!")
    found = _by_rule(metadata.records([(ex, False, False)], ("R-6.2-01", "R-6.2-05")))
    assert found["R-6.2-05"].verdict is Verdict.INCONCLUSIVE, found["R-6.2-05"].detail
    assert "none of its 9 tries" in found["R-6.2-05"].detail
    assert "9.00-19.00 ms" in found["R-6.2-05"].detail
    assert found["R-6.2-01"].verdict is Verdict.INCONCLUSIVE


def test_silence_to_a_try_past_the_wake_up_still_fails() -> None:
    """The sim's schedule puts a retry 169 ms after each break: silence there is evidence."""
    ex = _sim_schedule("0IM_000!")
    assert unheard(ex) == ""
    found = _by_rule(metadata.records([(ex, False, False)], ("R-6.2-01", "R-6.2-05")))
    assert found["R-6.2-05"].verdict is Verdict.FAIL
    assert "got no reply" in found["R-6.2-05"].detail


def test_a_try_with_no_break_before_it_is_heard_as_the_engine_judged() -> None:
    """A follow-up sent without a break went to a sensor the engine judged awake: its
    silence still counts."""
    ex = _exchange("0I!", [(None, 10.0, 0, 0), (10.12, 10.129, 1, 0), (10.3, 10.309, 2, 0)])
    assert unheard(ex) == ""
    assert xjudge.identification(ex, "0")[1][0].verdict is Verdict.FAIL


def test_the_uncertainty_of_the_stamps_counts_against_the_wake_up() -> None:
    """A retry 105 ms after its break, stamped to ±5 ms, is not surely past 100.4 ms."""
    brk = _break(10.0, u=5e-3)
    tries = [
        Attempt(brk, chars(TOOL, "0!", 10.009, uncertainty=5e-3), [], NO_REPLY, 10.07, 0, 0),
        Attempt(None, chars(TOOL, "0!", 10.105, uncertainty=5e-3), [], NO_REPLY, 10.16, 0, 1),
    ]
    ex = Exchange(parse_command("0!"), "0!", tries)
    assert "none of its 2 tries" in unheard(ex)
    tries[1].command_events[:] = chars(TOOL, "0!", 10.106)
    tries[0].break_event = _break(10.0)
    assert unheard(ex) == ""


def test_basic_commands_unheard_are_inconclusive_but_the_wake_rules_are_not() -> None:
    exchanges = [_own_breaks("0!"), _own_breaks("0I!", t=20.0)]
    found = xjudge.answered("R-4.4-01", exchanges, "it is a basic command", late_is_reply=True)
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    first = xjudge.answered("R-7.0-07", exchanges[:1], "x", first_attempt=True)
    assert first.verdict is Verdict.FAIL
    # one silent exchange heard for sure keeps the FAIL
    mixed = xjudge.answered("R-4.4-01", [*exchanges, _sim_schedule("0D0!")], "basic")
    assert mixed.verdict is Verdict.FAIL
    assert "0D0!" in mixed.detail and "0I!" not in mixed.detail


def test_acknowledge_and_identify_unheard_are_inconclusive() -> None:
    ack = xjudge.reply_only_address(_own_breaks("0!"), "0", "R-4.4.1-01", "a!")
    assert ack.verdict is Verdict.INCONCLUSIVE, ack.detail
    ident, found = xjudge.identification(_own_breaks("0I!"), "0")
    assert ident is None
    assert {f.verdict for f in found} == {Verdict.INCONCLUSIVE}


def _after_abort(third_try: float) -> tuple[Event, Exchange]:
    """The run's 0M! after the aborting break (end 88.8174): 11 and 107 ms after it without
    a break, then a retry behind a break of its own, a second sequence, and a third answered
    ``third_try`` after its break, its earlier tries 12 and 109 ms after it unanswered."""
    brk2 = _break(88.8174)
    tries = [
        (None, 88.8284, 0, 0),
        (None, 88.9247, 0, 1),
        (89.0448, 89.0625, 0, 2),
        (89.1490, 89.1613, 1, 0),
        (None, 89.2581, 1, 1),
        (None, 89.1490 + third_try, 1, 2),
    ]
    return brk2, _exchange("0M!", tries, reply=5)


def test_abort_m_unheard_while_the_sensor_was_shown_to_need_longer_is_no_evidence() -> None:
    brk2, ex = _after_abort(0.2088)
    assert abs(wake_shown(ex, brk2) - 0.1091) < 1e-4
    why = first_sequence_unheard(ex, brk2)
    assert "11.00, 107.30 ms after the aborting break" in why
    assert "109.1 ms" in why


def test_abort_m_ignored_by_a_sensor_quick_to_wake_still_counts() -> None:
    """The same tries, but the answered one came 9 ms after a break of its own: nothing
    shows the sensor needs more than 100 ms, and the 107 ms retry went unanswered."""
    brk2, ex = _after_abort(0.2088)
    ex.attempts[3].reply_events = list(ex.attempts[5].reply_events)
    ex.attempts[3].reason = OK
    del ex.attempts[4:]
    assert wake_shown(ex, brk2) == 100.4e-3
    assert first_sequence_unheard(ex, brk2) == ""


def test_abort_m_answered_in_the_first_sequence_needs_nothing() -> None:
    brk2, ex = _after_abort(0.2088)
    ex.attempts[2].reply_events = list(ex.attempts[5].reply_events)
    assert first_sequence_unheard(ex, brk2) == ""


def test_a_try_met_by_the_sensors_characters_is_set_aside() -> None:
    """0IMC3!'s own echo stalled 58 ms inside, the sensor's '00000' met it (contention), and
    the four retries each went 11-16 ms after a break of their own: R-6.1-01 FAILed."""
    ex = _exchange(
        "0IMC3!",
        [(None, 152.5565, 0, 0)]
        + [
            (b, b + d, 1 + i // 3, i % 3)
            for i, (b, d) in enumerate(
                [(152.8012, 0.0114), (152.9999, 0.0163), (153.1836, 0.0108), (153.3787, 0.0119)]
            )
        ],
    )
    first = ex.attempts[0]
    first.reason = CONTENTION + " (3 characters during the command)"
    first.stray_events = chars(DUT, "00000\r\n", 152.6610)
    found = xjudge.answered("R-6.1-01", [ex], "v1.4 makes them mandatory", late_is_reply=True)
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "none of its 4 tries (1 more met by the sensor's characters)" in found.detail
    first.reason = NO_REPLY  # the same first try, quiet: the engine judged the sensor awake
    first.stray_events = []
    assert xjudge.answered("R-6.1-01", [ex], "mandatory").verdict is Verdict.FAIL


def _one_shots(starts: list[float]) -> list[Exchange]:
    return [
        Exchange(
            parse_command("0!"),
            "0!",
            [Attempt(None, chars(TOOL, "0!", t), [], NO_REPLY, t + 0.05)],
        )
        for t in starts
    ]


def test_a_wake_up_retried_too_late_shows_nothing() -> None:
    """R-7.0-04's retries, meant 40 and 60 ms after the try before, went 225 and 253 ms after
    it on the loaded host: a sensor woken by the break may be in standby again by then."""
    brk = _break(349.9651)
    why = woken_unheard(_one_shots([349.9783, 350.2038, 350.4563]), brk, 3.6e-3)
    assert why.startswith("no try went while a sensor woken by the break must have been")
    assert "238.70 ms after the break" in why


def test_a_wake_up_retried_in_time_is_evidence() -> None:
    """The sim's schedule: 13 ms after the break, then 40 and 60 ms after each try's end."""
    brk = _break(10.0)
    starts = [10.013]
    starts.append(starts[-1] + 2 * CHAR_TIME + 0.04)
    starts.append(starts[-1] + 2 * CHAR_TIME + 0.06)
    assert woken_unheard(_one_shots(starts), brk, 0.0) == ""
