"""The recorder's wire rules (``testcases/passive/test_recorder_7_wire.py``'s judges) over a
whole view and over a recording's windows, each window's view read from its own events
alone: ``tests/judges/recorder/test_windowed_wire.py`` and ``benchmarks/capture_windows.py``
compare the two (issue 22's windowed judge)."""

from __future__ import annotations

from collections.abc import Iterable

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
from conformance.transcript import Event
from conformance.verdicts import Finding
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
