"""R-4.4.12-03 after a CRC metadata command (aIMC_001!) the sensor answered only late.

The case asks aIMC_001!, then a plain measurement, and judges its D replies: a CRC there
outlived the command that asked for one (metadata-crc-sticks). Where aIMC_001!'s reply came
only after the window, met by the retries, the case's precondition ("got no reply to
follow") left an INCONCLUSIVE resting on nothing, which does not outvote another case's
PASS (``results.counted``): test_crc_presence's PASS over D replies read before any CRC
metadata command stood for the clause they cannot show, beside replies-after-retry, whose
plain D replies after aIMC_001! came late, with the CRC (truth21).
"""

from __future__ import annotations

from ..results import decides
from ..tool_recorder.records import Exchange
from ..verdicts import Finding, inconclusive
from .cite import cited
from .late_before import answered_late

RULE = "R-4.4.12-03"


def after_late_request(meta: Exchange, findings: list[Finding]) -> list[Finding]:
    """The case's findings where ``meta`` (aIMC_001!) was answered only late: the sensor
    heard it, so ``findings`` (the plain measurement's D replies after it) stand where one
    judged the rule; else R-4.4.12-03 INCONCLUSIVE resting on that late reply."""
    late = answered_late(meta)
    if not late or any(f.requirement == RULE and decides(f) for f in findings):
        return findings
    bare = "a" + meta.text[1:]
    why = (
        f"{bare} {late} (R-7.0-10 judges its timing), and no plain D reply after it was read"
        " in its window: whether its CRC outlived it is unread"
    )
    return [*findings, inconclusive(RULE, why, evidence=[cited(meta)], observed=1)]
