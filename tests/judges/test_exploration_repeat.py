"""The exploration's D0-repeat check (R-4.4.5-10) counts only where the earlier D0 held
values: an empty buffer read twice cannot show data lost (continuous-overwrites-data beside
d0-empty PASSed "held over 48 checks" from a sensor that never delivered a value, seed 4066)."""

from __future__ import annotations

import pytest

from conformance.judges.exploration import Observation, held_findings, judge
from conformance.verdicts import Verdict


def repeat(previous: str | None, reply: str) -> Observation:
    return Observation("repeat", "0D0!", reply, previous=previous)


@pytest.mark.parametrize(
    ("previous", "reply"),
    [
        (None, "0+1.5\r\n"),  # the first D0 after a measurement: nothing to compare with
        ("0\r\n", "0\r\n"),  # an empty buffer read twice
        ("0Ba]\r\n", "0Ba]\r\n"),  # an empty CRC reply: CRC characters are never digits
    ],
)
def test_a_repeat_of_nothing_is_no_check(previous, reply):
    assert judge(repeat(previous, reply)).checked == ()


def test_values_read_again_are_a_check_and_lost_values_breach_it():
    kept = judge(repeat("0+1.5-2\r\n", "0+1.5-2\r\n"))
    assert kept.checked == ("R-4.4.5-10",) and kept.breach is None
    lost = judge(repeat("0+1.5-2\r\n", "0\r\n"))
    assert lost.breach is not None and lost.breach.requirement == "R-4.4.5-10"


def test_a_held_repeat_is_a_partial_pass_the_other_rules_whole_ones():
    """R-4.4.5-10's PASS from repeated D0s checks repeated reads only: no pair need span the
    aRn! continuous-overwrites-data empties the buffer at (seed 4197), so it is partial and
    cannot stand for the retention case; a framing check is a PASS of its rule as usual."""
    kept = repeat("0+1.5-2\r\n", "0+1.5-2\r\n")
    framed = Observation("framing", "0D0!", "0+1.5-2\r\n", "0")
    found = {f.requirement: f for f in held_findings([kept, framed], 10)}
    assert found["R-4.4.5-10"].verdict is Verdict.PASS and found["R-4.4.5-10"].partial
    assert found["R-4.3-01"].verdict is Verdict.PASS and not found["R-4.3-01"].partial


def test_r_4_2_03_framing_of_replies_is_a_partial_pass():
    """The exploration reads replies only; R-4.2-03 names service requests too, so its
    framing PASS is partial (a -k run of it alone: INCONCLUSIVE), R-4.3-01's whole."""
    framed = Observation("framing", "0I!", "013TEST\r\n", "0")
    found = {f.requirement: f for f in held_findings([framed], 10)}
    assert found["R-4.2-03"].verdict is Verdict.PASS and found["R-4.2-03"].partial
    assert not found["R-4.3-01"].partial


def test_silence_to_a_foreign_command_that_maybe_collided_is_no_check():
    """R-4.0-01's exploration check counted silence to a foreign command sent the way the
    sensor hears one even where sensor characters met it (it may not have been heard)."""
    from conformance.judges.exploration import Observation, checks

    heard = Observation("foreign", "9I!", "", "9", answered=False, marked=True)
    met = Observation("foreign", "9I!", "", "9", answered=False, marked=True, collided=True)
    assert checks([heard])["R-4.0-01"] == 1
    assert checks([met])["R-4.0-01"] == 0


def test_lost_values_after_a_foreign_measurement_a_late_sensor_may_have_taken_are_no_check():
    """answers-old-address + replies-after-retry (truth21): 9M!, to the address the sensor
    had been moved from and still answers at, started a measurement whose reply, 80 ms
    late, the next break cut; D0 then read '0<CR><LF>' and R-4.4.5-10 FAILed. Whether the
    data were lost or replaced by that measurement is R-4.0-01's question: no check."""
    lost = Observation("repeat", "0D0!", "0\r\n", previous="0+1.5-2\r\n", unheard="9M!")
    assert judge(lost) == judge(Observation("repeat", "0D0!", "0\r\n", previous=None))
    kept = Observation("repeat", "0D0!", "0+1.5-2\r\n", previous="0+1.5-2\r\n", unheard="9M!")
    assert judge(kept).checked == ("R-4.4.5-10",) and judge(kept).breach is None
