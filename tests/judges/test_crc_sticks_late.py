"""R-4.4.12-03 where aIMC_001! was answered only late (``judges.crc_sticks``).

metadata-crc-sticks + replies-after-retry (truth21): aIMC_001!'s record came 80 ms late,
met by each retry, so the case's precondition "got no reply to follow" left an
INCONCLUSIVE resting on nothing, and test_crc_presence's PASS over D replies read before any
CRC metadata command set the rule's verdict: a missed FAIL. Hand-typed wire events; the
module is new, so every test here fails on the tree before (base-s61: no such module, and
the case extended no finding at all)."""

from __future__ import annotations

from conformance.judges.crc_sticks import after_late_request
from conformance.protocol import commands as cmds
from conformance.results import counted
from conformance.tool_recorder.records import NO_REPLY, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict, failed, passed, worst
from tests.support.hand_events import chars

META = "0IMC_001!"


def _late_meta() -> Exchange:
    """aIMC_001! sent, unanswered in its window; the retry 55 ms after it met its record,
    begun 80 ms after the first try (a stray of the retry's)."""
    first = chars(TOOL, META, 0.0)
    retry = chars(TOOL, META, first[-1].end + 0.055)
    record = chars(DUT, "0,TA,degC,air temperature;\r\n", first[-1].end + 0.080)
    return Exchange(
        cmds.parse_command(META),
        META,
        [
            Attempt(None, first, [], NO_REPLY, first[-1].end + 0.03),
            Attempt(None, retry, [], NO_REPLY, record[-1].end, retry=1, stray_events=record),
        ],
    )


def test_a_pass_before_the_metadata_command_no_longer_stands_alone() -> None:
    found = after_late_request(_late_meta(), [])
    assert [f.verdict for f in found] == [Verdict.INCONCLUSIVE]
    assert found[0].observed == 1 and "answered only after the reply window" in found[0].detail
    elsewhere = passed("R-4.4.12-03", "conforms (18 checked)", observed=18)
    assert worst(f.verdict for f in counted([elsewhere, *found])) is Verdict.INCONCLUSIVE


def test_d_replies_read_after_it_still_decide() -> None:
    """The sensor heard aIMC_001! (it answered, late): a D reply read after it with a CRC
    FAILs the rule, one without PASSes it."""
    fail = failed("R-4.4.12-03", "0D0! carries a CRC", evidence=["x"], observed=1)
    assert after_late_request(_late_meta(), [fail]) == [fail]
    ok = passed("R-4.4.12-03", "conforms (1 checked)", observed=1)
    assert after_late_request(_late_meta(), [ok]) == [ok]
