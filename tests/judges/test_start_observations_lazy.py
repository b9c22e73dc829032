"""R-7.0-09/-10's observations with their evidence line made when asked (issue 22, matrix23):
``wire._start_observations`` hands each reply's :class:`~conformance.judges.timing.Measured`
a :class:`~conformance.judges.wire._StartWhere` instead of the line itself, and asks a
segment with nothing that met its command, or no sensor break, no more about them; a PASS
reckons its margin without ``_margin_ms``'s loop (``timing._margin_inside_ms``). Each must
give what the old path gave (kept here as ``_old_start_observations``): the same
observations in the same order, the same figures, verdicts, places and taint, and, once
asked, the same finding, evidence line and all, over drawn segments that hold what each
branch reads (an unanswered command before, a reply beginning with another address, a
contention before and after the command's end, a sensor break before the reply) beside
plain ones, on exact and on uncertain stamps."""

from __future__ import annotations

import math
import random
from dataclasses import asdict

import pytest

from conformance.judges import timing, wire
from conformance.judges.timing import Measured, StampUncertainty
from conformance.judges.wire import EARLY_WINDOW, LATE_WINDOW
from conformance.transcript import DUT, TOOL, Event, EventKind, escape
from conformance.view.runs import Segment, Segments
from tests.support.hand_events import chars


def _old_start_observations(segs, stamps, before=None):
    """``_start_observations`` as it was before matrix23 (the line made for every reply),
    with truth36's :func:`wire._carried` (a reply naming another address than its command's,
    after an unanswered command, leaves its command unanswered for the next)."""
    early, late = [], []
    for seg in segs:
        earlier = wire._unanswered_before(before, seg)
        before = wire._carried(earlier, seg)
        if not seg.reply or wire._reply_set_aside(seg) or wire._not_a_reply_to(seg):
            continue
        delay = seg.reply[0].start - seg.command_end
        u = stamps.between(seg.command[-1].start, seg.reply[0].end)
        tainted = u > stamps.base
        where = [f"reply to {escape(seg.text)} at t={seg.command_end:.4f} s"]
        place = (seg.text, wire._text(seg), 0)
        if earlier is not None:
            lagged = seg.reply[0].start - earlier.command_end
            where = [
                f"{where[0]} (or to {escape(earlier.text)} before it, "
                f"{lagged * 1e3:.2f} ms after that one)"
            ]
        spacing = wire._spacing_before_reply(seg)
        for window, out in ((EARLY_WINDOW, early), (LATE_WINDOW, late)):
            measured, said = delay, where
            if window is EARLY_WINDOW and spacing is not None:
                measured = max(spacing.start, seg.command_end) - seg.command_end
                said = [
                    f"{where[0]}: the sensor held the line spacing from {measured * 1e3:.2f} ms "
                    f"after the command, {spacing.duration * 1e3:.2f} ms (a break), before "
                    f"its reply at {delay * 1e3:.2f} ms"
                ]
            if earlier is not None:
                other = measured + seg.command_end - earlier.command_end
                if window.inside(measured) != window.inside(other):
                    continue
            out.append((Measured(window, measured, u, said), tainted, place))
    return early, late, before


def _segments(n: int, rng: random.Random) -> list[Segment]:
    """Drawn segments: the command's reply after a delay around both windows' edges, now
    and then none (the next may be its late reply), another address first, a contention,
    a sensor break."""
    segs, t = [], 0.0
    for k in range(n):
        text = rng.choice(["0!", "0M!", "0D0!", "1I!", "?!", "0A1!"])
        command = chars(TOOL, text, t)
        end = command[-1].end
        delay = rng.choice([0.0, 0.5e-3, 7.9e-3, 8.33e-3, 12e-3, 15.4e-3, 15.6e-3, 0.09])
        delay += rng.uniform(-0.3e-3, 0.3e-3)
        first = rng.choice(["0", "0", "0", "1", "5"])
        reply = [] if rng.random() < 0.2 else chars(DUT, first + "+1\r\n", end + delay)
        later = chars(DUT, "0\r\n", end + 0.4) if rng.random() < 0.1 else []
        contention = []
        if rng.random() < 0.15:
            contention = chars(DUT, "x", end + rng.uniform(-0.02, 0.005))
        breaks: tuple[Event, ...] = ()
        if rng.random() < 0.15:
            start = end + rng.uniform(-0.002, 0.01)
            breaks = (Event(EventKind.BREAK, DUT, start, start + rng.uniform(0.001, 0.015)),)
        segs.append(
            Segment(
                None,
                command,
                reply,
                later=later,
                contention=contention,
                text=text,
                sensor_breaks=breaks,
            )
        )
        t = end + 0.3
        if k % 7 == 0:
            t += rng.uniform(0, 1e-4)
    return segs


