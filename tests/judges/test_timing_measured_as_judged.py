"""``MeasuredAsJudged`` stands for a whole :func:`judge_window` finding per interval (the
recorder's command character gaps, break lengths and markings after a break): combined, the
observations give the same finding, field for field and distribution and all, as the
findings they replace, whatever their verdicts; and the recorder's character-gap and break
judges give what they gave with a finding per interval."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges.recorder import breaks, commands
from conformance.judges.recorder.common import combine
from conformance.judges.timing import MeasuredAsJudged, Window, judge_window
from conformance.protocol.timing import (
    BREAK_MIN,
    INTER_CHAR_GAP_MAX,
    MARKING_AFTER_BREAK,
    TOLERANCE,
)
from conformance.verdicts import Finding, Verdict
from tests.judges.recorder.test_recorder_judges import Wire

LIMIT = INTER_CHAR_GAP_MAX
# gaps around the limit (inside, on it, straddling it with the uncertainty, outside), and
# values that round alike to the ms's third decimal, so ordering and medians are tested
gap = st.sampled_from([0.0, 1e-4, 0.0008334, 0.00083349, LIMIT - 2e-5, LIMIT, LIMIT + 1e-9,
                       LIMIT + 3e-5, 0.0025, -1e-5]) | st.floats(-0.001, 0.004)  # fmt: skip
uncertainty = st.sampled_from([0.0, 1e-6, 5e-5])


#: the recorder judges' windows that keep one observation per interval: R-7.0-13's command
#: character gaps (a maximum, no tolerance), R-7.0-02's break length and R-7.0-06's marking
#: after a break (minimums, the ±0.40 ms tolerance)
WINDOWS = {
    "gap": ("R-7.0-13", "marking between command characters", None, LIMIT, 0.0),
    "break": ("R-7.0-02", "break length", BREAK_MIN, None, TOLERANCE),
    "marking": ("R-7.0-06", "marking after the break", MARKING_AFTER_BREAK, None, TOLERANCE),
}
# a window's edges and either side of them, the tolerance's edges too
edge = st.sampled_from([w[2] if w[2] is not None else w[3] for w in WINDOWS.values()])
near = st.builds(
    lambda e, d: e + d,
    edge,
    st.sampled_from([0.0, 1e-9, -1e-9, 2e-5, -2e-5, TOLERANCE, -TOLERANCE, 4.1e-4, -4.1e-4]),
)
interval = gap | near


def old_way(name: str, values: list[float], u: float) -> list[Finding]:
    rid, what, low, high, tol = WINDOWS[name]
    return [
        judge_window(
            rid, what, v, u, low=low, high=high, tolerance=tol, evidence=[f"at {i}"]
        )  # fmt: skip
        for i, v in enumerate(values)
    ]


def new_way(name: str, values: list[float], u: float) -> list[MeasuredAsJudged]:
    rid, what, low, high, tol = WINDOWS[name]
    window = Window(rid, what, low, high, tol)
    return [MeasuredAsJudged(window, v, u, [f"at {i}"]) for i, v in enumerate(values)]


@given(st.sampled_from(sorted(WINDOWS)), st.lists(interval, max_size=40), uncertainty)
def test_combined_as_the_findings_were(name: str, values: list[float], u: float):
    old = combine(WINDOWS[name][0], old_way(name, values, u), name)
    new = combine(WINDOWS[name][0], new_way(name, values, u), name)
    assert new.to_json() == old.to_json()


@given(st.sampled_from(sorted(WINDOWS)), st.lists(interval, min_size=1, max_size=10), uncertainty)
def test_each_reads_as_its_finding(name: str, values: list[float], u: float):
    for f, m in zip(old_way(name, values, u), new_way(name, values, u), strict=True):
        assert (m.verdict, m.measured_ms, m.margin_ms, m.uncertainty_ms) == (
            f.verdict, f.measured_ms, f.margin_ms, f.uncertainty_ms,
        )  # fmt: skip
        assert m.finding.to_json() == f.to_json()
        assert m.distribution == f.distribution


def test_a_fail_is_a_fail():
    found = combine("R-7.0-13", new_way("gap", [0.0005, LIMIT + 0.001], 0.0), "gap")
    assert found.verdict is Verdict.FAIL and found.evidence == ["at 1"]
    short = combine("R-7.0-02", new_way("break", [0.013, 0.010], 0.0), "break")
    assert short.verdict is Verdict.FAIL and short.evidence == ["at 1"]


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
    found, tolerance = commands.judge_character_gaps(view, 1e-6)
    assert found.to_json() == combine("R-7.0-13", before, "character gap").to_json()
    assert tolerance.to_json() == tolerance_as_judged(measured).to_json()


def tolerance_as_judged(measured: list) -> Finding:
    """R-7.0-01 as judge_character_gaps made it from its list of every (gap, command)."""
    leaning = [(g, s) for g, s in measured if LIMIT < g <= LIMIT + TOLERANCE]
    if leaning:
        gap, s = leaning[0]
        return Finding(
            "R-7.0-01",
            Verdict.FAIL,
            f"a {gap * 1e3:.2f} ms gap in {s.at()} relies on the ±0.40 ms tolerance, which the "
            f"1.66 ms character gap does not have ({len(leaning)} such gap(s))",
            measured_ms=round(gap * 1e3, 3),
            limit_ms=LIMIT * 1e3,
            evidence=[f"{g * 1e3:.2f} ms gap in {t.at()}" for g, t in leaning[:5]],
            observed=len(measured),
        )
    return Finding(
        "R-7.0-01",
        Verdict.PASS,
        f"{len(measured)} command character gaps, none inside the tolerance band the 1.66 ms "
        "limit does not have; ±0.40 ms applied to every other recorder limit",
        observed=len(measured),
    )


@given(
    st.lists(
        st.tuples(st.sampled_from([9.0, 11.5, 11.7, 12.0, 13.0]),
                  st.sampled_from([7.0, 7.95, 8.33, 9.0])),
        min_size=1, max_size=5,
    )
)  # fmt: skip
def test_the_break_judge_gives_what_a_finding_per_break_gave(held: list[tuple[float, float]]):
    """judge_breaks on a recorder's breaks (lengths and the marking after each, on both
    sides of their limits and tolerances), against combine() over a finding per break."""
    wire = Wire()
    for ms, marking_ms in held:
        wire.brk(ms, marking_ms).rec("0M!")
    view = wire.view()
    u = 1e-6
    lengths = [
        judge_window(
            "R-7.0-02",
            "break length",
            b.duration,
            max(u, b.duration_uncertainty or 0.0),
            low=BREAK_MIN,
            evidence=[f"break at t={b.start:.3f} s"],
        )  # fmt: skip
        for b in view.breaks
    ]
    markings = [
        judge_window(
            "R-7.0-06",
            "marking after the break",
            s.first_char - s.break_event.end,
            max(u, s.break_event.duration_uncertainty or 0.0),
            low=MARKING_AFTER_BREAK,
            evidence=[f"before {s.at()}"],
        )  # fmt: skip
        for s in view.transmissions
        if s.break_event is not None
    ]
    before = [combine("R-7.0-02", lengths, "break"), combine("R-7.0-06", markings, "marking")]
    found = breaks.judge_breaks(view, u)
    assert [f.to_json() for f in found] == [f.to_json() for f in before]
