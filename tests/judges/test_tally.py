"""A finding quotes the first few offending observations in its detail and says "(+N more)";
the rest used to be dropped, so neither verdicts.json nor the report had them (issue 20,
"Findings cut to '(+1 more)'"). They are kept in the evidence."""

from __future__ import annotations

from conformance.judges.tally import SHOWN, Tally
from conformance.protocol.responses import Violation
from conformance.verdicts import Verdict


def test_every_offending_observation_is_kept_in_the_evidence():
    tally = Tally(("R-4.4.8-03",))
    for i in range(SHOWN + 2):
        tally.observe(f"0M{i}!", [Violation("R-4.4.8-03", f"{i} values for 9 announced")])
    (f,) = tally.findings()
    assert f.verdict is Verdict.FAIL
    assert f.detail.endswith("(+2 more)")
    text = "\n".join(f.evidence)
    for i in range(SHOWN + 2):
        assert f"{i} values for 9 announced" in f.detail + text, i
    assert f.evidence[-1] == f"{SHOWN + 2} observation(s)"
