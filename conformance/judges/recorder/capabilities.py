"""Judges of what the recorder can do: issue the commands it was asked to (R-4.4-02), poll
every address (R-4.3-03/04), pass commands through transparently (R-4.4.14-01/02,
R-4.4.13-03, R-6.3-01), end multi-line text without ETX (R-4.4.13.1-04)."""

from __future__ import annotations

from collections.abc import Sequence

from ...protocol.commands import ADDRESS_CHARS, CommandError, Kind, parse_command
from ...protocol.timing import MULTILINE_GAP_MAX, STANDBY_MARKING
from ...transcript import decode_7e1, escape
from ...verdicts import Finding, Verdict
from ...view.segments import TranscriptView
from ..reply_validity import STX
from ..tally import Tally
from ..timing import judge_window
from .common import CUT_SHORT, Record, combine, record_of
from .measurements import collection_end, observed_measurements
from .replies import crc_context, cut_off, first_answered, reply_problem
from .stalls import fail_unless_stalled


def judge_commands_issued(
    line: TranscriptView, asked: Sequence[str], uncertainty: float, rid: str = "R-4.4-02"
) -> Finding:
    """``rid`` (R-4.4-02 by default): every command the recorder was asked to use went out and
    drew a valid reply; for measurements, every announced value was read. Commands that went
    out and drew no valid reply from the tool's own played sensors, with nothing else amiss,
    leave it undecided: the wire shows the recorder issuing them, and why they went unheard
    is another rule's (a wake-up too short, R-7.0-06), not a command the recorder lacks."""
    first = first_answered(line, uncertainty)
    missing = [text for text in asked if text not in first]
    sent = {s.text for s in line.transmissions}
    taken = {m.start.text: m for m in observed_measurements(line, uncertainty)}
    short = [
        f"{escape(t)} ({len(m.values())} of {m.count} values)"
        for t, m in taken.items()
        if t in asked and len(m.values()) < m.count
    ]
    # a collection that ended on a data command no valid reply answered: sent, unheard
    stopped = [
        t
        for t, m in taken.items()
        if t in asked
        and len(m.values()) < m.count
        and collection_end(m)[1] is None
        and m.cut_at is None
    ]
    cut_job = bool(line.cut_parts)  # an unsent command may have been owed by the cut job
    if missing or short:
        parts = []
        # A command the recorder never sent is its own fault, not a missing reply: the
        # sensor side is the tool's, so "never answered" alone read as the tool's failure.
        unsent = [t for t in missing if t not in sent]
        unanswered = [t for t in missing if t in sent]
        # on the wire with more after its '!' (the STM32 logger's NUL terminator after 0A5!,
        # docs/kit.md twenty-third round): sent, malformed (R-4.2-01/R-4.4-04 judge the form)
        garbled = _sent_with_more(unsent, sent)
        unsent = [t for t in unsent if t not in garbled]
        # a reply the recorder's own break cut into was never heard whole, by its doing
        cut = {s.text for s in line.transmissions if cut_off(s) is not None}
        cut_short = [t for t in unanswered if t in cut]
        unanswered = [t for t in unanswered if t not in cut]
        if unsent:
            said = CUT_SHORT if cut_job else "never sent"
            parts.append(f"{said}: " + ", ".join(escape(t) for t in unsent))
        if garbled:
            parts.append(
                "sent with more after its '!' (its form is R-4.2-01's and R-4.4-04's): "
                + ", ".join(escape(w) for w in garbled.values())
            )
        if unanswered:
            parts.append(
                "sent but never answered validly: " + ", ".join(escape(t) for t in unanswered)
            )
        if cut_short:
            parts.append(
                "sent, its reply cut by the recorder's own break: "
                + ", ".join(escape(t) for t in cut_short)
            )
        if short:
            parts.append("data not read: " + ", ".join(short))
        return Finding(
            rid,
            Verdict.FAIL if (unsent and not cut_job) or stopped else Verdict.INCONCLUSIVE,
            "; ".join(parts),
            evidence=record_of(line.transmissions, missing + list(garbled.values()))
            + [m.start.at() for t, m in taken.items() if t in asked and len(m.values()) < m.count],
            observed=len(line.transmissions),
        )
    return Finding(
        rid,
        Verdict.PASS,
        f"{len(asked)} commands issued and answered: " + " ".join(escape(t) for t in asked),
        observed=len(asked),
    )


def _sent_with_more(unsent: Sequence[str], sent: set[str]) -> dict[str, str]:
    """Of the commands ``unsent`` (no transmission is the text alone), those a transmission
    begins with, by the first such transmission's text (sorted, so the same each run): the
    recorder put them on the wire with more after the ``!``. "Never sent" was false for the
    twenty-third round's STM32 logger, whose ``0A5!<0x00>`` the played sensor answered."""
    found: dict[str, str] = {}
    for text in unsent:
        if text.endswith("!"):
            longer = sorted(s for s in sent if s.startswith(text) and len(s) > len(text))
            if longer:
                found[text] = longer[0]
    return found


