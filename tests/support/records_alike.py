"""Records and views as comparable fields: what the windowed and per-sensor rebuilds must
give exactly as the whole recording does (tests/view, benchmarks/capture_windows.py).
Events compare by identity of content; everything a judge reads of an exchange's attempts
and a measurement's data is in the tuples."""

from __future__ import annotations

from typing import Any

from conformance.tool_recorder.records import Exchange, Measurement
from conformance.view.rebuilt_records import Rebuilt
from conformance.view.segments import TranscriptView, Transmission


def exchange_fields(x: Exchange) -> tuple[Any, ...]:
    """An exchange with each attempt's break, command, reply, reason, end and retry."""
    return (
        x.text,
        x.command,
        x.binary,
        [
            (a.break_event, a.command_events, a.reply_events, a.reason, a.end, a.sequence)
            + (a.retry, a.stray_events)
            for a in x.attempts
        ],
    )


def measurement_fields(m: Measurement) -> tuple[Any, ...]:
    """A measurement with its start, announcement, service request, data and values."""
    return (
        exchange_fields(m.start),
        m.ttt,
        m.count,
        m.reply_end,
        m.service_request_end,
        m.waited_events,
        [exchange_fields(d) for d in m.data],
        m.values,
        m.packets,
        m.binary_value_count,
    )


def records_fields(rebuilt: list[Rebuilt]) -> tuple[list[Any], list[Any]]:
    """Every exchange and measurement of ``rebuilt``, field by field, in order."""
    return (
        [exchange_fields(x) for r in rebuilt for x in r.exchanges],
        [measurement_fields(m) for r in rebuilt for m in r.measurements],
    )


def _transmission_fields(t: Transmission) -> tuple[Any, ...]:
    return (t.break_event, t.chars, t.heard, t.cut, t.cut_by, t.text)


def view_differences(whole: TranscriptView, parts: list[TranscriptView]) -> list[str]:
    """What of ``parts`` (each read alone, in order) is not ``whole``: empty when nothing."""
    wrong = []
    mine = [_transmission_fields(t) for p in parts for t in p.transmissions]
    if mine != [_transmission_fields(t) for t in whole.transmissions]:
        wrong.append("transmissions")
    for name in ("breaks", "chars", "unanswerable", "undirected"):
        if [e for p in parts for e in getattr(p, name)] != getattr(whole, name):
            wrong.append(name)
    return wrong
