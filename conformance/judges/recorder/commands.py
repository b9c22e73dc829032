"""Judges of the recorder's command characters: printable, ``!`` last, the address first;
the gaps between them (R-7.0-13, R-7.0-01); their bit rate (R-4.1-01)."""

from __future__ import annotations

from collections.abc import Sequence

from ...links.host_stall import Stall, stalled_over
from ...protocol.commands import ADDRESS_CHARS
from ...protocol.timing import CHAR_TIME, INTER_CHAR_GAP_MAX, TOLERANCE
from ...transcript import Event, escape
from ...verdicts import Finding, Verdict
from ...view.segments import NEW_COMMAND, TranscriptView, Transmission
from ..stalled import held_by
from ..tally import Tally
from ..timing import Counted, MeasuredIn, Repeats, Window
from ..wire import judge_frame_lengths, judge_rate
from .common import combine, own_uncertainty
from .stalls import hold

#: R-7.0-13's window, worked out once for the many gaps of a recording
COMMAND_GAP = Window(
    "R-7.0-13", "marking between command characters", high=INTER_CHAR_GAP_MAX, tolerance=0.0
)


_BANG = ord("!")


def _dropped(
    gap: float, uncertainty: float, bang_seen: bool, s: Transmission, a: Event, b: Event
) -> bool:
    """Whether a sensor ends the partial command at this gap between a recorder's
    characters: 8.33 ms (-0.40) of marking with no ``!`` before it in the transmission (App.
    B, R-AppB-01). What follows is a new try as much as more of the same command (a library
    that never writes the ``!`` and retries: ``0M1`` 50 ms ``0M1``, nineteenth round): the
    text before the gap is an unterminated command (R-4.4-04), and whether the gap is inside
    a command, which R-7.0-13 limits, the wire does not say. A gap a sensor talked in is no
    marking: a retry over a reply that the line held back (R-7.2-06 drags R-7.0-13)."""
    if bang_seen or gap - uncertainty < NEW_COMMAND:
        return False
    return not any(h.end > a.end and h.start < b.start for h in s.heard)


def _cut_while_sent(line: TranscriptView, s: Transmission) -> bool:
    """Whether the tool cut ``s``'s job at its budget while ``s`` was still being sent: no
    ``!`` in it yet, and the cut came before a sensor would have dropped it as a partial
    command (App. B). What it had not sent by then it may yet have sent: whether ``!`` came
    last is not known (the twenty-fourth round's ATtiny logger was cut after '0XM=G', and
    R-4.4-04 FAILed "'!' is not exactly the last character")."""
    cut = line.cut_parts.get(s.part)
    if cut is None or "!" in s.text or not s.chars:
        return False
    return -1e-6 <= cut - s.chars[-1].end < NEW_COMMAND


def judge_command_text(line: TranscriptView, uncertainty: float = 0.0) -> list[Finding]:
    """R-4.2-01 printable command characters; R-4.4-04 ``!`` last and nowhere else, and no
    part a sensor drops for want of it (:func:`_dropped`); R-4.3-01 the first character is
    the address (``?`` only in ``?!``)."""
    judge = CommandText(uncertainty, line.stalls)
    judge.add(line)
    return judge.findings()