def judge_addresses(line: TranscriptView, uncertainty: float) -> list[Finding]:
    """R-4.3-03: the recorder polls every address 0-9 (an address it polled that never drew a
    valid reply from the played sensors is undecided, as in :func:`judge_commands_issued`).
    R-4.3-04 (MAY): letters as addresses. (One :meth:`Addresses.add` of the whole view: the
    windowed judge's code path.)"""
    judge = Addresses(uncertainty)
    judge.add(line)
    return judge.findings()


#: The polls R-4.3-03's evidence cites, by the address never validly answered.
_POLLS = [f"{a}!" for a in "0123456789"]
#: Commands to what is no address that R-4.3-04's evidence quotes (the first ones).
_FOREIGN_CITED = 8


class Addresses:
    """:func:`judge_addresses` of a recording given a window's view at a time (issue 22's
    windowed judge). Carried: the addresses that drew a valid reply (each transmission's
    reply judged with its address's CRC expectation carried, :func:`~.replies.crc_context`)
    and those sent to, whether the tool cut a job (``cut_parts``), the evidence of the polls
    (:class:`~.common.Record`), and of the commands to what is no address their count and
    first few: sets and counts, no transmission."""

    def __init__(self, uncertainty: float) -> None:
        self.uncertainty = uncertainty
        self._crc: dict[str, bool] = {}
        self._polled: set[str] = set()
        self._tried: set[str] = set()
        self._cut_job = False
        self._record = Record(_POLLS)
        self._foreign: set[str] = set()
        self._foreign_at: list[str] = []
        self._foreign_count = 0

    def add(self, line: TranscriptView) -> None:
        """Take the next window's view."""
        crc = crc_context(line, self._crc)
        for i, s in enumerate(line.transmissions):
            self._tried.add(s.address)
            if s.address not in self._polled and reply_problem(s, crc[i], self.uncertainty) is None:
                self._polled.add(s.address)
            if s.is_command and s.address not in ADDRESS_CHARS and s.address != "?":
                self._foreign.add(s.address)
                self._foreign_count += 1
                if len(self._foreign_at) < _FOREIGN_CITED:
                    self._foreign_at.append(s.at())
        self._cut_job = self._cut_job or bool(line.cut_parts)
        self._record.add(line.transmissions)

    def findings(self) -> list[Finding]:
        """R-4.3-03's and R-4.3-04's findings of the recording so far."""
        return [self._polls(), self._letters()]

    def _polls(self) -> Finding:
        digits = [a for a in "0123456789" if a not in self._polled]
        if not digits:
            return Finding(
                "R-4.3-03",
                Verdict.PASS,
                "sensors at 0-9 each polled and answered",
                observed=len(self._polled),
            )
        unsent = [a for a in digits if a not in self._tried]
        return Finding(
            "R-4.3-03",
            Verdict.FAIL if unsent and not self._cut_job else Verdict.INCONCLUSIVE,
            "addresses never polled successfully: "
            + ", ".join(digits)
            + ("" if unsent else " (each was polled, never validly answered)")
            + (f" ({CUT_SHORT})" if unsent and self._cut_job else ""),
            evidence=self._record.evidence([f"{a}!" for a in digits]),
            observed=self._record.count,
        )

    def _letters(self) -> Finding:
        letters = sorted(a for a in self._polled if a.isalpha())
        if self._foreign:  # a MAY rule: the Finding caps this at WARN
            shown = ", ".join(f"'{escape(a)}'" for a in sorted(self._foreign))
            return Finding(
                "R-4.3-04",
                Verdict.FAIL,
                f"addressed {shown}, not an address",
                decision="A17",
                evidence=list(self._foreign_at),
                observed=self._foreign_count,
            )
        if letters:
            return Finding(
                "R-4.3-04",
                Verdict.PASS,
                f"letter addresses used: {' '.join(letters)}",
                observed=len(letters),
            )
        return Finding(
            "R-4.3-04", Verdict.NA, "the recorder did not use letter addresses (optional)"
        )


def _could_be_extended(text: str) -> bool:
    """Whether a command no one asked for may be an extended one changed on its way ('XSN!'
    for '0XSN!', transparent-drops-address): it reads as one, or as no command at all. A
    recorder's own a! or aI! (sent to wake an address first) is neither."""
    try:
        return parse_command(text).kind is Kind.EXTENDED
    except CommandError:
        return True


