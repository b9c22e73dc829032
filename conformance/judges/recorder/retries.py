"""Retry reconstruction (section 7.2) and the judges of retries: consecutive transmissions
of one command text, each with its reply's problem, split into break+command+retries
sequences.

A retry, as section 7.2 defines it, is the same command sent again without a break while the
sensor is still awake. A break and the command again is a new sequence, not a retry; so is the
command sent again without a break after the sensor's 100 ms to standby (R-7.0-15: it cannot
hear it as a retry). A PASS of R-7.2-01, R-7.2-04 or R-7.2-06 rests only on retries inside
the 87 ms window of R-7.2-02 (a logger that only ever repeats break + command, or re-sends
after a long poll timeout, must not pass "implements retries")."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field

from ...links.host_stall import REACH, Stall, stalled_over
from ...protocol.timing import (
    CHAR_TIME,
    RESPONSE_START_MAX,
    RETRY_AFTER_BREAK,
    RETRY_MAX,
    RETRY_MIN,
    STANDBY_MARKING,
    TOLERANCE,
)
from ...transcript import escape
from ...verdicts import Finding, Verdict
from ...view.segments import TranscriptView, Transmission, memo
from ..reply_validity import NO_REPLY, STX, Reason, ReplyProblem
from ..tally import Tally
from ..timing import MeasuredAsJudged, Repeats, Window, judge_window
from .common import combine, own_uncertainty
from .logged import same_values
from .replies import crc_context, cut_off, reply_problem
from .stalls import fail_unless_stalled, hold

#: Marking after which a sensor is in standby (R-7.0-15, +0.40 ms): a command sent again
#: without a break after longer than this is not a retry but a new try without its break.
STANDBY = STANDBY_MARKING + TOLERANCE
#: Latest start of a retry (R-7.2-02: 87 ms, +0.40 ms) that a PASS may rest on.
WINDOW = RETRY_MAX + TOLERANCE
#: R-7.2-02's window for a retry after no reply (16.67-87 ms after the command)
RETRY_WAIT = Window("R-7.2-02", "retry after no reply", low=RETRY_MIN, high=RETRY_MAX)
#: The catalog decision that says what counts as a retry (and cites these two figures).
RETRY_DECISION = "T2"
#: The longest single-line reply a sensor may give (address, 75 value characters after aHA!,
#: aCn!, aRn!, a CRC, CR LF): a break over a reply heard shorter than this, whose last
#: character had not yet been followed by 8.33 ms of marking, cut a response that may
#: still have been on its way to completing (section 7.2).
LONGEST_LINE = 1 + 75 + 3 + 2


@dataclass
class Try:
    sent: Transmission
    problem: ReplyProblem | None  # None: valid reply
    #: marking (s) between the line's last activity and this transmission, for one that
    #: follows a try of the same command; None for the first try
    quiet: float | None = None

    @property
    def retry(self) -> bool:
        """The same command again, without a break, while the sensor is still awake."""
        return self.sent.break_event is None and self.quiet is not None and self.quiet <= STANDBY

    def in_window(self, uncertainty: float) -> bool:
        """A retry that started within 87 ms of the line going quiet, for every stamp error
        the run allows: the only kind a PASS of R-7.2-01/04/06 may rest on."""
        return self.retry and self.quiet is not None and self.quiet + uncertainty <= WINDOW

    def instead(self, nxt: Try | None) -> str:
        """What the recorder did after this unanswered or invalid try, when it did not retry."""
        if nxt is None:
            return "not sent again"
        later = f"{nxt.sent.start - self.sent.end:.3f} s later"
        if nxt.sent.break_event is not None:
            return f"sent again only after a new break, {later} (a new sequence, not a retry)"
        return (
            f"sent again without a break {later}, after the sensor's "
            f"{STANDBY_MARKING * 1e3:.0f} ms to standby (not a retry)"
        )

    def after(self) -> str:
        return f"after {self.problem} to {self.sent.at()}"


@dataclass
class RetryGroup:
    """Consecutive transmissions of one command text: the first try and its retries."""

    text: str
    attempts: list[Try]

    def sequences(self) -> list[list[Try]]:
        """Split where a try is no retry (a break, or after standby): each break + command +
        retries is one sequence (R-7.2-04)."""
        out: list[list[Try]] = []
        for a in self.attempts:
            if not out or not a.retry:
                out.append([a])
            else:
                out[-1].append(a)
        return out

    @property
    def succeeded(self) -> bool:
        return any(a.problem is None for a in self.attempts)

    def real_retries(self, uncertainty: float) -> list[Try]:
        return [a for a in self.attempts if a.in_window(uncertainty)]


def retry_groups(line: TranscriptView, uncertainty: float) -> list[RetryGroup]:
    """Every command's tries, in order (one :meth:`RetryGroups.add` of the whole view)."""
    groups = RetryGroups(uncertainty)
    found = [group for group, _ in groups.add(line)]
    return found + [group for group, _ in groups.close()]


