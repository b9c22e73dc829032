"""The bulk UART decoder (``conformance.capture.uart_bulk``) against the reference one
(``conformance.capture.uart``), which stays as it was: item for item, bit for bit, over
synthesised edge streams (frames at and off the nominal rate, framing and parity errors,
breaks, spacing pulses, glitches inside and between frames, random noise edges, odd gaps,
both polarities, captures cut anywhere, any chunking, windows small enough to carry frames
across), and ``decode_capture`` both ways over exported runs and the shared real captures."""

from __future__ import annotations

from collections import Counter

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conformance.capture import decode as capture_decode
from conformance.capture import uart, uart_bulk
from conformance.capture.export import export_events
from conformance.capture.levels import _RUNS
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from tests.support.paths import SHARED
from tests.support.shared_runs import copied_run

FRAME = st.tuples(
    st.just("frame"),
    st.integers(0, 255),
    st.sampled_from([1.0, 1.0, 1.0, 0.97, 1.03, 0.9, 1.12, 0.8, 1.25]),  # sender's bit / nominal
    st.booleans(),  # stop bit marking (False: a framing error)
    st.floats(0, 14),  # marking after it, in bits
)
BREAK = st.tuples(st.just("break"), st.floats(0.2, 20.0))  # ms: pulses, breaks and short ones
GLITCH = st.tuples(st.just("glitch"), st.floats(0.01, 0.9))  # bits
GAP = st.tuples(st.just("gap"), st.floats(0, 40))  # bits
TEXT = st.tuples(  # a reply: characters back to back, or nearly, from one sender
    st.just("text"),
    st.lists(st.integers(0, 255), min_size=1, max_size=30),
    st.sampled_from([1.0, 1.0, 0.98, 1.02, 0.95]),
    st.sampled_from([0.0, 0.0, 0.3, 1.0]),
)


@st.composite
def streams(draw):
    """An edge stream and the line it is decoded as (the decoder's keyword arguments)."""
    rate = draw(st.sampled_from([100_000.0, 1_000_000.0, 48_000.0, 76_800.0]))
    baud = draw(st.sampled_from([1200, 1200, 1200, 9600]))
    bit = rate / baud
    toggles: list[int] = []
    t = draw(st.floats(0, 30)) * bit
    for seg in draw(st.lists(st.one_of(FRAME, TEXT, BREAK, GLITCH, GAP), max_size=50)):
        if seg[0] == "text":
            _, wires, factor, after = seg
            b = bit * factor
            for wire in wires:
                for i, j in _RUNS[wire]:
                    toggles += [round(t + i * b), round(t + j * b)]
                t += (10 + after) * b
        elif seg[0] == "frame":
            _, wire, factor, stop, after = seg
            b = bit * factor
            runs = list(_RUNS[wire])
            if not stop:
                last = runs.pop() if runs and runs[-1][1] == 9 else (9, 9)
                runs.append((last[0], 10))
            for i, j in runs:
                toggles += [round(t + i * b), round(t + j * b)]
            t += (10 + after) * b
        elif seg[0] == "break":
            toggles += [round(t), round(t + seg[1] * 1e-3 * rate)]
            t += seg[1] * 1e-3 * rate + bit
        elif seg[0] == "glitch":
            toggles += [round(t), round(t + seg[1] * bit)]
            t += seg[1] * bit
        else:
            t += seg[1] * bit
    span = max(round(t), 1)
    toggles += draw(st.lists(st.integers(0, span), max_size=12))  # noise anywhere
    edges = sorted(x for x, n in Counter(toggles).items() if n % 2 and x >= 0)
    cuts = sorted(draw(st.lists(st.integers(0, len(edges)), max_size=5)))
    chunks = [edges[a:b] for a, b in zip([0, *cuts], [*cuts, len(edges)], strict=True)]
    end = draw(st.one_of(st.none(), st.integers(0, round(3 * bit))))
    last = edges[-1] if edges else 0
    kw = dict(
        initial_level=draw(st.integers(0, 1)),
        tick_rate=rate,
        invert=draw(st.booleans()),
        baud=baud,
        framing=uart.Framing.parse(draw(st.sampled_from(["7E1", "7O1", "8N1"]))),
        t0=draw(st.sampled_from([0.0, 1.5, -0.25])),
        uncertainty=1 / rate,
        period_ticks=draw(st.sampled_from([1.0, 2.0, 0.5])),
        end_tick=None if end is None else (lambda: last + end),
    )
    return chunks, kw


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(streams(), st.sampled_from([None, 4, 9, 33]))
def test_bulk_decoder_gives_the_reference_items(found, window):
    """``window``: edges held at a time (small ones carry frames from window to window)."""
    chunks, kw = found
    reference = list(uart.decode([list(c) for c in chunks], **kw))
    assert list(uart_bulk.decode([list(c) for c in chunks], window=window, **kw)) == reference