def _figures(observation) -> tuple:
    m, tainted, place = observation
    return (
        m.requirement,
        m.measured,
        m.uncertainty,
        m.verdict,
        m.margin_ms,
        m.measured_ms,
        tainted,
        place,
    )


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize(
    "stamps",
    [
        StampUncertainty(0.0),
        StampUncertainty(0.4e-3),
        StampUncertainty(0.1e-3, lambda a, b: 0.2e-3 if int(a) % 2 else 0.0),
    ],
)
def test_lazy_evidence_observes_as_the_eager_path(seed, stamps) -> None:
    segs = _segments(200, random.Random(seed))
    new = wire._start_observations(segs, stamps)
    old = _old_start_observations(segs, stamps)
    assert new[2] is old[2]
    for kept, was in zip(new[:2], old[:2], strict=True):
        assert [_figures(o) for o in kept] == [_figures(o) for o in was]
        # the findings, evidence lines and all, once asked (a PASS's only when shown)
        assert [asdict(o[0].finding) for o in kept] == [asdict(o[0].finding) for o in was]
    shown = [o for half in new[:2] for o in half]
    assert any("(or to" in o[0].finding.evidence[0] for o in shown)  # an earlier command
    assert any("line spacing" in o[0].finding.evidence[0] for o in shown)  # a sensor break


def test_the_evidence_line_is_made_once_and_only_when_asked() -> None:
    """A PASS's line is not made until its finding is; then it is the same list each time."""
    segs = _segments(60, random.Random(7))
    early, late, _ = wire._start_observations(segs, StampUncertainty(0.0))
    passing = [o[0] for o in late if o[0].verdict.name == "PASS"]
    assert passing
    where = passing[0].evidence_lines
    assert isinstance(where, wire._StartWhere) and where.lines is None
    line = passing[0].finding.evidence
    assert where.lines == line and where() is where()


def test_the_pass_margin_is_margin_ms_inside() -> None:
    rng = random.Random(3)
    edges = [None, 0.0, -0.0, 7.93e-3, 8.33e-3, 15.0e-3, 1.66e-3, math.inf]
    for _ in range(20_000):
        lo, hi = rng.choice(edges), rng.choice(edges)
        measured = rng.choice([rng.uniform(-0.02, 0.03), 0.0, -0.0, 8.33e-3, 15.0e-3])
        assert timing._margin_inside_ms(lo, hi, measured) == timing._margin_ms(
            lo, hi, measured, False
        )


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize(
    "stamps",
    [StampUncertainty(0.0), StampUncertainty(0.1e-3, lambda a, b: 0.3e-3 if a > 5 else 0.0)],
)
def test_the_shared_texts_judge_as_a_plain_list(seed, stamps) -> None:
    """R-7.0-09/-10 and R-7.0-12/-01 over a run's Segments (each reply's text made once,
    ``wire._texts``; the gaps judged in one part, the Segments themselves) find what the
    same segments as a plain list find (each text made as it goes, the gaps 64 segments at
    a time)."""
    segs = _segments(150, random.Random(seed))
    shared = Segments(segs)
    for judge in (wire.judge_response_start, wire.judge_gaps):
        assert [asdict(f) for f in judge(shared, stamps)] == [
            asdict(f) for f in judge(list(segs), stamps)
        ]
    assert wire.starts_to_confirm(shared, stamps) == wire.starts_to_confirm(list(segs), stamps)
    assert wire.gaps_to_confirm(shared, stamps) == wire.gaps_to_confirm(list(segs), stamps)


def test_a_reply_text_is_made_once_for_both_rules(monkeypatch) -> None:
    """The case's order (starts, then gaps) over one Segments makes each text once."""
    made = []
    inner = wire._text

    def counted(seg):
        made.append(seg)
        return inner(seg)

    monkeypatch.setattr(wire, "_text", counted)
    segs = Segments(_segments(100, random.Random(2)))
    wire.starts_after_a_retry(segs, StampUncertainty(0.0))
    wire.judge_response_start(segs, StampUncertainty(0.0))
    wire.judge_gaps(segs, StampUncertainty(0.0))
    sent = [s for s in segs if s.reply or s.later]
    assert len(made) == len(sent) == len({id(s) for s in made})