class CommandText:
    """:func:`judge_command_text` over a recording read a window at a time (issue 22): each
    window's view :meth:`add`-ed in order, the findings those of the whole view. It keeps
    the tally's labels (one short string a command), none of a window's events."""

    def __init__(self, uncertainty: float = 0.0, stalls: Sequence[Stall] = ()) -> None:
        self.tally = Tally(("R-4.2-01", "R-4.4-04", "R-4.3-01"))
        self.uncertainty = uncertainty
        #: the tool's host stalls noted in the recording (a window's view holds none)
        self.stalls = list(stalls)

    def add(self, line: TranscriptView) -> None:
        """The commands of ``line`` (the next window of the recording)."""
        tally = self.tally
        self._stalls = self.stalls or line.stalls
        for s in line.transmissions:
            text, where = s.text, escape(s.text)
            bad = [c for c in text if not 0x20 <= ord(c) <= 0x7E]
            cut = _cut_while_sent(line, s)
            if cut:
                # its end is the tool's cut, not the recorder's: the rest was still to come
                tally.observe(where, ids=["R-4.2-01", "R-4.3-01"])
            else:
                tally.observe(where, ids=["R-4.2-01", "R-4.4-04", "R-4.3-01"])
            if bad:
                tally.fail(
                    "R-4.2-01", where, f"non-printable {escape(''.join(bad))} in the command"
                )
            if cut:
                pass
            elif not text.endswith("!") or "!" in text[:-1]:
                tally.fail("R-4.4-04", where, "'!' is not exactly the last character")
            else:
                self._unterminated_part(s)
            first = text[:1]
            # the address query with more after its ``!`` is addressed as ``?!`` is (an STM32
            # HAL logger, HarveyBates/stm32-projects, sends each command's C string with its
            # NUL, ``?!<NUL>``: R-4.3-01 FAILed "starts with ?"); the rest is R-4.2-01's and
            # R-4.4-04's
            if not (first in ADDRESS_CHARS or text.startswith("?!")):
                tally.fail("R-4.3-01", where, f"starts with {escape(first)}, not an address")

    def _unterminated_part(self, s: Transmission) -> None:
        """R-4.4-04 for text that ends in its only ``!`` but whose first part a sensor
        dropped (:func:`_dropped`): ``0M1`` 50 ms ``0M1`` 50 ms ``0MC!``."""
        chars = s.chars
        for i, (a, b) in enumerate(zip(chars, chars[1:], strict=False)):
            gap = b.start - a.end
            u = own_uncertainty(self.uncertainty, a, b)
            if _dropped(gap, u, False, s, a, b):
                part = escape("".join(chr(e.wire & 0x7F) for e in chars[: i + 1]))
                where = escape(s.text)
                dropped = Finding(
                    "R-4.4-04",
                    Verdict.FAIL,
                    f"'{part}' then {gap * 1e3:.2f} ms of marking with no '!': a sensor "
                    "drops it there (App. B)",
                    measured_ms=gap * 1e3,
                    uncertainty_ms=u * 1e3,
                    evidence=[where],
                    observed=1,
                )
                # a gap the tool's host stalled across: its own doing, or its stamps' (truth32)
                held = hold(self._stalls, dropped, a.start, b.end, NEW_COMMAND)
                if held.verdict is Verdict.FAIL:
                    self.tally.fail("R-4.4-04", where, dropped.detail)
                else:
                    self.tally.undecide("R-4.4-04", where, held.detail)
                return
            if a.wire & 0x7F == _BANG:
                return

    def findings(self) -> list[Finding]:
        """R-4.2-01, R-4.4-04 and R-4.3-01 over everything added."""
        return self.tally.findings("well formed")


