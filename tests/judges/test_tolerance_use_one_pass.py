"""R-7.0-01's judge of the character gaps goes over them once (``wire._judge_tolerance_use``
skips the gaps below the 1.66..2.06 ms band): the finding two passes over a list of every
gap gave, for gaps around and inside the band and any uncertainty."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.judges import wire
from conformance.protocol.timing import INTER_CHAR_GAP_MAX, TOLERANCE
from conformance.verdicts import Finding


def _two_passes(gaps: list[tuple[float, str]], uncertainty: float) -> Finding:
    """The judge as it was: a list of every (gap, where), filtered twice, the finding made
    from the two lists as the judge makes it."""
    band_lo, band_hi = INTER_CHAR_GAP_MAX, INTER_CHAR_GAP_MAX + TOLERANCE
    sure = [(g, w) for g, w in gaps if g - uncertainty > band_lo and g + uncertainty <= band_hi]
    maybe = [(g, w) for g, w in gaps if g + uncertainty > band_lo and g - uncertainty <= band_hi]
    return wire._tolerance_finding(sure, maybe, len(gaps), uncertainty)


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
