"""``MeasuredAsJudged`` stands for a whole :func:`judge_window` finding per interval (the
recorder's command character gaps): combined, the observations give the same finding, field
for field and distribution and all, as the findings they replace, whatever their verdicts;
and the recorder's character-gap judge gives what it gave with a finding per gap."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges.recorder import commands
from conformance.judges.recorder.common import combine
from conformance.judges.timing import MeasuredAsJudged, Window, judge_window
from conformance.protocol.timing import INTER_CHAR_GAP_MAX
from conformance.verdicts import Finding, Verdict
from tests.judges.recorder.test_recorder_judges import Wire

LIMIT = INTER_CHAR_GAP_MAX
# gaps around the limit (inside, on it, straddling it with the uncertainty, outside), and
# values that round alike to the ms's third decimal, so ordering and medians are tested
gap = st.sampled_from([0.0, 1e-4, 0.0008334, 0.00083349, LIMIT - 2e-5, LIMIT, LIMIT + 1e-9,
                       LIMIT + 3e-5, 0.0025, -1e-5]) | st.floats(-0.001, 0.004)  # fmt: skip
uncertainty = st.sampled_from([0.0, 1e-6, 5e-5])


def old_way(gaps: list[float], u: float) -> list[Finding]:
    return [
        judge_window(
            "R-7.0-13",
            "marking between command characters",
            g,
            u,
            high=LIMIT,
            tolerance=0.0,
            evidence=[f"in gap {i}"],
        )  # fmt: skip
        for i, g in enumerate(gaps)
    ]


def new_way(gaps: list[float], u: float) -> list[MeasuredAsJudged]:
    window = Window("R-7.0-13", "marking between command characters", high=LIMIT, tolerance=0.0)
    return [MeasuredAsJudged(window, g, u, [f"in gap {i}"]) for i, g in enumerate(gaps)]


@given(st.lists(gap, max_size=40), uncertainty)
def test_combined_as_the_findings_were(gaps: list[float], u: float):
    old = combine("R-7.0-13", old_way(gaps, u), "character gap")
    new = combine("R-7.0-13", new_way(gaps, u), "character gap")
    assert new.to_json() == old.to_json()


@given(st.lists(gap, min_size=1, max_size=10), uncertainty)
def test_each_reads_as_its_finding(gaps: list[float], u: float):
    for f, m in zip(old_way(gaps, u), new_way(gaps, u), strict=True):
        assert (m.verdict, m.measured_ms, m.margin_ms, m.uncertainty_ms) == (
            f.verdict, f.measured_ms, f.margin_ms, f.uncertainty_ms,
        )  # fmt: skip
        assert m.finding.to_json() == f.to_json()
        assert m.distribution == f.distribution


def test_a_fail_is_a_fail():
    found = combine("R-7.0-13", new_way([0.0005, LIMIT + 0.001], 0.0), "character gap")
    assert found.verdict is Verdict.FAIL and found.evidence == ["in gap 1"]


@given(st.lists(st.sampled_from([0.5, 1.0, 1.66, 1.67, 1.9, 3.0]), min_size=1, max_size=6))
def test_the_judge_gives_what_a_finding_per_gap_gave(gaps_ms: list[float]):
    """judge_character_gaps on a recorder's commands, against combine() over the findings
    it made per gap before (the gaps read off the same view)."""
    wire = Wire()
    for g in gaps_ms:
        wire.brk().rec("0M!", gap_ms=g)
    view = wire.view()
    measured = [
        (b.start - a.end, s)
        for s in view.transmissions
        for a, b in zip(s.chars, s.chars[1:], strict=False)
    ]
    before = [
        judge_window(
            "R-7.0-13",
            "marking between command characters",
            g,
            1e-6,
            high=LIMIT,
            tolerance=0.0,
            evidence=[f"in {s.at()}"],
        )  # fmt: skip
        for g, s in measured
    ]
    found = commands.judge_character_gaps(view, 1e-6)[0]
    assert found.to_json() == combine("R-7.0-13", before, "character gap").to_json()
