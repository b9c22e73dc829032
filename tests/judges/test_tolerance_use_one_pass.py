"""R-7.0-01's judge of the character gaps goes over them once (``wire._judge_tolerance_use``
skips the gaps below the 1.66..2.06 ms band): the finding two passes over a list of every
gap gave, for gaps around and inside the band and any uncertainty."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges import wire
from conformance.protocol.timing import INTER_CHAR_GAP_MAX, TOLERANCE
from conformance.verdicts import Finding, Verdict


def _two_passes(gaps: list[tuple[float, str]], uncertainty: float) -> Finding:
    """The judge as it was: a list of every (gap, where), filtered twice."""
    band_lo, band_hi = INTER_CHAR_GAP_MAX, INTER_CHAR_GAP_MAX + TOLERANCE
    sure = [(g, w) for g, w in gaps if g - uncertainty > band_lo and g + uncertainty <= band_hi]
    maybe = [(g, w) for g, w in gaps if g + uncertainty > band_lo and g - uncertainty <= band_hi]
    if sure:
        gap, where = sure[0]
        return Finding(
            "R-7.0-01",
            Verdict.FAIL,
            f"gap of {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} relies on the ±0.40 ms "
            f"tolerance, which the 1.66 ms character gap does not have ({len(sure)} such "
            "gap(s))",
            evidence=[where for _, where in sure[:5]],
            observed=len(gaps),
            measured_ms=round(gap * 1e3, 3),
            limit_ms=INTER_CHAR_GAP_MAX * 1e3,
            uncertainty_ms=round(uncertainty * 1e3, 3),
        )
    if maybe:
        gap, where = maybe[0]
        return Finding(
            "R-7.0-01",
            Verdict.INCONCLUSIVE,
            f"{len(maybe)} gap(s) such as {gap * 1e3:.2f} ms ± {uncertainty * 1e3:.2f} may lie "
            "in the 1.66..2.06 ms band, where no tolerance applies",
            evidence=[where],
            measured_ms=round(gap * 1e3, 3),
            limit_ms=INTER_CHAR_GAP_MAX * 1e3,
            uncertainty_ms=round(uncertainty * 1e3, 3),
        )
    if not gaps:
        return Finding("R-7.0-01", Verdict.INCONCLUSIVE, "no character gap observed")
    return Finding(
        "R-7.0-01",
        Verdict.PASS,
        f"{len(gaps)} character gaps: none leans on a tolerance the rule does not grant; "
        "±0.40 ms applied to every other limit",
        observed=len(gaps),
    )


gap_values = st.floats(-1e-3, 3e-3, allow_nan=False) | st.sampled_from(
    [0.0, INTER_CHAR_GAP_MAX, INTER_CHAR_GAP_MAX + TOLERANCE, 1.8e-3, 2.0e-3, 2.2e-3]
)


@given(
    st.lists(gap_values, max_size=30),
    st.sampled_from([0.0, 0.05e-3, 0.2e-3, 0.5e-3, 1e-3]) | st.floats(0.0, 2e-3),
)
def test_one_pass_is_two(values, uncertainty):
    gaps = [(g, f"in reply to {i}", None, None, ("c", "t", i)) for i, g in enumerate(values)]
    assert wire._judge_tolerance_use(gaps, uncertainty) == _two_passes(
        [(g, w) for g, w, *_ in gaps], uncertainty
    )
