"""Timing margins (issue 24, item 3): every timed rule's measurements as a distribution in
``verdicts.json`` and as a strip chart in ``report.html``, drawn from the figures the judges
decided on."""

from __future__ import annotations

import re

import pytest

from conformance.catalog import requirement
from conformance.conduct import run_once
from conformance.judges.timing import Measured, Window, combine, distribution, judge_window
from conformance.reports.margins import margins_html, margins_json, nice_ticks, strip
from conformance.results import RequirementResult
from conformance.verdicts import MAX_TICKS, Verdict

LATE = Window("R-7.0-10", "reply start", high=0.015)  # ≤ 15.00 ms + 0.40 ms tolerance


def test_a_combined_finding_carries_every_measurement():
    seen = [Measured(LATE, ms / 1e3, 0.0005, None) for ms in (9.0, 9.5, 14.2, 10.0)]
    found = combine("R-7.0-10", seen, "reply")
    d = found.distribution
    assert d is not None and found.verdict is Verdict.PASS
    assert (d.count, d.min_ms, d.median_ms, d.max_ms) == (4, 9.0, 9.75, 14.2)
    assert d.high_ms == 15.4 and d.low_ms is None and not d.mixed_limits
    assert d.margin_ms == pytest.approx(1.2)  # 15.40 - 14.20, the closest one
    assert d.margin_in_uncertainty() == pytest.approx(2.4)  # 1.2 ms / 0.5 ms
    assert d.values_ms == [9.0, 9.5, 10.0, 14.2] and d.slack_ms[-1] == pytest.approx(1.2)


def test_a_measurement_outside_the_limit_has_a_negative_margin():
    seen = [Measured(LATE, ms / 1e3, 0.0, [f"reply after {ms} ms"]) for ms in (9.0, 20.0)]
    found = combine("R-7.0-10", seen, "reply")
    assert found.verdict is Verdict.FAIL
    assert found.distribution is not None and found.distribution.margin_ms == pytest.approx(-4.6)


def test_ticks_are_sampled_but_keep_the_extremes():
    seen = [Measured(LATE, (5 + i * 1e-3) / 1e3, 0.0, None) for i in range(5000)]
    seen.append(Measured(LATE, 0.0152, 0.0, None))
    d = distribution(seen)
    assert d is not None and d.count == 5001 and len(d.values_ms) == MAX_TICKS
    assert d.values_ms[0] == 5.0 and d.values_ms[-1] == 15.2
    assert d.margin_ms == pytest.approx(0.2)


def test_observations_judged_against_different_limits_are_compared_by_their_slack():
    waits = [
        judge_window("R-4.4.5-04", "wait", 2.3, 0.0, low=2.0),
        judge_window("R-4.4.5-04", "wait", 1.2, 0.0, low=1.0),
    ]
    d = distribution(waits)
    assert d is not None and d.mixed_limits and d.low_ms is None
    assert sorted(d.slack_ms) == pytest.approx([200.4, 300.4])  # the 0.40 ms tolerance
    assert d.margin_ms == pytest.approx(200.4)


def test_a_single_judged_window_is_a_distribution_of_one():
    f = judge_window("R-4.1-01", "spacing", 8.333e-3, 0.0, low=8.0e-3, high=8.5e-3, tolerance=0)
    assert f.distribution is not None and f.distribution.count == 1
    assert f.distribution.margin_ms == pytest.approx(0.167, abs=1e-3)


def test_axis_values_are_round():
    assert nice_ticks(7.5, 16.0) == [8.0, 10.0, 12.0, 14.0, 16.0]
    assert nice_ticks(149.4, 150.6) == [149.5, 150.0, 150.5]


def _result(found) -> RequirementResult:
    return RequirementResult(requirement("R-7.0-10"), found.verdict, [found], [])


def test_the_strip_draws_the_limit_the_band_and_a_tick_per_measurement():
    seen = [Measured(LATE, ms / 1e3, 0.0008, None) for ms in (9.0, 9.5, 12.0)]
    found = combine("R-7.0-10", seen, "reply")
    svg = strip(_result(found), found, 3)
    assert svg.count('class="sdi12-tick"') == 3
    assert svg.count('class="sdi12-limit"') == 1 and "limit 15.40 ms" in svg
    assert 'class="sdi12-band"' in svg and "± 0.80 ms" in svg
    assert "n=3 · 9.00 / 9.50 / 12.00 ms" in svg and "margin 3.40 ms = 4.25 u" in svg
    # the limit line lies right of every tick: the figures are drawn where they were measured
    xs = [float(v) for v in re.findall(r'class="sdi12-tick" x1="([\d.]+)"', svg)]
    (limit,) = [float(v) for v in re.findall(r'class="sdi12-limit" x1="([\d.]+)"', svg)]
    assert max(xs) < limit


def test_the_figures_fit_their_column_on_a_bench_links_uncertainty():
    """A late reply judged with a bench link's ±15.34 ms: the right-hand figures, drawn in
    10 px type, must fit the FIGURES column (about 5.6 px a character), not run off the strip
    ("margin -4.60 ms = -0.30 u · ±15.34 ms" did)."""
    from conformance.reports.margins import FIGURES

    seen = [Measured(LATE, ms / 1e3, 0.01534, None) for ms in (9.0, 20.0, 123.4)]
    found = combine("R-7.0-10", seen, "reply")
    svg = strip(_result(found), found, 1234)
    right = re.findall(r'<text x="(\d+)" y="\d+" font-size="10">([^<]*)</text>', svg)
    lines = [text for x, text in right if int(x) > 400]
    assert any("u" in t and "margin" in t for t in lines) and any("±15.34 ms" in t for t in lines)
    assert max(len(t) for t in lines) * 5.6 <= FIGURES - 8, lines


def test_no_band_on_an_exact_clock_and_no_section_without_timed_rules():
    found = combine("R-7.0-10", [Measured(LATE, 0.009, 0.0, None)], "reply")
    assert 'class="sdi12-band"' not in strip(_result(found), found, 1)
    untimed = RequirementResult(requirement("R-4.2-01"), Verdict.PASS, [], [])
    assert margins_html([untimed]) == "" and margins_json([untimed]) == []


@pytest.fixture(scope="module")
def clean_and_late() -> tuple[dict, dict]:
    return run_once("sim"), run_once("sim://?faults=response-too-late")


def test_verdicts_json_lists_the_margins_of_a_run(clean_and_late):
    clean, late = clean_and_late
    rows = {m["requirement"]: m for m in clean["margins"]}
    assert {"R-7.0-09", "R-7.0-10", "R-7.0-12"} <= set(rows)
    assert rows["R-7.0-10"]["margin_ms"] == pytest.approx(6.4) and rows["R-7.0-10"]["count"] > 100
    bad = {m["requirement"]: m for m in late["margins"]}["R-7.0-10"]
    assert bad["verdict"] == "FAIL" and bad["margin_ms"] == pytest.approx(-4.6)
    # the finding carries the whole distribution, its ticks included
    (f,) = [r for r in late["requirements"] if r["id"] == "R-7.0-10"][0]["findings"]
    assert f["distribution"]["values_ms"] and f["distribution"]["max_ms"] == 20.0