#: The view a try of a group was read from (:class:`RetryGroups`).
LineOf = Callable[[Try], TranscriptView]


class RetryGroups:
    """:func:`retry_groups` of a recording given a window's view at a time (issue 22's
    windowed judge): :meth:`add` gives each group once the command after it shows it done,
    with the view each of its tries came from (a group may span windows: the same command
    again after a break, its reply invalid; each of its sequences lies in one window, every
    window beginning with a break); :meth:`close` the last. Carried: each address's CRC
    expectation (:func:`~.replies.crc_context`) and the group still open."""

    def __init__(self, uncertainty: float) -> None:
        self.uncertainty = uncertainty
        self._crc: dict[str, bool] = {}
        self._open: RetryGroup | None = None
        self._views: list[TranscriptView] = []  # the open group's, one per try

    def add(self, line: TranscriptView) -> Iterator[tuple[RetryGroup, LineOf]]:
        """Take the next window's view; the groups it shows done."""
        crc = crc_context(line, self._crc)
        for i, s in enumerate(line.transmissions):
            if not s.is_command:  # CR LF after the '!' aside (Transmission.stem)
                continue  # no command, so no reply to retry for; R-4.4-04 judges its text
            problem = reply_problem(s, crc[i], self.uncertainty)
            if problem is not None and problem.reason is Reason.CUT:
                problem = None  # the recorder's own break cut it: no sensor reply to retry for
            elif problem is NO_REPLY and _window_taken(line, i, self.uncertainty):
                problem = None  # it never waited for a reply (the next command came at once)
            attempt = Try(s, problem)
            group = self._open
            last = group.attempts[-1] if group is not None else None
            if (
                group is not None
                and last is not None
                and last.sent.part == s.part
                and last.sent.stem == s.stem
                and (last.problem is not None)
            ):
                before = line.previous_activity(s)
                attempt.quiet = s.first_char - (last.sent.end if before is None else before)
                group.attempts.append(attempt)
            else:
                yield from self.close()
                self._open = RetryGroup(s.stem, [attempt])
            self._views.append(line)

    def close(self) -> Iterator[tuple[RetryGroup, LineOf]]:
        """The group still open, done (the recording, or the command after it, ended it)."""
        if self._open is None:
            return
        group, views = self._open, self._views
        self._open, self._views = None, []

        def line_of(a: Try) -> TranscriptView:
            return views[next(k for k, b in enumerate(group.attempts) if b is a)]

        yield group, line_of


