"""A capture decoded into columns (issue 22, the thirteenth matrix round): with ``columns=True``
the decoder keeps each certified character's start, end, byte and side instead of making its
event, and :meth:`WireColumns.events` makes exactly the events the decoder would have made
(the replay of a fault-matrix row reads the columns; a user's ``judge`` the events).
"""

from __future__ import annotations

import pytest

from conformance.capture import decode as decode_module
from conformance.capture import decode_capture
from conformance.capture.columns import WireColumns
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.transcript import DUT, TOOL, Event, EventKind, plain_fields
from tests.support.capture_digest import traffic


def fields(e: Event) -> tuple:
    """Every field of ``e`` with its type (an int where a float was would read apart)."""
    values = (e.kind, e.origin, e.start, e.end, e.wire, e.text, e.uncertainty)
    return (*values, e.duration_uncertainty, tuple(map(type, values)))


@pytest.mark.parametrize("seed", [5, 11])
def test_the_columns_make_the_decoders_events(tmp_path, seed):
    """A hostile bus (glitches, parity errors, short breaks, off-rate senders) with its TX
    channel: the same events, field for field and type for type, the same counters and
    notes, and the events the decoder made itself kept whole."""
    path = tmp_path / "run.sr"
    export_events(traffic(seed, seconds=20.0), str(path), "sr", tool_channel=True)
    made = decode_capture(str(path), tx_channel=TOOL_CHANNEL, keep=False)
    cols = decode_capture(str(path), tx_channel=TOOL_CHANNEL, columns=True)
    assert cols.events == [] and cols.columns is not None and made.columns is None
    assert len(made.events) > 1000 and cols.columns.made
    assert list(map(fields, cols.columns.events())) == list(map(fields, made.events))
    assert cols.event_list() == made.events == made.event_list()
    assert cols.columns.kinds() == [e.kind for e in made.events]
    assert cols.columns.uncertainties() == [e.uncertainty for e in made.events]
    assert cols.columns.plain() == all(map(plain_fields, made.events))
    assert cols.columns.in_start_order() == all(
        a.start <= b.start for a, b in zip(made.events, made.events[1:], strict=False)
    )
    same = ("chars", "breaks", "pulses", "glitches", "framing_errors", "parity_errors", "notes")
    assert [getattr(cols, k) for k in same] == [getattr(made, k) for k in same]
    assert cols.problems == made.problems and cols.tx_channel == made.tx_channel


def test_a_columns_decode_is_not_kept_nor_taken_from_the_kept_one(tmp_path):
    path = tmp_path / "run.sr"
    export_events(traffic(3, seconds=4.0), str(path), "sr", tool_channel=True)
    kept = decode_capture(str(path), tx_channel=TOOL_CHANNEL)
    before = decode_module._LAST
    cols = decode_capture(str(path), tx_channel=TOOL_CHANNEL, columns=True)
    assert decode_module._LAST is before and cols.columns is not None
    assert cols.columns.events() == kept.events


def test_widened_stamps_give_the_events_made_and_widened(tmp_path, monkeypatch):
    """A glitch beside a kept edge widens every stamp: the columns are made into events
    then (as before), never kept with the unwidened uncertainty."""
    path = tmp_path / "run.sr"
    export_events(traffic(5, seconds=3.0), str(path), "sr", tool_channel=True)
    filtered = decode_module._filtered

    def beside(out, glitch, width):
        glitch.beside_edges = max(glitch.beside_edges, 1)
        filtered(out, glitch, width)

    monkeypatch.setattr(decode_module, "_filtered", beside)
    made = decode_capture(str(path), tx_channel=TOOL_CHANNEL, keep=False)
    cols = decode_capture(str(path), tx_channel=TOOL_CHANNEL, columns=True)
    assert cols.columns is None and cols.events == made.events
    assert made.events[0].uncertainty > made.uncertainty_s - made.glitch_filter_s


def test_columns_plain_and_order_checks():
    cols = WireColumns(1e-6)
    cols.start += [0.0, 1.0]
    cols.end += [0.5, 1.5]
    cols.wire += [0x30, 0x31]
    cols.origin += [TOOL, DUT]
    assert cols.plain() and cols.in_start_order()
    cols.add_made(Event(EventKind.BREAK, TOOL, 0.9, 1.0))
    assert not cols.in_start_order() and cols.kinds()[2] is EventKind.BREAK
    cols.start[0] = 0  # an int stamp reads back as a float: not plain
    assert not cols.plain()


@pytest.mark.parametrize(
    "starts",
    [[], [1.0], [0.0, 0.0, 1.0], [0.0, 2.0, 1.0], [0.0, float("nan"), 1.0], [float("nan")],
     [-0.0, 0.0, 0.0], [3.0, 2.0], [0.0, 1.0, float("inf")]],
)  # fmt: skip
def test_start_order_is_each_start_at_most_the_next(starts):
    """``in_start_order`` compares in C what a pairwise ``<=`` compares (NaN in no order)."""
    cols = WireColumns(0.0, start=list(starts))
    assert cols.in_start_order() == all(a <= b for a, b in zip(starts, starts[1:], strict=False))