def both_ways(monkeypatch, path, **kw):
    """``decode_capture`` in bulk and by the reference decoder (no kept decode between)."""
    got = {}
    for bulk in (True, False):
        monkeypatch.setattr(capture_decode, "BULK", bulk)
        monkeypatch.setattr(capture_decode, "_LAST", None)
        got[bulk] = capture_decode.decode_capture(str(path), **kw)
    return got[True], got[False]


def same_decode(a, b) -> None:
    assert a.events == b.events
    assert a.problems == b.problems
    assert [x if x == x else "nan" for x in a.baud_error_pct] == [
        x if x == x else "nan" for x in b.baud_error_pct
    ]
    fields = ("chars", "framing_errors", "parity_errors", "glitches", "breaks", "pulses")
    assert [getattr(a, f) for f in fields] == [getattr(b, f) for f in fields]
    assert (a.partial_frames, a.notes, a.inverted, a.uncertainty_s) == (
        b.partial_frames,
        b.notes,
        b.inverted,
        b.uncertainty_s,
    )


def busy_run(slow: float) -> list[Event]:
    """Commands and replies, the replies' characters ``slow`` times a nominal frame long."""
    events: list[Event] = []
    t = 0.05
    for n in range(60):
        events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0125))
        t += 0.0125 + CHAR_TIME
        for origin, text, frame in (
            (TOOL, f"{n % 10}D0!", CHAR_TIME),
            (DUT, f"{n % 10}+1.23-45.6\r\n", CHAR_TIME * slow),
        ):
            for c in text:
                events.append(Event(EventKind.CHAR, origin, t, t + frame, wire=to_wire_7e1(ord(c))))
                t += frame
            t += 0.0095
    return events


@pytest.mark.parametrize("slow", [1.0, 1.03, 0.96])
@pytest.mark.parametrize("rate", [100_000.0, 1_000_000.0])
def test_decode_capture_of_an_export_is_the_same_both_ways(tmp_path, monkeypatch, slow, rate):
    path = tmp_path / "run.sr"
    export_events(busy_run(slow), str(path), "sr", sample_rate=rate, tool_channel=True)
    for tx in (None, "TOOL_TX"):
        for invert in (None, False):
            a, b = both_ways(monkeypatch, path, tx_channel=tx, invert=invert)
            same_decode(a, b)
    assert a.chars == 60 * 17


@pytest.mark.parametrize(
    ("name", "baud", "framing"),
    [
        ("hello_world_8n1_1200.sr", 1200, "8N1"),
        ("hello_world_8n1_9600.sr", 9600, "8N1"),
        ("hello_world_7e1_115200.sr", 115200, "7E1"),
        ("hello_world_7o1_115200.sr", 115200, "7O1"),
    ],
)
def test_shared_captures_decode_the_same_both_ways(monkeypatch, name, baud, framing):
    path = SHARED / "captures" / name
    if not path.exists():
        pytest.skip(f"shared capture {path} is not there")
    for invert in (None, True):
        kw = dict(baud=baud, framing=framing, invert=invert, force=True)
        same_decode(*both_ways(monkeypatch, path, **kw))


@pytest.mark.slow
@pytest.mark.parametrize("fault", ["fast-baud", "inter-char-gap", "binary-invalid-type"])
def test_a_fault_runs_capture_decodes_the_same_both_ways(
    tmp_path, tmp_path_factory, monkeypatch, fault
):
    """A fault run's capture as ``judge`` decodes it (the tool's TX on a second channel):
    a sender at 1300 baud (every reply character read by the scan's own code), gaps
    between characters, 8N1 binary bytes among 7E1 frames."""
    from conformance.replay.recording import read_recording

    # the main command's run of the fault, made once a session (inter-char-gap and fast-baud
    # are judged passively in tests/commands/test_passive.py too: tests/support/shared_runs.py)
    copied_run(tmp_path_factory, tmp_path / "live", f"sim://?faults={fault}")
    events = read_recording(tmp_path / "live").events
    path = tmp_path / "run.sr"
    export_events(events, str(path), "sr", tool_channel=True)
    a, b = both_ways(monkeypatch, path, tx_channel="TOOL_TX")
    same_decode(a, b)
    assert a.chars > 10_000