def _window_taken(line: TranscriptView, i: int, uncertainty: float) -> bool:
    """Whether the recorder sent another command, without a break, before a reply to
    transmission ``i`` could have begun (R-7.0-10's 15 ms, +0.40): ``0M!`` and at once
    ``1M!``. It never waited for a reply, so there was no "no reply" to retry for (R-7.2-01
    FAILed "after no reply to 0M!: not sent again"); R-7.0-17 FAILs the missing break. The
    same command again is a retry, timed by R-7.2-02 (0 ms: a FAIL)."""
    transmissions = line.transmissions
    if i + 1 >= len(transmissions):
        return False
    s, nxt = transmissions[i], transmissions[i + 1]
    return (
        nxt.part == s.part
        and nxt.break_event is None
        and nxt.stem != s.stem
        and nxt.first_char - s.end < RESPONSE_START_MAX + TOLERANCE + uncertainty
    )


def judge_retries(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """Section 7.2 over every command whose reply was missing or invalid: R-7.2-01 it was
    retried (a PASS needs a retry inside the 87 ms window; a new break instead is a FAIL);
    R-7.2-02 after no reply, a retry without a break 16.67-87 ms after the command; R-7.2-03
    a sequence given up had two retries, one more than 100 ms after its break; R-7.2-04
    (SHOULD) three sequences before giving up, judged only where a sequence held a retry;
    R-7.2-05 every missing or invalid reply triggered a retry; R-7.2-06 the retry waited for
    the invalid reply to end."""
    judge = Retries(uncertainty, line.stalls)
    judge.add(line)
    return judge.findings()


class Retries:
    """:func:`judge_retries` of a recording given a window's view at a time (issue 22's
    windowed judge; the whole-run function is one :meth:`add`): each command's tries judged
    once :class:`RetryGroups` gives them done, each window's cut replies
    (:func:`cut_replies`: a cut reply and the break that cut it are in one window,
    :func:`~conformance.view.windows.window_starts`); carried: what :class:`RetryGroups`
    carries and the findings gathered (the tally's counts and labels, each retry's timing
    finding, the cuts). :meth:`findings` once, at the end."""

    def __init__(self, uncertainty: float, stalls: Sequence[Stall] = ()) -> None:
        self.uncertainty = uncertainty
        self._groups = RetryGroups(uncertainty)
        self._resent: list[Finding] = []  # R-7.2-06's FAILs of cut_replies
        self._restarted: list[str] = []  # and the cuts it only names
        self._acc = _RetryEvidence(Tally(("R-7.2-01", "R-7.2-04", "R-7.2-05")))
        #: the tool's host stalls noted in the recording (a window's view holds none)
        self._acc.stalls = list(stalls)

    def add(self, line: TranscriptView) -> None:
        """Take the next window's view."""
        acc = self._acc
        acc.stalls = acc.stalls or line.stalls
        self._judge(self._groups.add(line))
        resent, restarted = cut_replies(line, self.uncertainty, acc.stalls)
        self._resent += resent
        self._restarted += restarted

    def _judge(self, done: Iterable[tuple[RetryGroup, LineOf]]) -> None:
        for group, line_of in done:
            if all(a.problem is None for a in group.attempts):
                continue
            _judge_group(line_of, group, self.uncertainty, self._acc)

    def findings(self) -> list[Finding]:
        """Section 7.2's findings of the recording."""
        self._judge(self._groups.close())
        acc = self._acc
        acc.ends.extend(self._resent)
        acc.restarted.extend(self._restarted)
        tally = acc.tally
        for rid in tally.ids:
            tally.decision(rid, RETRY_DECISION)
        ok = {
            "R-7.2-01": f"retried without a break within {RETRY_MAX * 1e3:.0f} ms of the line "
            f"going quiet (decision {RETRY_DECISION})",
            "R-7.2-04": "a break+command+retries sequence that drew no valid reply was repeated",
            "R-7.2-05": "retried as due",
        }
        found = [
            *tally.findings(ok),
            combine("R-7.2-02", acc.window, "retry after no reply"),
            combine("R-7.2-03", acc.third, "unanswered sequence"),
            _waited(acc.ends, acc.restarted),
        ]
        for f in found[len(tally.ids) :]:
            f.decision = RETRY_DECISION
        return found


@dataclass
class _RetryEvidence:
    """What :func:`judge_retries` gathers over all groups before combining: the tallied
    requirements, and the findings of the ones combined from windows of their own."""

    tally: Tally
    window: list[Finding | MeasuredAsJudged] = field(default_factory=list)  # R-7.2-02
    #: R-7.2-02's retries after no reply judged where no stall is noted, each distinct wait
    #: once (:class:`~..timing.Repeats`: a pointer a retry in ``window``, memory27)
    window_seen: Repeats[MeasuredAsJudged] = field(default_factory=Repeats)
    third: list[Finding] = field(default_factory=list)  # R-7.2-03
    ends: list[Finding] = field(default_factory=list)  # R-7.2-06
    #: invalid replies followed by a new sequence, not a retry (R-7.2-06's INCONCLUSIVE)
    restarted: list[str] = field(default_factory=list)
    #: the tool's host stalls noted in the recording (truth32)
    stalls: Sequence[Stall] = ()

    def across(
        self, finding: Finding, start: float, end: float, high: float | None = None
    ) -> Finding:
        """``finding`` on the line between ``start`` and ``end``, or where it FAILs or
        WARNs across noted stalls of the tool's host that can account for it (:func:`.stalls.
        hold`: they held up the played sensor's reply, an in-process recorder, or the
        stamps), INCONCLUSIVE naming the first; as before outside any stall."""
        return hold(self.stalls, finding, start, end, high)

    def fail(
        self,
        rid: str,
        where: str,
        message: str,
        line: TranscriptView,
        tries: tuple[Try, Try],
        until: float | None = None,
        *,
        warning: bool = False,
    ) -> None:
        """A tallied FAIL (a WARN with ``warning``) of ``rid`` that rests on the tries from
        the first of ``tries`` (read from ``line``) to the last and the recorder's decision
        after it (:func:`_decided_by`; or the next try at ``until``, if sooner), or where a
        noted stall of the tool's host lies over that stretch, the observation undecided
        naming it (truth34: the reply it held back read invalid, or a paused in-process
        recorder missed its window; a stall's disorder reaches back to
        :func:`_unsettled_from`). What came after the decision is no part of it: a recorder
        that waits out a 1 s poll timeout instead of retrying had its chance first."""
        span = (0.0, 0.0)
        if self.stalls:
            first, last = tries
            end = _decided_by(last)
            span = (_unsettled_from(line, first), end if until is None else min(until, end))
        fail_unless_stalled(self.tally, self.stalls, rid, where, message, span, warning=warning)


def _judge_group(
    line_of: LineOf, group: RetryGroup, uncertainty: float, acc: _RetryEvidence
) -> None:
    """One command's tries, at least one unanswered or invalid, into ``acc``; ``line_of``:
    the view each try was read from (a sequence's tries share one)."""
    where = escape(group.text)
    acc.tally.observe(where, ids=["R-7.2-05"])
    # Given up, as opposed to accepted: silence cannot be mistaken for a valid reply, and
    # a command sent again shows the recorder found the reply invalid. A garbled reply
    # sent once may have been accepted: that is R-7.2-05's (and R-4.4.12-07's) finding.
    gave_up = group.attempts[-1].problem is NO_REPLY or len(group.attempts) > 1
    real = group.real_retries(uncertainty)
    _judge_retried(line_of, group, where, real, gave_up, acc)
    sequences = group.sequences()
    for n, seq in enumerate(sequences):
        later = sequences[n + 1][0] if n + 1 < len(sequences) else None
        line = line_of(seq[0])
        _judge_tries(line, seq, later, where, uncertainty, acc)
        if any(a.problem is None for a in seq) or not gave_up:
            continue
        _judge_given_up(line, seq, f"{where} sequence {n + 1}", uncertainty, acc)
    _judge_repeated(line_of, group, where, sequences, real, gave_up, acc)


def _judge_retried(
    line_of: LineOf,
    group: RetryGroup,
    where: str,
    real: list[Try],
    gave_up: bool,
    acc: _RetryEvidence,
) -> None:
    """R-7.2-01: a PASS only from a retry inside the window, a FAIL where none was tried
    (named at the first try whose reply and the recorder's answer to it no noted stall of
    the tool's host lies over; where one lies over every such try, undecided: truth34)."""
    tally = acc.tally
    if real:
        tally.observe(where, ids=["R-7.2-01"])
    elif gave_up and not any(a.retry for a in group.attempts):
        tries = group.attempts
        k = _first_unstalled(line_of, tries, acc.stalls)
        nxt = tries[k + 1] if k + 1 < len(tries) else None
        a = tries[k]
        until = nxt.sent.first_char if nxt is not None else None
        message = f"{a.after()}: {a.instead(nxt)}"
        acc.fail("R-7.2-01", where, message, line_of(a), (a, a), until)
    elif gave_up:
        tally.unobservable(
            "R-7.2-01",
            f"{where} was sent again without a break only later than "
            f"{RETRY_MAX * 1e3:.0f} ms after the line went quiet (R-7.2-02 judges it); "
            "no retry inside the window was seen",
        )


def _judge_tries(
    line: TranscriptView,
    seq: list[Try],
    later: Try | None,
    where: str,
    uncertainty: float,
    acc: _RetryEvidence,
) -> None:
    """R-7.2-05, R-7.2-02 and R-7.2-06 over the failed tries of one sequence; ``later``:
    the first try of the next sequence, if any."""
    for k, a in enumerate(seq):
        if a.problem is None:
            continue
        nxt = seq[k + 1] if k + 1 < len(seq) else None
        began = _unsettled_from(line, a) if acc.stalls else a.sent.start
        if nxt is None and len(seq) < 3:
            acc.fail(
                "R-7.2-05",
                where,
                f"{a.problem} at {a.sent.at()}, then "
                + ("a new sequence, not a retry" if later is not None else "no retry"),
                line,
                (seq[0], a),  # no break since: the sensor's state (asleep, say) is the sequence's
                later.sent.first_char if later is not None else None,
            )
        # "no reply" times a retry from a quiet line: sensor characters that met the
        # command (the recorder talked over them) leave that window undecided
        if a.problem is NO_REPLY and not a.sent.contention:
            if nxt is not None:
                waited = nxt.sent.first_char - a.sent.end
                u = own_uncertainty(uncertainty, a.sent.chars[-1], nxt.sent.chars[0])
                if acc.stalls:  # each its own finding, as hold names a stall with its evidence
                    judged = RETRY_WAIT.judge(waited, u, [nxt.sent.at()])
                    acc.window.append(acc.across(judged, began, nxt.sent.first_char, RETRY_MAX))
                else:  # one object per distinct wait (the first's evidence is shown)
                    seen = acc.window_seen
                    acc.window.append(
                        seen.first(waited, u)
                        or seen.keep(MeasuredAsJudged(RETRY_WAIT, waited, u, [nxt.sent.at()]))
                    )
            elif k == 0:
                missing = Finding(
                    "R-7.2-02",
                    Verdict.FAIL,
                    f"no retry without a break after no reply to {a.sent.at()}: {a.instead(later)}",
                    evidence=[a.sent.at()]
                    + ([f"next: {later.sent.at()}"] if later is not None else []),
                    observed=1,
                )
                # the wait for the reply and what the recorder did instead: a stall there
                # may have held the reply back (or the recorder, in the tool's process)
                # (no further than the decision the recorder owed it: truth34)
                until = _decided_by(a)
                if later is not None:
                    until = min(until, later.sent.first_char)
                acc.window.append(acc.across(missing, began, until))
        elif nxt is not None and nxt.in_window(uncertainty):
            judged = _retry_after_reply(line, a.sent, nxt.sent, a.problem, uncertainty)
            acc.ends.append(acc.across(judged, began, nxt.sent.first_char))
        elif nxt is None and later is not None:
            acc.restarted.append(f"{a.after()}: {a.instead(later)}")


def _unsettled_from(line: TranscriptView, a: Try) -> float:
    """The earliest moment a stall of the tool's host could have disturbed what try ``a``
    shows (truth34: its disorder outlives its noted span). Where it drew no reply: where
    the marking before it began (truth32: a stall there decides how long the sensor had been
    left alone, so whether it was awake to answer, and a paused in-process recorder came
    back to begin anew with a break, new1's 0M! at 101.667 s), or the standby before it,
    whichever is earlier (the played sensor counts its marking from when it planned its
    last frame, which a stall sent late: new1's 0DB3! 26 ms after a stall's reach drew
    nothing, nor its retry; base0's 5A0! and 0M! just past one). A reply, however invalid,
    shows the sensor was awake: from the try itself. Where the sensor was still sending as
    the try began (a reply the stall held back met it), from the start of the transmission
    whose reply that was (:data:`MET_CHAIN`). And :data:`~conformance.links.host_stall.REACH`
    before all that: a paused in-process recorder acts as it comes back, just past the
    note's reach (newF's retry 0.03 ms past it, then a reply it talked over)."""
    sent = a.sent
    start = sent.start
    if a.problem is NO_REPLY:
        before = line.previous_activity(sent)
        start = min(start if before is None else before, start - STANDBY)
    met = sent
    for _ in range(MET_CHAIN):  # a held-back reply may meet several tries in turn
        previous = _previous(line, met)
        if previous is None or not _talked_over(line, met):
            break
        met = previous
        start = min(start, previous.start)
    return start - REACH


#: how many tries back :func:`_unsettled_from` follows a reply still coming as each began
#: (truth32's newF3: a stall held 0DB8!'s packet back, the paused recorder's retry met it
#: and 0DB9! the rest, 250 ms after the stall's reach)
MET_CHAIN = 3


def _talked_over(line: TranscriptView, sent: Transmission) -> bool:
    """Whether the sensor was still sending as ``sent`` began (a reply it talked over)."""
    return sent.cut is not None or bool(line.sensor_chars_between(sent.start - CHAR_TIME, sent.end))


def _decided_by(a: Try) -> float:
    """When the recorder had to have acted on try ``a``: the standby after the last thing it
    heard (its reply, or the command itself)."""
    heard = a.sent.heard
    return max(a.sent.end, heard[-1].end if heard else a.sent.end) + STANDBY


def _previous(line: TranscriptView, sent: Transmission) -> Transmission | None:
    """The transmission before ``sent`` in ``line`` (None for its first)."""
    transmissions = line.transmissions
    index = memo(
        line,
        "_retry_index",
        len(transmissions),
        lambda: {id(t): i for i, t in enumerate(transmissions)},
    )
    i = index.get(id(sent))
    return transmissions[i - 1] if i else None


def _first_unstalled(line_of: LineOf, tries: Sequence[Try], stalls: Sequence[Stall]) -> int:
    """The index of the first of ``tries`` (each unanswered or invalid, none retried) whose
    stretch, from :func:`_unsettled_from` to the next try (or :func:`_decided_by`), no noted
    stall lies over; 0 where one lies over each (or none is noted)."""
    if not stalls:
        return 0
    for k, a in enumerate(tries):
        if a.problem is None:  # the group's last try, answered: nothing to retry for
            continue
        until = _decided_by(a)
        if k + 1 < len(tries):
            until = min(until, tries[k + 1].sent.first_char)
        if stalled_over(stalls, _unsettled_from(line_of(a), a), until) is None:
            return k
    return 0


def _judge_given_up(
    line: TranscriptView, seq: list[Try], label: str, uncertainty: float, acc: _RetryEvidence
) -> None:
    """R-7.2-03 over a sequence that never drew a valid reply: two retries, the latest more
    than 100 ms after the break."""
    retries = seq[1:]
    if len(retries) < 2:
        few = Finding(
            "R-7.2-03",
            Verdict.FAIL,
            f"{label}: {len(retries)} retries, then no more",
            evidence=[a.sent.at() for a in seq],
            observed=len(seq),
        )
        # the sequence's tries and the wait after its last (its reply, a retry due); a
        # stall's disorder reaches back past the marking before the first (truth34)
        began = _unsettled_from(line, seq[0])
        acc.third.append(acc.across(few, began, _decided_by(seq[-1])))
        return
    brk = seq[0].sent.break_event or line.last_break_before(seq[0].sent)
    if brk is not None:
        latest = max(r.sent.first_char for r in retries)
        judged = judge_window(
            "R-7.2-03",
            "latest retry after the end of the break",
            latest - brk.end,
            uncertainty,
            low=RETRY_AFTER_BREAK,
            evidence=[label],
        )
        acc.third.append(acc.across(judged, brk.start, latest))


def _judge_repeated(
    line_of: LineOf,
    group: RetryGroup,
    where: str,
    sequences: list[list[Try]],
    real: list[Try],
    gave_up: bool,
    acc: _RetryEvidence,
) -> None:
    """R-7.2-04 is about repeating a whole break+command+retries sequence: repeats of a
    break and the command alone hold no retry and are no evidence for it either way. "Gave
    up" rests on every try of the group reading unanswered or invalid: a noted stall over
    any of them (or the wait after the last) leaves it undecided (truth34)."""
    tally = acc.tally
    repeated = any(a in real for seq in sequences[:-1] for a in seq)
    if not group.succeeded and gave_up and len(sequences) < 3:
        first, last = group.attempts[0], group.attempts[-1]
        acc.fail(
            "R-7.2-04",
            where,
            f"gave up after {len(sequences)} break+command+retries sequence(s)",
            line_of(first),
            (first, last),
            warning=True,
        )
    elif len(sequences) > 1 and (repeated or (not group.succeeded and real)):
        tally.observe(where, ids=["R-7.2-04"])
    elif len(sequences) > 1:
        tally.unobservable(
            "R-7.2-04",
            f"{where} was repeated {len(sequences)} times, each time a new sequence with "
            "no retry in it: no break+command+retries sequence was seen to repeat",
        )


def cut_replies(
    line: TranscriptView, uncertainty: float, stalls: Sequence[Stall] = ()
) -> tuple[list[Finding], list[str]]:
    """Replies the recorder's own break cut into (:func:`.replies.cut_off`): no invalid
    reply of the sensor's, so no retry was due (R-7.2-01, -03, -05 leave them out). Where
    the same command followed that break (the command sent again) over a single-line reply
    heard shorter than any reply may be (:data:`LONGEST_LINE`), less than 8.33 ms after its
    last character even at the stamps' uncertainty, the recorder did not "wait for the
    response to complete before sending a retry" (section 7.2): R-7.2-06 FAILs (a 500 ms
    poll over a 75-value reply, the fourteenth round's MicroPython logger; a break and the
    command again is the sequence repeated, part of the retry logic, even where decision T2
    counts no retry in it). Else R-7.2-06 names the cut and stays INCONCLUSIVE (a break to
    abort, a reply longer than any valid one, multi-line text: R-4.4.13.1-04's)."""
    failed: list[Finding] = []
    named: list[str] = []
    transmissions = line.transmissions
    for i, s in enumerate(transmissions):
        cut = cut_off(s)
        if cut is None:
            continue
        nxt = transmissions[i + 1] if i + 1 < len(transmissions) else None
        last, brk = s.reply[-1], s.cut_by
        assert brk is not None  # cut_off found it
        early = brk.start - last.end + own_uncertainty(uncertainty, last, brk) < CHAR_TIME
        if (
            nxt is not None
            and nxt.break_event is brk
            and nxt.stem == s.stem
            and len(s.reply) < LONGEST_LINE
            and not (len(s.reply) > 1 and s.reply[1].char7 == STX)
            and early
        ):
            found = Finding(
                "R-7.2-06",
                Verdict.FAIL,
                f"{cut}, and sent {escape(nxt.text)} again after it: it did not wait for"
                " the response to complete",
                evidence=[s.at(), nxt.at()],
                observed=1,
            )
            # a reply the tool's host stalled over (truth32): held back, its rest late; or
            # one a stall's disorder reached (truth34: :func:`_unsettled_from`)
            began = _unsettled_from(line, Try(s, NO_REPLY)) if stalls else s.start
            failed.append(hold(stalls, found, began, brk.end))
        else:
            named.append(f"{cut} (after {s.at()}): a new sequence, not a retry")
    return failed, named


def judge_breaks_over_replies(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.2-06's FAILs of :func:`cut_replies` alone (none where nothing was cut): for
    the scenarios :func:`judge_retries` does not read, whose long replies a recorder with a
    short receive buffer or poll breaks into (breaks-over-long-reply: aHA!'s and aC9!'s
    75-character D replies)."""
    return cut_replies(line, uncertainty, line.stalls)[0]


def _waited(ends: list[Finding], restarted: list[str]) -> Finding:
    """R-7.2-06 over the retries after an invalid reply; without one, say what came instead."""
    if not ends and restarted:
        return Finding(
            "R-7.2-06",
            Verdict.INCONCLUSIVE,
            "no retry after an invalid reply was seen: " + "; ".join(restarted[:3]),
        )
    return combine("R-7.2-06", ends, "retry after an invalid reply")


def _retry_after_reply(
    line: TranscriptView,
    sent: Transmission,
    retry: Transmission,
    problem: ReplyProblem | None,
    uncertainty: float,
) -> Finding:
    """R-7.2-06: marking between the end of the invalid reply and the retry; negative when
    the sensor was still sending as the recorder took the line again."""
    reply = line.sensor_chars_between(sent.end, retry.end)
    reply_end = max((c.end for c in reply), default=sent.end)
    return judge_window(
        "R-7.2-06",
        "retry after the end of the invalid reply",
        retry.start - reply_end,
        uncertainty,
        low=0.0,
        tolerance=0.0,
        evidence=[f"{retry.at()} after {problem}"],
    )


def judge_crc_checked(
    line: TranscriptView, uncertainty: float, logged: dict[str, list[str]] | None, truth: list[str]
) -> list[Finding]:
    """R-4.4.12-07: a reply whose CRC does not match is treated as invalid: it is retried, and
    (when the recorder reports what it logged) its values are not logged."""
    tally = Tally(("R-4.4.12-07",))
    for group in retry_groups(line, uncertainty):
        for k, a in enumerate(group.attempts):
            if a.problem is None or a.problem.reason is not Reason.CRC_WRONG:
                continue
            where = escape(group.text)
            tally.observe(where)
            if k + 1 >= len(group.attempts):
                # "not retried", not "accepted": whether its values were taken is the
                # logged values' finding below (a logger that raised on it logged none)
                tally.fail("R-4.4.12-07", where, f"not retried after a reply whose {a.problem}")
    if logged is not None and truth:
        for command, values in logged.items():
            if values and not same_values(truth[: len(values)], values):
                tally.fail(
                    "R-4.4.12-07",
                    escape(command),
                    f"logged {' '.join(values[:4])}..., the sensor's values are "
                    f"{' '.join(truth[:4])}...",
                )
    return tally.findings("CRC mismatches retried, correct values logged")
