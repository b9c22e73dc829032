"""Declared interactions between golden-recorder faults (the recorder combination matrix).

As for the emulator's faults (:mod:`conformance.emulator.faults.interactions`, whose
:class:`Interaction` this reuses): an entry records only where a combination genuinely changes
what a correct tool must say on the wire (one member hides another's deviation, or the two
together break a further rule), with its reason; never to make a row pass.
"""

from __future__ import annotations

from ..emulator.faults.interactions import Interaction

#: why a first try goes unheard by the played sensors
_UNHEARD = "short-marking's 5 ms of marking after every break leaves each first try unheard"

#: Found by ``sdi12-conform matrix --role recorder`` (seeds 1, 20, 21), each row read on its
#: transcript; the rows the tool got wrong were fixed in the judges instead.
RECORDER_INTERACTIONS: tuple[Interaction, ...] = (
    # masked: a retry that talks into the 15.0 ms reply
    Interaction(
        frozenset({"short-reply-timeout", "talks-over-reply"}),
        "talks-over-reply's retry goes out while reply-at-window-edge's 15.0 ms reply is on the"
        " line and their characters interleave, so no reply to aM! there is ever valid: the"
        " whole reply short-reply-timeout ignores never reaches the wire, and the retries"
        " judged are after no reply, in time (R-7.2-06 and R-7.0-13 FAIL instead).",
        removes=("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-05", "R-4.4.8-05"),
    ),
    Interaction(
        frozenset({"retry-too-early", "short-reply-timeout"}),
        "retry-too-early's retry 12 ms after aM! runs into every 15.0 ms reply of"
        " reply-at-window-edge (its own R-7.0-13), so no valid reply there is ignored and no"
        " lost reply goes without its retry: short-reply-timeout's deviation is hidden.",
        removes=("R-7.2-01", "R-7.2-03", "R-7.2-05", "R-4.4.8-05"),
    ),
    # masked: no retry at all, so no retry that is late, unbroken or colliding
    *(
        Interaction(
            frozenset({never, other}),
            f"{never} sends no retry, so {other}'s retry without a break after 87 ms of"
            " marking never goes out: R-7.0-17 holds on the wire.",
            removes=("R-7.0-17",),
        )
        for never in ("no-retries", "retries-with-break")
        for other in ("retry-too-late", "resends-after-timeout")
    ),
    *(
        Interaction(
            frozenset({never, "talks-over-reply"}),
            f"{never} sends no retry, so talks-over-reply's retry never collides with a"
            " reply: every command goes out whole and R-7.0-13 holds on the wire.",
            removes=("R-7.0-13",),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    # true: retry-too-early's 10 ms reply timeout, hidden alone by its colliding retry
    *(
        Interaction(
            frozenset({never, "retry-too-early"}),
            "retry-too-early takes no reply by 10 ms as silence; alone its early retry collides"
            f" with the 15.0 ms reply (R-7.0-13). {never} sends no retry, so nothing collides"
            " (R-7.0-13 holds) and the whole reply is ignored: aM!'s values are never"
            " collected (R-4.4.8-05, true on the wire).",
            adds=("R-4.4.8-05",),
            removes=("R-7.0-13",),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    Interaction(
        frozenset({"retry-too-early", "short-marking"}),
        f"{_UNHEARD}, so retry-too-early's retry 12 ms later collides with nothing (R-7.0-13"
        " holds) and is answered 15.0 ms after it, past its 10 ms timeout: the reply is"
        " ignored, no retry follows the lost reply and aM!'s values are never collected"
        " (R-7.2-03, R-7.2-05, R-4.4.8-05: true on the wire, as short-reply-timeout's).",
        adds=("R-7.2-03", "R-7.2-05", "R-4.4.8-05"),
        removes=("R-7.0-13",),
    ),
    Interaction(
        frozenset({"short-marking", "short-reply-timeout"}),
        f"{_UNHEARD}; the retry without a break that follows it is on the wire, so the"
        " recorder shows that it retries (R-7.2-01 holds) while the reply it then ignores"
        " still goes without its retry (R-7.2-02/-03/-05 FAIL).",
        removes=("R-7.2-01",),
    ),
    Interaction(
        frozenset({"concurrent-ttt-zero-stalls", "no-concurrent"}),
        "no-concurrent sends no aC!, so no concurrent measurement with ttt = 000 is started"
        " for concurrent-ttt-zero-stalls to leave uncollected: R-4.4.8-05 holds on the"
        " measurements that ran (R-4.4.7-08 FAILs for both).",
        removes=("R-4.4.8-05",),
    ),
    Interaction(
        frozenset({"ignores-service-request", "no-break-after-87ms"}),
        "ignores-service-request sends aD0! only after the whole ttt, long after the service"
        " request, and no-break-after-87ms sends it without a break: aD0! 730 ms after the"
        " request with no break (R-7.1-01, true on the wire). Alone the first breaks and the"
        " second sends aD0! at once.",
        adds=("R-7.1-01",),
    ),
    Interaction(
        frozenset({"ignores-service-request", "short-break"}),
        "ignores-service-request sends aD0! only after the whole ttt, 749 ms and more after"
        " the service request, and short-break's 10 ms of spacing before it is no break"
        " (R-7.0-02): aD0! long after the request with no break (R-7.1-01, true on the wire;"
        " seed 7501, outside32). Alone the first breaks 12 ms and the second sends aD0! at"
        " once.",
        adds=("R-7.1-01",),
    ),
    Interaction(
        frozenset({"ignores-service-request", "late-d0-without-break"}),
        "ignores-service-request waits the whole ttt and sends aD0! after a break, so the"
        " unbroken aD0! 95 ms after the service request never goes out: R-7.1-01 holds on"
        " the wire (seed 22: 'a break before 0D0! after the service request').",
        removes=("R-7.1-01",),
    ),
    Interaction(
        frozenset({"ignores-service-request", "waits-forever-for-service-request"}),
        "ignores-service-request never waits for a service request (aD0! after the whole"
        " ttt), so waits-forever-for-service-request's endless wait for one never starts:"
        " every job ends and its values are collected (seed 23).",
        removes=("R-4.4.5-04", "R-4.4.5-06", "R-4.4.5-07", "R-4.4.8-05"),
    ),
    Interaction(
        frozenset({"ignores-bad-crc", "ignores-service-request", "no-break-after-87ms"}),
        "aD0! after the whole ttt without a break finds the sensor asleep, it and its"
        " unbroken retries unheard; the break+aD0! that follows draws bad-crc-once's bad CRC,"
        " which ignores-bad-crc takes as valid: the job ends after two sequences, the second"
        " without a retry after an invalid reply (R-7.2-03, R-7.2-04: true on the wire,"
        " seed 23).",
        adds=("R-7.2-03", "R-7.2-04"),
    ),
    Interaction(
        frozenset({"resends-after-timeout", "short-reply-timeout"}),
        "reply-at-window-edge: each break+aM! draws a valid 15.0 ms reply that the 10 ms"
        " timeout ignores, and each is followed by two unbroken resends 1.5 s later, unheard"
        " by the sleeping sensor; after the third break+aM! the last two resends go"
        " unanswered and the recorder stops, its last command with no valid reply and no"
        " break+command sequence after it (R-7.2-04, SHOULD: true on the wire, seeds 22-24;"
        " alone, resends-after-timeout's last sequence draws a reply it takes).",
        adds=("R-7.2-04",),
    ),
    # masked: with every try after a break unheard, no aM! starts on two sensors at once
    *(
        Interaction(
            frozenset({"interleaves-measurements", never, "short-marking"}),
            f"{_UNHEARD} and {never} never retries without a break, so no aM! of"
            " two-sensors is ever answered: no measurement runs to be interleaved, and the"
            " service-request rules PASS on the other scenarios' measurements.",
            removes=("R-4.4.5-05", "R-4.4.5-06", "R-4.4.5-07"),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    *(
        Interaction(
            frozenset({"ttt-8-bit", never, "short-marking"}),
            f"{_UNHEARD} and {never} never retries without a break, so ttt-over-255's aM! is"
            " never answered: no ttt of 260 s reaches the recorder to be cut to 8 bits"
            " (seed 23).",
            removes=("R-4.4.5-04", "R-4.4.5-07"),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    # masked: with every try after a break unheard, no aC! announces ttt = 000
    *(
        Interaction(
            frozenset({"concurrent-ttt-zero-stalls", never, "short-marking"}),
            f"{_UNHEARD} and {never} never retries without a break, so neither sensor of"
            " concurrent-ttt-zero ever answers its aC! (seed 43: six break+aC! tries, no"
            " reply, logged {'0C!': [], '1C!': []}): no concurrent measurement announcing"
            " ttt = 000 starts for concurrent-ttt-zero-stalls to leave uncollected, and"
            " R-4.4.8-05 holds on the six measurements that ran (R-4.4.7-08 still FAILs).",
            removes=("R-4.4.8-05",),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    Interaction(
        frozenset({"ignores-service-request", "late-d0-without-break", "short-marking"}),
        "ignores-service-request waits the whole ttt and sends aD0! after a break, so"
        " late-d0-without-break's skipped break is left over; beside it alone the next"
        " command takes it (1M! to a new sensor with no break: R-7.0-17). Here"
        f" {_UNHEARD}, and the retry without a break that follows it (which needs none)"
        " takes the skip: 1M! goes out after a break, every unbroken command comes 9-45 ms"
        " after the line's last activity and R-7.0-17 holds on the wire (seed 50).",
        removes=("R-7.0-17",),
    ),
    Interaction(
        frozenset({"ignores-service-request", "interleaves-measurements", "late-d0-without-break"}),
        "ignores-service-request waits the whole ttt and sends aD0! after a break, so"
        " late-d0-without-break's skipped break is left over; beside it alone the next"
        " command takes it (1M! to a new sensor in two-sensors: R-7.0-17). Here"
        " interleaves-measurements sends 1M! before 0D0! (after a break), and each skip falls on"
        " a command that needs no break (the same sensor, within 87 ms: 8 skips, at 2.417 s,"
        " 286.145 s ...): R-7.0-17 holds on the wire ('62 commands without a break,"
        " 9.00..45.00 ms', seed 5).",
        removes=("R-7.0-17",),
    ),
    # masked: with every try after a break unheard, no measurement with values past D0 runs
    *(
        Interaction(
            frozenset({never, "short-marking", "stops-after-d0"}),
            f"{_UNHEARD} and {never} never retries without a break, so d0-to-d2's 0M2!,"
            " concurrent-99's 0C9! and aHA!/aHB! are never answered (three break+command"
            " tries each, logged {'0M2!': []}): no measurement whose values go past D0 reaches"
            " stops-after-d0, and R-4.4.8-05 holds on the six that ran, each whole in D0"
            " (0M1!, 0MC!, 0V!, 0C!, 0C1!, 0CC!; seed 1).",
            removes=("R-4.4.8-05",),
        )
        for never in ("no-retries", "retries-with-break")
    ),
    # masked: breaks-over-long-reply never retries without a break (all pairs, stop 48)
    *(
        Interaction(
            frozenset({"breaks-over-long-reply", other}),
            "breaks-over-long-reply never retries without a break (it breaks and sends the"
            f" command again instead), so {other}'s unbroken retry after 87 ms of marking"
            " never goes out: R-7.0-17 holds on the wire ('42 commands without a break,"
            " 9.00..9.00 ms').",
            removes=("R-7.0-17",),
        )
        for other in ("retry-too-late", "resends-after-timeout")
    ),
    *(
        Interaction(
            frozenset({"breaks-over-long-reply", other}),
            "breaks-over-long-reply never retries without a break, so"
            f" {other}'s retry into reply-at-window-edge's 15.0 ms reply never goes out:"
            " every command goes out whole and R-7.0-13 holds on the wire (325 gaps,"
            " 0.00 ms).",
            removes=("R-7.0-13",),
        )
        for other in ("talks-over-reply", "retry-too-early")
    ),
    Interaction(
        frozenset({"breaks-over-long-reply", "no-concurrent"}),
        "no-concurrent sends no aC!, so aC9!'s 75-character D0 reply, the one measurement"
        " whose data breaks-over-long-reply gives up at D0, is never asked for: R-4.4.8-05"
        " holds on the measurements that ran (R-7.2-06 and R-5.4-01 still FAIL on aHA!'s"
        " long reply).",
        removes=("R-4.4.8-05",),
    ),
    Interaction(
        frozenset({"no-retries", "short-reply-timeout"}),
        "no-retries gives a try up when no reply has started 10 ms after the command"
        " (short-reply-timeout's timeout) and sends nothing more, so reply-at-window-edge's"
        " 15.0 ms reply starts after the job ended: no measurement was announced to the"
        " recorder and R-4.4.8-05 is owed nothing (a reply after the job's end, seventeenth"
        " outside round); short-reply-timeout's other rules FAIL for no-retries as well.",
        removes=("R-4.4.8-05",),
    ),
)