def judge_transparent(
    line: TranscriptView,
    asked: Sequence[str],
    uncertainty: float,
    relayed: dict[str, str] | None,
) -> list[Finding]:
    """R-4.4.14-01: each host command goes out whole, after a break, and (when the recorder
    reports it) the sensor's reply is relayed unchanged; a PASS without that report says the
    relay was not judged (an outside logger on the C kit, which has no call to report it).
    R-4.4.14-02: basic, extended and metadata commands pass unchanged. R-4.4.13-03: extended
    commands start with the address and end with ``!``. R-6.3-01: metadata commands pass
    through (what a recorder that does not understand metadata must at least do)."""
    mechanism = Tally(("R-4.4.14-01",))
    unchanged = Tally(("R-4.4.14-02", "R-4.4.13-03", "R-6.3-01"))
    wanted = set(asked)
    # what went out that was not asked for: a command changed on its way (the only "instead")
    unasked = list(dict.fromkeys(s.text for s in line.transmissions if s.text not in wanted))
    for text in asked:
        where = escape(text)
        cmd = parse_command(text)
        ids = ["R-4.4.14-02"]
        if cmd.kind is Kind.EXTENDED:
            ids.append("R-4.4.13-03")
        if cmd.kind in (Kind.METADATA, Kind.IDENTIFY_MEASUREMENT):
            ids.append("R-6.3-01")
        unchanged.observe(where, ids=ids)
        matching = [s for s in line.transmissions if s.text == text]
        if not matching:
            same = [t for t in unasked if t[:1] == text[:1]]
            said, shown = ("sent instead", same) if same else ("sent unasked", unasked)
            listed = ", ".join(repr(escape(t)) for t in shown[:3])
            missing = f"not on the wire as typed ({said}: {listed})" if shown else "never sent"
            for rid in ids:
                if line.cut_parts:
                    unchanged.undecide(rid, where, f"{CUT_SHORT} ({missing})")
                elif rid == "R-4.4.13-03" and not any(map(_could_be_extended, unasked)):
                    # the form of an extended command rests on one on the wire: the twenty-
                    # third round's STM32 library sends none (R-4.4.14-02 FAILs that)
                    unchanged.undecide(rid, where, "never sent: no extended command on the wire")
                else:
                    unchanged.fail(rid, where, missing)
            continue
        mechanism.observe(where)  # only a command that went out shows how it went out
        first, last = matching[0], matching[-1]
        stalls = line.stalls  # the tool's host's (truth34): a break it laid with the command
        # as one late read, a reply it held back or cut, are its doing, not the recorder's
        if first.break_event is None:
            fail_unless_stalled(
                mechanism,
                stalls,
                "R-4.4.14-01",
                where,
                "sent without a break to wake the bus",
                (first.first_char - STANDBY_MARKING, first.end),
            )
        if relayed is not None:
            got = relayed.get(text)
            want = decode_7e1(last.reply)
            if got is not None and got != want:
                heard = last.heard
                fail_unless_stalled(
                    mechanism,
                    stalls,
                    "R-4.4.14-01",
                    where,
                    f"relayed '{escape(got[:40])}', the sensor sent '{escape(want[:40])}'",
                    (first.start, heard[-1].end if heard else last.end),
                )
    through = "passed through"
    if relayed is None:  # the wire shows the break and the command, not what the host got
        through += " (the replies relayed to the host were not reported: not judged)"
    return [*mechanism.findings(through), *unchanged.findings("passed unchanged")]


def judge_multiline_end(
    line: TranscriptView, relayed: dict[str, str] | None, uncertainty: float
) -> list[Finding]:
    """R-4.4.13.1-04 (SHOULD): multi-line text without ETX is complete once no further line
    starts within 150 ms: the recorder neither talks over a line that may still come nor
    loses the lines it got."""
    found: list[Finding] = []
    for i, s in enumerate(line.transmissions):
        answer = s.reply
        if len(answer) < 2 or answer[1].char7 != STX:
            continue
        cut = cut_off(s)
        if cut is not None:  # the recorder broke into a line: it waited for no end at all
            found.append(
                Finding(
                    "R-4.4.13.1-04",
                    Verdict.WARN,
                    f"{cut}: it did not wait for the text to end",
                    evidence=[f"text in reply to {s.at()}"],
                    observed=1,
                )
            )
            continue
        if answer[-1].char7 != 0x0A:
            continue
        nxt = line.transmissions[i + 1] if i + 1 < len(line.transmissions) else None
        where = [f"text in reply to {s.at()}"]
        if nxt is not None:
            f = judge_window(
                "R-4.4.13.1-04",
                "marking after the last line before the recorder spoke again",
                nxt.start - answer[-1].end,
                uncertainty,
                low=MULTILINE_GAP_MAX,
                should=True,
                evidence=where,
            )
            found.append(f)
        if relayed is not None and s.text in relayed:
            lines = decode_7e1(answer).count("\r\n")
            got = relayed[s.text].count("\r\n")
            if got < lines:
                found.append(
                    Finding(
                        "R-4.4.13.1-04",
                        Verdict.WARN,
                        f"relayed {got} of {lines} lines",
                        evidence=where,
                        observed=1,
                    )
                )
    return [combine("R-4.4.13.1-04", found, "multi-line text without ETX")]
