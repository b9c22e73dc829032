"""The recorder's wire rules (``testcases/passive/test_recorder_7_wire.py``'s judges) and
measurement, retry and address rules (``test_recorder_4_4_measurement.py``'s), each
sensor's reply timing and framing (``test_sensor_7_wire.py``'s response start, character
gaps, bit rate and framing) and
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
from conformance.judges.recorder.capabilities import Addresses, judge_addresses
from conformance.judges.recorder.collection import judge_data_collection, judge_high_volume
from conformance.judges.recorder.commands import (
    CharacterGaps,
    CommandBitRate,
    CommandText,
    judge_character_gaps,
    judge_command_bit_rate,
    judge_command_text,
)
from conformance.judges.recorder.measurements import (
    ObservedMeasurement,
    ObservedMeasurements,
    observed_measurements,
)
from conformance.judges.recorder.retries import Retries, judge_retries
from conformance.judges.recorder.waits import judge_concurrent_waits, judge_measure_waits
from conformance.judges.wire import (
    Framing,
    ReplyBitRate,
    ReplyGaps,
    ResponseStarts,
    judge_framing,
    judge_gaps,
    judge_reply_bit_rate,
    judge_response_start,
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
from conformance.view.runs import Segment
from conformance.view.segments import TranscriptView, read_view
from conformance.view.windows import stream_windows, window_events, window_starts


def at_every_break(events: list[Event]) -> list[list[Event]]:
    """``events`` cut before every break: finer than any cut :func:`window_starts` makes
    (which never cuts inside a measurement, nor between two transmissions of one command),
    so what one window leaves the next shows."""
    windows: list[list[Event]] = []
    for e in sorted(events, key=lambda e: e.start):
        if e.kind is EventKind.BREAK or not windows:
            windows.append([])
        windows[-1].append(e)
    return windows


def product_cuts(events: list[Event], uncertainty: float) -> list[list[list[Event]]]:
    """The windows the product cuts ``events`` into: :func:`window_starts`' cut of the whole
    view, and :func:`stream_windows` as the events come."""
    view = read_view(events)
    ordered = sorted(events, key=lambda e: e.start)
    return [
        list(window_events(events, view, window_starts(view))),
        list(stream_windows(iter(ordered), uncertainty=uncertainty)),
    ]


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


def recorder_measurements(view: TranscriptView, uncertainty: float) -> list[Finding]:
    """The whole view's findings of ``testcases/passive/test_recorder_4_4_measurement.py``'s
    judges: the measurements' waits, concurrent waits, data collection and high-volume
    data (over :func:`observed_measurements`), the retries and the addresses polled."""
    taken = observed_measurements(view, uncertainty)
    return [
        *_over_measurements(taken, uncertainty),
        *judge_retries(view, uncertainty),
        *judge_addresses(view, uncertainty),
    ]


def recorder_measurements_windowed(
    windows: Iterable[list[Event]], uncertainty: float
) -> list[Finding]:
    """The same findings from ``windows`` (in order), each window's view read alone and
    let go: :class:`ObservedMeasurements`, :class:`Retries` and :class:`Addresses`."""
    taken = ObservedMeasurements(uncertainty)
    retries, addresses = Retries(uncertainty), Addresses(uncertainty)
    for window in windows:
        view = read_view(window)
        for judge in (taken, retries, addresses):
            judge.add(view)
    return [
        *_over_measurements(taken.measurements(), uncertainty),
        *retries.findings(),
        *addresses.findings(),
    ]


def _over_measurements(taken: list[ObservedMeasurement], uncertainty: float) -> list[Finding]:
    return [
        *judge_measure_waits(taken, uncertainty),
        *judge_concurrent_waits(taken, uncertainty),
        *judge_data_collection(taken),
        *judge_high_volume(taken, True),
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


def _sensor_segments(view: TranscriptView) -> dict[str, list[Segment]]:
    """The view's segments by the sensor each transmission is to (its first character)."""
    found: dict[str, list[Segment]] = {}
    for t in view.transmissions:
        found.setdefault(t.text[:1], []).append(Segment.of(t))
    return found


def sensor_timing(view: TranscriptView, uncertainty: float) -> dict[str, list[Finding]]:
    """Each sensor's reply timing and framing findings (R-7.0-09/-10, R-7.0-12, R-7.0-01,
    R-4.1-01, R-4.1-02, R-4.2-02/-03, R-4.3-01) from the whole view, as its passive run
    judges its own segments."""
    return {
        a: [
            *judge_response_start(segs, uncertainty),
            *judge_gaps(segs, uncertainty),
            judge_reply_bit_rate(segs, uncertainty),
            *judge_framing(segs, uncertainty),
        ]
        for a, segs in _sensor_segments(view).items()
    }


def sensor_timing_windowed(
    windows: Iterable[list[Event]], uncertainty: float
) -> dict[str, list[Finding]]:
    """The same findings from ``windows`` (in order), each window's view read alone and
    let go: each sensor's segments of the window added to its own judges."""
    judges: dict[str, tuple[ResponseStarts, ReplyGaps, ReplyBitRate, Framing]] = {}
    for window in windows:
        for a, segs in _sensor_segments(read_view(window)).items():
            folds = judges.setdefault(
                a,
                (
                    ResponseStarts(uncertainty),
                    ReplyGaps(uncertainty),
                    ReplyBitRate(uncertainty),
                    Framing(uncertainty),
                ),
            )
            for fold in folds:
                fold.add(segs)
    return {
        a: [*s.findings(), *g.findings(), r.finding(), *f.findings()]
        for a, (s, g, r, f) in judges.items()
    }
