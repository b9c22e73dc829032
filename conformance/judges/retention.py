"""R-4.4.5-10 from a measurement's D replies read twice: once after it, once after a break,
standby and the commands that must not touch the buffer (aI!, a!, aR0!, aRC0!).

The case sends; this judges. A pair of reads is compared only where both drew a reply of
their own in the window: a D read the tool gave up on (its reply late, met by the retry, or
maybe the command before's) has no reply to compare, and two such reads "identical" as two
silences PASSed the rule beside continuous-overwrites-data, whose aR0! empties the buffer
(replies-after-retry: every reply 80 ms late, truth21). Nor is a pair that differs where
either read was held up by a stall of the tool's own host (truth29): a cut reply differs
from a whole one, and the host's doing is no lost buffer (INCONCLUSIVE, the stall named).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..protocol.responses import holds_values
from ..tool_recorder.records import Exchange
from ..transcript import escape
from ..verdicts import Finding, Verdict, failed, inconclusive, passed
from .cite import cite, listed, shown
from .late_before import answered_late
from .stalled import unless_stalled

RULE = "R-4.4.5-10"


def _unread(ex: Exchange) -> bool:
    """No reply of its own: silent in its windows, or what it took may be another's."""
    return not ex.answered or bool(answered_late(ex))


def retained(before: Sequence[Exchange], again: Sequence[Exchange]) -> Finding:
    """R-4.4.5-10 over the D reads ``before`` and the same reads ``again``: FAIL where a
    pair both read differs (or a read is missing ``again``), INCONCLUSIVE where a pair was
    not both read, differs only where the tool's host stalled over either read
    (:func:`~.stalled.unless_stalled`), or nothing read before held values (a lost buffer
    would change nothing), PASS otherwise."""
    pairs = list(zip(before, again, strict=False))
    held: Finding | None = None  # the first change seen only in a read the host stalled over
    for n, (first, second) in enumerate(pairs):
        if _unread(first) or _unread(second) or first.reply_text == second.reply_text:
            continue
        changed = failed(
            RULE,
            f"D{n} changed from '{escape(first.reply_text)}' to '{escape(second.reply_text)}'",
            evidence=cite([first, second]),
            observed=len(before),
        )
        changed = unless_stalled(changed, [first, second], together=True)
        if changed.verdict is Verdict.FAIL:
            return changed
        held = held or changed
    if len(again) < len(before):
        missing = before[len(again)]
        return failed(
            RULE,
            f"D{len(again)} changed from '{escape(missing.reply_text)}' to '(nothing)'",
            evidence=cite([missing]),
            observed=len(before),
        )
    if held is not None:
        return held
    unread = [ex for pair in pairs for ex in pair if _unread(ex)]
    if unread:
        detail = f"{listed([answered_late(ex) or shown(ex) for ex in unread])}: not compared"
        return inconclusive(RULE, detail, evidence=cite(unread), observed=len(unread))
    if not any(holds_values(ex.reply_text) for ex in before):
        detail = f"no values read before ({listed([shown(ex) for ex in before])}): nothing lost"
        return inconclusive(RULE, detail, evidence=cite(before), observed=len(before))
    return passed(
        RULE,
        f"{len(again)} D replies identical after break, standby and aI!/a!/aR0!/aRC0!",
        observed=len(again),
    )
