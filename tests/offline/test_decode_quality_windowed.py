"""Each sensor's decode quality gathered a window at a time (issue 22's windowed judge: a
whole-run figure kept as counts and a float array, not events): ``decode_quality.Quality``
fed each window's characters of a sensor, with that window's share of the decode's bit-rate
errors (``CharRates.of_rates``), gives the note the whole capture's characters give.

The case a wrong merge gets wrong: one sensor heard in two windows, exact in the first and
2 % fast in the second, another 3 % fast between them: its character count, its min..max
and its median run over both windows (a merge keeping one window's figures, or a rate
slice taken from the wrong place, changes them), and a framing error counted in its first."""

from __future__ import annotations

from conformance.capture import decode_capture, export_events
from conformance.capture.uart import Decoded
from conformance.protocol.timing import BIT_TIME
from conformance.transcript import DUT
from conformance.view.segments import read_view
from conformance.view.windows import stream_windows, window_events, window_starts
from tests.capture.test_export import brk, chars
from tests.support.windowed_judges import qualities, qualities_windowed


def _exchange(address: str, start: float, fast_pct: float = 0.0) -> tuple[list, float]:
    """A break, ``aI!`` and the sensor's reply 9.5 ms after it, at ``fast_pct`` % above
    1200 baud; the events and where they end."""
    command = chars(f"{address}I!", start + 0.02)
    bit = BIT_TIME / (1 + fast_pct / 100)
    reply = chars(
        f"{address}14CONFORM EMU001100SN000{address}\r\n", command[-1].end + 9.5e-3, DUT, bit
    )
    return [brk(start, 0.013), *command, *reply], reply[-1].end


def test_a_sensor_heard_in_two_windows_has_one_note_over_both(tmp_path):
    first, end = _exchange("0", 0.05)
    between, end = _exchange("1", end + 0.1, fast_pct=3.0)
    last, _ = _exchange("0", end + 0.1, fast_pct=2.0)
    capture = tmp_path / "three.sr"
    export_events([*first, *between, *last], capture, sample_rate=1e6)
    decoded = decode_capture(str(capture))
    events, u = decoded.events, decoded.uncertainty_s
    whole = read_view(events)
    windows = list(window_events(events, whole, window_starts(whole)))
    assert len(windows) == 3
    expected = qualities(decoded, events, u)
    assert list(expected) == ["0", "1"]
    assert "56 character(s)" in expected["0"]
    assert qualities_windowed(decoded, windows, u) == expected
    assert qualities_windowed(decoded, stream_windows(iter(events), uncertainty=u), u) == expected


def test_a_framing_error_in_an_early_window_is_counted(tmp_path):
    """A framing error the decode reported (its problem item) on a reply character of the
    sensor's first window, the sensor heard again in a later one: counted once, in the note
    over both."""
    first, end = _exchange("0", 0.05)
    last, _ = _exchange("0", end + 0.1, fast_pct=1.0)
    capture = tmp_path / "broken.sr"
    export_events([*first, *last], capture, sample_rate=1e6)
    decoded = decode_capture(str(capture))
    events, u = decoded.events, decoded.uncertainty_s
    reply = [e for e in events if e.start > events[4].end][:5]  # after 0I!: its reply
    bad = reply[4]
    decoded.problems.append(Decoded("char", bad, bad.start, bad.end, True))  # framing error
    expected = qualities(decoded, events, u)
    assert "1 with a framing error" in expected["0"], expected
    assert qualities_windowed(decoded, stream_windows(iter(events), uncertainty=u), u) == expected
