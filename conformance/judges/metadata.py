"""Judges for the v1.4 identify-measurement and metadata commands (section 6)."""

from __future__ import annotations

import re

from ..protocol.responses import parse_measurement_reply_for, parse_metadata_reply, split_line
from ..tool_recorder.records import Exchange, Measurement
from ..transcript import escape
from ..verdicts import Finding, inconclusive
from .cite import cite, listed, shown
from .exchanges import answered_late, undecided_if_late
from .stalled import through_stall
from .tally import Tally

SHORT_ID = re.compile(r"[A-Za-z0-9_.+\-/ ]{1,8}")  # R-6.2.1-01: SHEF code or a short identifier


def identify_matches(pairs: list[tuple[Exchange, Measurement]]) -> list[Finding]:
    """R-6.1-02 with decision A9: same shape and count as the measurement's own reply; a
    different ttt is only a warning."""
    tally = Tally(("R-6.1-02",))
    tally.decision("R-6.1-02", "A9")
    for ident, m in pairs:
        label = escape(ident.text)
        if not ident.answered or not m.start.answered or ident.command is None:
            continue
        if late := answered_late(ident) or answered_late(m.start):
            # the reply taken may be the command before's: two counts of different
            # commands compared (answers-foreign-address + replies-after-retry, truth15)
            tally.undecide("R-6.1-02", label, f"{late} (R-7.0-10 judges its timing)")
            continue
        a, _ = split_line(ident.reply_text)
        b, _ = split_line(m.start.reply_text)
        pa = parse_measurement_reply_for(a, ident.command)
        pb = parse_measurement_reply_for(b, m.command)
        if pb.violations:
            continue  # the measurement's own reply is malformed: its rule judges that
        # either read stalled over by the tool's host: what the two show is undecided
        here = through_stall(tally, ident.stall or m.start.stall)
        here.observe(label)
        if pa.violations or len(a) != len(b):
            here.fail(
                "R-6.1-02", label, f"'{escape(a)}' is not shaped like {m.command}'s '{escape(b)}'"
            )
        elif pa.count != pb.count:
            here.fail("R-6.1-02", label, f"announces {pa.count} values, {m.command} {pb.count}")
        elif pa.ttt != pb.ttt:
            here.fail(
                "R-6.1-02", label, f"ttt {pa.ttt} differs from {m.command}'s {pb.ttt}", warning=True
            )
    return tally.findings("same reply as the measurement command")


def announced_count(ident: Exchange) -> int | None:
    """The value count an identify-measurement reply announces (None: no reply, or none
    readable in it)."""
    if not ident.answered or ident.command is None:
        return None
    body, _ = split_line(ident.reply_text)
    return parse_measurement_reply_for(body, ident.command).count


#: the rules over every record of a measurement's group: a PASS over the groups that were
#: read says nothing of a group whose records could not be counted, so not asked for
RECORD_RULES = ("R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2-07", "R-6.2.1-01", "R-6.2.2-01")


def uncounted_groups(
    groups: list[tuple[Exchange, Exchange]], ids: tuple[str, ...]
) -> list[Finding]:
    """The record rules (:data:`RECORD_RULES`, those of ``ids``) for the measurements (start
    exchange, identify exchange) of which neither reply gave a value count although one of
    them answered: their records cannot be counted, so none was asked for, and each rule is
    INCONCLUSIVE for them, whatever the other groups' records showed (a FAIL found there
    still stands; metadata-too-long + measure-ttt-two-digits, seed 4118: R-6.2-04 PASSed on
    276 other records while aM!'s too-long one was never read). Observed: those replies."""
    if not groups:
        return []
    pairs = listed([f"{shown(start)}, {shown(ident)}" for start, ident in groups])
    return [
        inconclusive(
            rule,
            f"no value count to ask the records by, so none was read: {pairs}",
            evidence=cite(ex for pair in groups for ex in pair),
            observed=len(groups),
        )
        for rule in RECORD_RULES
        if rule in ids
    ]


def records(
    exchanges: list[tuple[Exchange, bool, bool | None]], ids: tuple[str, ...]
) -> list[Finding]:
    """Metadata replies: each item is (exchange, crc expected, index expected valid); valid
    None: inside a count only the identify reply announced (its measurement gave none), where
    a missing record may as well be that count's fault (R-6.1-02, which has no measurement
    reply to compare it with): R-6.2-07 is INCONCLUSIVE there, never FAIL."""
    whole = Tally(ids)  # ``tally``: the same, seen through each record's read (a stall)
    unconfirmed: list[Exchange] = []
    for ex, crc, valid in exchanges:
        label = escape(ex.text)
        count_rule = [] if valid is None else ["R-6.2-07" if valid else "R-6.2-05"]
        if undecided_if_late(whole, ex, ["R-6.2-01", *count_rule]):
            if valid is None:
                unconfirmed.append(ex)
            continue
        tally = through_stall(whole, ex.stall)  # what a stalled read shows is undecided
        if not ex.answered:
            if valid is None:
                unconfirmed.append(ex)
            else:
                tally.fail("R-6.2-07" if valid else "R-6.2-05", label, f"{label} got no reply")
            tally.fail("R-6.2-01", label, f"{label} got no reply")
            continue
        body, framing = split_line(ex.reply_text, crc_positions=3 if crc else 0)
        reply = parse_metadata_reply(body, crc_expected=crc, expected_address=ex.text[0])
        tally.observe(label, framing, ids=["R-6.2-01"])
        if valid is None and reply.invalid_index:
            unconfirmed.append(ex)
        elif valid is not False:
            tally.observe(
                label,
                reply.violations,
                ids=["R-6.2-02", "R-6.2-03", "R-6.2-04", "R-6.2.2-01", "R-6.2-07", "R-6.2.1-01"],
            )
            if reply.invalid_index:
                tally.fail(
                    "R-6.2-07",
                    label,
                    f"{label} answered the invalid-index reply for an "
                    "index inside the announced count",
                )
            elif reply.fields and not SHORT_ID.fullmatch(reply.fields[0]):
                tally.fail(
                    "R-6.2.1-01",
                    label,
                    f"field 1 '{escape(reply.fields[0])}' is neither "
                    "a SHEF code nor a short identifier",
                    warning=True,
                )
        else:
            tally.observe(
                label,
                [v for v in reply.violations if v.requirement == "R-6.2-05"],
                ids=["R-6.2-05"],
            )
            if not reply.invalid_index:
                tally.fail(
                    "R-6.2-05",
                    label,
                    f"invalid index answered '{escape(body)}' instead "
                    f"of 'a{'<CRC>' if crc else ''}<CR><LF>'",
                )
    return whole.findings() + _unconfirmed(unconfirmed, ids)


def _unconfirmed(missing: list[Exchange], ids: tuple[str, ...]) -> list[Finding]:
    """R-6.2-07 INCONCLUSIVE for records missing inside a count only an identify reply gave."""
    if not missing or "R-6.2-07" not in ids:
        return []
    return [
        inconclusive(
            "R-6.2-07",
            "no record inside a count only the identify reply announced (its measurement "
            f"gave none to confirm it): {listed([shown(ex) for ex in missing])}",
            evidence=cite(missing),
            observed=len(missing),
        )
    ]
