"""How late the sensor was seen to start a reply, from what came back between the tool's tries.

A one-shot probe (a command sent once after a timed break or marking, no retry) is listened
to for the engine's first-character timeout, 30 ms. A sensor whose every reply starts 80 ms
after its command (the Arduino Due sensor's ``delay(80)``, fault replies-after-retry) answers
it after the tool has stopped listening, and the probe's rule read "no reply" (R-7.0-05/-07/
-16, truth12). The engine's own exchanges show such a sensor before any probe: a try goes
unanswered and its reply arrives during or just before the retry (the retry's stray
characters). :class:`LateStartWatch` keeps the latest such start, measured from the try it
answers, so a probe from that sensor can listen that long (bounded) and its silence is
evidence again; a sensor never seen late costs nothing.
"""

from __future__ import annotations

from ..judges.wire import EARLY_WINDOW
from ..protocol.timing import NO_BREAK_WINDOW
from ..tool_recorder.records import Attempt
from ..transcript import DUT
from ..view.sides import expected_reply_address

#: The latest start (s) believed: beyond the 87 ms a recorder may wait before it must break
#: again, a start is no reply to a try the retry followed 55 ms after it.
LATE_START_MAX = NO_BREAK_WINDOW
#: How long (s) :meth:`~.session.SensorSession.late_start_probe` listens after its one
#: ``a!``: far past any reply the recorder's retry 55 ms after a try would have met (the Due
#: sensor's 80 ms); also the bound on the rest of a late reply once it began
LATE_START_LISTEN = 1.0


class LateStartWatch:
    """The latest reply start seen after an unanswered try, from the try (s), or None."""

    def __init__(self) -> None:
        self._start: float | None = None
        self._late = 0  # unanswered tries whose reply came late, as above
        self._early = 0  # first tries answered sooner than R-7.0-09's 7.93 ms
        self._previous: tuple[Attempt, str] | None = None

    @property
    def start(self) -> float | None:
        """The latest start seen (s), None if none, or if the sensor answered first tries too
        soon as often: then a retry's reply begun too soon is its own (the sim's
        response-too-early sensor answers 5 ms after every command: read as the late reply
        to an unanswered try before it, its standby probes were listened to for nothing).
        Counted, not any: a late sensor's reply that lands just after the next command is
        "too soon" too (answers-foreign-address + replies-after-retry, seed 4500..)."""
        return self._start if self._late > self._early else None

    def note(self, attempt: Attempt, text: str) -> None:
        """``attempt`` of the command ``text`` as the engine made it. After an unanswered try,
        a retry's stray characters (queued before it went out, or met by it) that began
        after that try ended, or its reply begun too soon to answer it (under R-7.0-09's
        7.93 ms: the 80 ms sensor's reply to a three-character command began as the retry
        ended), with the address a reply starts with, are the unanswered try's reply."""
        # (a retry: the same command again with no break; the engine numbers its tries
        # only once the hook has returned)
        previous, self._previous = self._previous, (attempt, text)
        reply = attempt.reply_events
        sent_end = attempt.command_end
        if previous is None or previous[1] != text or attempt.break_event is not None:
            if reply and sent_end is not None:  # a first try: answered too soon?
                self._early += not EARLY_WINDOW.inside(reply[0].start - sent_end)
            return
        before = previous[0]
        end = before.command_end
        if before.reply_events:
            return
        heard = [e for e in attempt.stray_events if e.origin == DUT]
        if not heard and reply and sent_end is not None:
            heard = [] if EARLY_WINDOW.inside(reply[0].start - sent_end) else reply
        if end is None or not heard or heard[0].start <= end:
            return
        address = expected_reply_address(text)
        if address is not None and heard[0].char7 != ord(address[0]):
            return
        late = heard[0].start - end
        if late <= LATE_START_MAX:
            self._late += 1
            self._start = late if self._start is None else max(self._start, late)
