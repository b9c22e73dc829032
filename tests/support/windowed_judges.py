"""The recorder's wire rules (``testcases/passive/test_recorder_7_wire.py``'s judges) and
each sensor's decode-quality note over a whole recording and over its windows, each window's
view read from its own events alone: ``tests/judges/recorder/test_windowed_wire.py``,
``tests/offline/test_decode_quality_windowed.py`` and ``benchmarks/capture_windows.py``
compare the two (issue 22's windowed judge)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from conformance.judges.recorder.breaks import (
    BreakRules,
    Breaks,
    judge_break_rules,
    judge_breaks,
)
from conformance.judges.recorder.commands import (
    CharacterGaps,
    CommandBitRate,
    CommandText,
    judge_character_gaps,
    judge_command_bit_rate,
    judge_command_text,
)
from conformance.offline.decode_quality import (
    CharRates,
    Quality,
    decode_quality,
    problems_by_character,
    rate_of,
    sensor_characters,
)
from conformance.transcript import Event, EventKind
from conformance.verdicts import Finding
from conformance.view.rebuilt_records import rebuild_records, rebuilt_exchanges
from conformance.view.segments import TranscriptView, read_view


def recorder_wire(view: TranscriptView, uncertainty: float) -> list[Finding]:
    """The whole view's findings, as the passive recorder cases make them."""
    return [
        *judge_breaks(view, uncertainty),
        *judge_break_rules(view, uncertainty),
        *judge_command_text(view),
        *judge_character_gaps(view, uncertainty),
        judge_command_bit_rate(view, uncertainty),
    ]


def recorder_wire_windowed(windows: Iterable[list[Event]], uncertainty: float) -> list[Finding]:
    """The same findings from ``windows`` (in order), each read alone and let go."""
    breaks, rules = Breaks(uncertainty), BreakRules(uncertainty)
    text, gaps, rate = CommandText(), CharacterGaps(uncertainty), CommandBitRate(uncertainty)
    for window in windows:
        view = read_view(window)
        for judge in (breaks, rules, text, gaps, rate):
            judge.add(view)
    return [
        *breaks.findings(),
        *rules.findings(),
        *text.findings(),
        *gaps.findings(),
        rate.finding(),
    ]


def qualities(decoded: Any, events: list[Event], uncertainty: float) -> dict[str, str | None]:
    """Each sensor's decode-quality note from the whole recording, as
    ``offline.heard._qualities`` makes them (by the first character of each exchange)."""
    rates = rate_of(decoded, events)
    found: dict[str, list[Event]] = {}
    for x in rebuilt_exchanges(read_view(events), uncertainty=uncertainty):
        found.setdefault(x.text[:1], []).extend(sensor_characters([x]))
    return {
        a: decode_quality(decoded, events, chars, f"sensor {a!r}", rates=rates)
        for a, chars in found.items()
    }


def qualities_windowed(
    decoded: Any, windows: Iterable[list[Event]], uncertainty: float
) -> dict[str, str | None]:
    """The same notes from ``windows`` (in order, together the decode's events): each
    window's records rebuilt alone (the CRC expectations carried), its characters' bit-rate
    errors its share of the decode's, in order, and each sensor's figures gathered in a
    :class:`~conformance.offline.decode_quality.Quality`."""
    broken = problems_by_character(decoded)
    found: dict[str, Quality] = {}
    carried: dict[str, bool] = {}
    taken = 0  # the decode's characters in the windows before
    for window in windows:
        count = sum(1 for e in window if e.kind is EventKind.CHAR)
        rates = CharRates.of_rates(decoded.baud_error_pct[taken : taken + count], window)
        taken += count
        view = read_view(window)
        for x in rebuild_records(view, uncertainty=uncertainty, carried=carried).exchanges:
            found.setdefault(x.text[:1], Quality()).add(sensor_characters([x]), rates, broken)
    return {a: q.note(decoded.baud, f"sensor {a!r}") for a, q in found.items()}