def judge_character_gaps(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-7.0-13: at most 1.66 ms of marking between the characters of a command (no
    tolerance); R-7.0-01: no gap leans on the ±0.40 ms that this limit does not have."""
    judge = CharacterGaps(uncertainty, line.stalls)
    judge.add(line)
    return judge.findings()


#: R-7.0-01's evidence: the first gaps inside the tolerance band, quoted
LEANING_SHOWN = 5


class CharacterGaps:
    """:func:`judge_character_gaps` over a recording read a window at a time (issue 22):
    each window's view :meth:`add`-ed in order, the findings those of the whole view. Kept
    across windows: one judged interval per distinct gap (:class:`~..timing.Repeats`, each
    holding the one transmission its evidence names) and how often each came
    (:class:`~..timing.Counted`) and, of the gaps inside the tolerance
    band, the first few R-7.0-01 quotes and how many there were."""

    def __init__(self, uncertainty: float, stalls: Sequence[Stall] = ()) -> None:
        self.uncertainty = uncertainty
        #: the tool's host stalls noted in the recording (a window's view holds none)
        self.stalls = list(stalls)
        # one judged interval each, its finding (and evidence line) made only where the
        # verdict shows it, counted by object (not a list a gap: Counted); the few gaps
        # inside the tolerance band kept apart for R-7.0-01
        self.found = Counted()
        # the first gap inside the tolerance band a noted stall covers, and its stall
        self.leaning_stalled: tuple[float, Transmission, Stall] | None = None
        self.leaning: list[tuple[float, Transmission]] = []  # the first LEANING_SHOWN
        self.leaning_count = 0
        # a gap equal to one judged before is that interval again (its first one: Repeats)
        self._judged: Repeats[MeasuredIn] = Repeats()
        # gaps a sensor ends a partial command at, in text with no '!' at all: how many,
        # the first (gap, transmission)
        self.dropped = 0
        self.first_dropped: tuple[float, Transmission] | None = None

    def add(self, line: TranscriptView) -> None:
        """The command character gaps of ``line`` (the next window of the recording)."""
        uncertainty, found, judged = self.uncertainty, self.found, self._judged
        stalls = self.stalls or line.stalls
        for s in line.transmissions:
            chars = s.chars
            bang_seen = False
            for a, b in zip(chars, chars[1:], strict=False):
                gap = b.start - a.end
                u = own_uncertainty(uncertainty, a, b)
                bang_seen = bang_seen or a.wire & 0x7F == _BANG
                if _dropped(gap, u, bang_seen, s, a, b):
                    self._keep_dropped(gap, s)
                    continue
                m = judged.first(gap, u) or judged.keep(MeasuredIn(COMMAND_GAP, gap, u, s))
                # a gap the tool's host stalled across (truth32): its stamps, or an
                # in-process recorder held up with the host, are the host's doing
                found.append(hold(stalls, m, a.start, b.end, INTER_CHAR_GAP_MAX) if stalls else m)
                if INTER_CHAR_GAP_MAX < gap <= INTER_CHAR_GAP_MAX + TOLERANCE:
                    stall = stalled_over(stalls, a.start, b.end) if stalls else None
                    if stall is not None:
                        if self.leaning_stalled is None:
                            self.leaning_stalled = (gap, s, stall)
                        continue
                    self.leaning_count += 1
                    if len(self.leaning) < LEANING_SHOWN:
                        self.leaning.append((gap, s))

    def _keep_dropped(self, gap: float, s: Transmission) -> None:
        """A gap a sensor ends the partial command at (:func:`_dropped`): not judged as
        inside a command; the first and how many kept for :meth:`_undecided`."""
        self.dropped += 1
        if self.first_dropped is None:
            self.first_dropped = (gap, s)

    def _undecided(self) -> list[Finding]:
        """R-7.0-13 INCONCLUSIVE for the gaps :meth:`_dropped` kept out (a FAIL of a gap
        judged still wins: see :func:`combine`)."""
        if self.first_dropped is None:
            return []
        gap, s = self.first_dropped
        return [
            Finding(
                "R-7.0-13",
                Verdict.INCONCLUSIVE,
                f"{self.dropped} gap(s) of 7.93 ms or more before any '!' (the first "
                f"{gap * 1e3:.2f} ms in {s.at()}): a sensor drops the partial command there "
                "(App. B), so each may be a gap inside a command or one after an "
                "unterminated try; R-4.4-04 judges their text",
                evidence=[f"in {s.at()}"],
                observed=self.dropped,
            )
        ]

    def findings(self) -> list[Finding]:
        """R-7.0-13 and R-7.0-01 over everything added."""
        found, leaning = self.found, self.leaning
        if leaning:
            gap, s = leaning[0]
            tol = _leaning(gap, s, leaning, self.leaning_count, len(found))
        elif self.leaning_stalled is not None:
            gap, s, stall = self.leaning_stalled
            tol = held_by(_leaning(gap, s, [(gap, s)], 1, len(found)), stall)
        elif found:
            tol = Finding(
                "R-7.0-01",
                Verdict.PASS,
                f"{len(found)} command character gaps, none inside the tolerance band the "
                "1.66 ms limit does not have; ±0.40 ms applied to every other recorder limit",
                observed=len(found),
            )
        else:
            tol = Finding("R-7.0-01", Verdict.INCONCLUSIVE, "no multi-character command observed")
        undecided = self._undecided()
        alike = found.alike()
        # listed one by one only with a dropped gap's INCONCLUSIVE (rare), after every gap
        judged = [*alike, *undecided] if undecided else alike
        return [combine("R-7.0-13", judged, "character gap"), tol]


def _leaning(
    gap: float, s: Transmission, shown: list[tuple[float, Transmission]], count: int, of: int
) -> Finding:
    """R-7.0-01's FAIL: the first of ``count`` gaps inside the tolerance band the 1.66 ms
    limit does not have (``gap`` in ``s``; ``shown`` quoted), of ``of`` gaps judged."""
    return Finding(
        "R-7.0-01",
        Verdict.FAIL,
        f"a {gap * 1e3:.2f} ms gap in {s.at()} relies on the ±0.40 ms tolerance, which "
        f"the 1.66 ms character gap does not have ({count} such gap(s))",
        measured_ms=round(gap * 1e3, 3),
        limit_ms=INTER_CHAR_GAP_MAX * 1e3,
        evidence=[f"{g * 1e3:.2f} ms gap in {t.at()}" for g, t in shown],
        observed=of,
    )


def judge_command_bit_rate(line: TranscriptView, uncertainty: float) -> Finding:
    """R-4.1-01 (decision A14, ±2%): back-to-back command characters start one frame apart."""
    judge = CommandBitRate(uncertainty)
    judge.add(line)
    return judge.finding()


class CommandBitRate:
    """:func:`judge_command_bit_rate` over a recording read a window at a time (issue 22):
    each window's view :meth:`add`-ed in order, the finding that of the whole view. Kept
    across windows: the shortest spacing so far (the first of the shortest, as ``min``
    takes it), its transmission and uncertainty, and how many spacings there were."""

    def __init__(self, uncertainty: float) -> None:
        self.uncertainty = uncertainty
        self.shortest: tuple[float, Transmission, float] | None = None
        self.spacings = 0

    def add(self, line: TranscriptView) -> None:
        """The command character spacings of ``line`` (the next window of the recording)."""
        uncertainty, shortest = self.uncertainty, self.shortest
        for s in line.transmissions:
            for a, b in zip(s.chars, s.chars[1:], strict=False):
                self.spacings += 1
                spacing = b.start - a.start
                if shortest is None or spacing < shortest[0]:
                    shortest = (spacing, s, own_uncertainty(uncertainty, a, b))
        self.shortest = shortest

    def finding(self) -> Finding:
        """R-4.1-01 over everything added."""
        if self.shortest is None:
            return Finding("R-4.1-01", Verdict.INCONCLUSIVE, "no multi-character command observed")
        shortest, s, uncertainty = self.shortest
        finding = judge_rate(
            "shortest start-to-start spacing of command characters",
            shortest,
            2 * uncertainty,
            [f"in {s.at()}"],
        )
        too_slow = shortest - 2 * uncertainty > CHAR_TIME * 1.02
        if (
            finding.verdict is Verdict.FAIL and too_slow
        ):  # a gap, not a rate: see wire.judge_reply_bit_rate
            finding.verdict = Verdict.INCONCLUSIVE
            finding.detail += " (no back-to-back characters: rate and gaps cannot be separated)"
        finding.detail += f"; about {10 / shortest:.0f} baud over {self.spacings} spacings"
        return finding


def judge_command_frame_lengths(line: TranscriptView, uncertainty: float) -> Finding:
    """R-4.1-01 from the length of every command frame, where each character event lasts its
    own measured frame (a firmware kit): slow as well as fast rates are seen."""
    frames_at = [(e, f"in {s.at()}") for s in line.transmissions for e in s.chars]
    return judge_frame_lengths(frames_at, uncertainty)
