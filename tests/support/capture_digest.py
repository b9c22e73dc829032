"""Digests of what the capture path produces, to pin it bit for bit (issue 22's speed-up).

``traffic`` builds a seeded, deliberately awkward transcript (busy exchanges, senders off the
nominal bit rate, contention, spacing pulses, short breaks that decode as glitches, 8-bit
values that fail 7E1 parity, back-to-back frames, a 300 baud sender); ``samples_digest`` hashes
the samples of an exported .sr, ``decode_digest`` everything a :class:`CaptureDecode` holds
(events, counters, diagnostics, notes), floats by ``repr`` so no bit can move unseen. The
golden values in ``data/capture_golden.json`` were computed with the code before the speed-up.
"""

from __future__ import annotations

import hashlib
import json
import random
import zipfile
from pathlib import Path

from conformance.capture import CaptureDecode
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from tests.support.paths import TESTS

GOLDEN = TESTS / "data" / "capture_golden.json"


def traffic(seed: int, seconds: float = 20.0) -> list[Event]:
    """A transcript of ``seconds`` of a hostile bus, the same for the same ``seed``."""
    rng = random.Random(seed)
    events: list[Event] = []
    t = 0.05
    while t < seconds:
        events.append(Event(EventKind.BREAK, TOOL, t, t + rng.uniform(0.012, 0.014)))
        t = events[-1].end + rng.uniform(0.0082, 0.012)
        for origin, text in ((TOOL, "0D0!"), (DUT, "0+1.23-45.6+7.891\r\n")):
            baud = 1200 * rng.choice((1.0, 1.0, 1.0, 0.97, 1.03, 0.94, 1.06))
            char = 10 / baud
            for c in text:
                wire = to_wire_7e1(ord(c)) if rng.random() > 0.03 else rng.randrange(256)
                events.append(Event(EventKind.CHAR, origin, t, t + char, wire=wire))
                t += char + rng.choice((0.0, 0.0, rng.uniform(0, 0.002)))
            t += rng.uniform(0.0087, 0.015)
        roll = rng.random()
        if roll < 0.15:  # contention: a sensor talking over the recorder
            for k in range(3):
                events.append(
                    Event(EventKind.CHAR, DUT, t + k * 0.0083, t + (k + 1) * 0.0083, wire=0x55)
                )
                events.append(
                    Event(
                        EventKind.CHAR,
                        TOOL,
                        t + 0.003 + k * 0.0083,
                        t + 0.003 + (k + 1) * 0.0083,
                        wire=to_wire_7e1(ord("?")),
                    )
                )
            t += 0.04
        elif roll < 0.25:  # a spacing pulse (6.5-12 ms) and a short break: a glitch
            events.append(Event(EventKind.BREAK, DUT, t, t + rng.uniform(0.0066, 0.0118)))
            events.append(Event(EventKind.BREAK, DUT, t + 0.02, t + 0.02 + 0.0002))
            t += 0.04
        elif roll < 0.3:  # a slow sender and a frame of mostly spacing (0xC0)
            for wire in (0xC0, 0x7F, 0x00):
                events.append(Event(EventKind.CHAR, DUT, t, t + 10 / 300, wire=wire))
                t += 10 / 300
            t += 0.02
        events.sort(key=lambda e: e.start)
        t += rng.uniform(0.0, 0.03)
    return events


def _f(x: float | None) -> str:
    return repr(x)


def _event(e: Event | None) -> list | None:
    if e is None:
        return None
    return [
        str(e.kind), e.origin, _f(e.start), _f(e.end), e.wire, e.text,
        _f(e.uncertainty), _f(e.duration_uncertainty),
    ]  # fmt: skip


def decode_digest(d: CaptureDecode) -> str:
    """Everything ``d`` says, hashed."""
    body = {
        "events": [_event(e) for e in d.events],
        "problems": [
            [
                p.kind,
                _event(p.event),
                _f(p.start),
                _f(p.end),
                p.framing_error,
                p.parity_error,
                _f(p.baud_error_pct),
                p.glitches,
                _f(p.marking_before),
            ]
            for p in d.problems
        ],  # fmt: skip
        "baud": [_f(x) for x in d.baud_error_pct],
        "counts": [d.chars, d.framing_errors, d.parity_errors, d.glitches, d.breaks, d.pulses],
        "meta": [
            d.format,
            _f(d.uncertainty_s),
            d.inverted,
            d.polarity_detected,
            _f(d.sample_rate),
            d.channel,
            d.channels,
            d.tx_channel,
            d.notes,
        ],  # fmt: skip
    }
    return hashlib.sha256(json.dumps(body).encode()).hexdigest()


def samples_digest(path: Path) -> str:
    """The samples and metadata of a .sr (not the zip's own bytes: dates, compression)."""
    h = hashlib.sha256()
    with zipfile.ZipFile(path) as zf:
        for name in sorted(zf.namelist()):
            h.update(name.encode() + b"\0" + zf.read(name) + b"\0")
    return h.hexdigest()


def text_digest(path: Path) -> str:
    """A VCD or CSV export, but for the line holding the date it was written."""
    lines = path.read_text().splitlines(keepends=True)
    kept = "".join(x for x in lines if not x.startswith("$date"))
    return hashlib.sha256(kept.encode()).hexdigest()


def golden() -> dict[str, str]:
    return json.loads(GOLDEN.read_text())
