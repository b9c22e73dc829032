"""A sensor pass's exchanges held as rows (issue 22, memory23: ``offline.held_exchanges``):
each made again must equal, field for field, the exchange the pass made (today's objects:
the same pass over the recording's events held as a list, where nothing is a row), its
reply text, timing and judged try the same; a measurement's own exchanges and any the rows
cannot say stay the objects; reading by kind makes no other; and a busy bus's exchanges
hold a few tens of bytes each, not the ~1.3 KB each an object took (memory21)."""

from __future__ import annotations

import gc
import tracemalloc
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.event_store import CompactEvents
from conformance.links.host_stall import Stall
from conformance.offline.held_exchanges import HeldExchanges
from conformance.offline.sensor_windows import bus_windows, sensor_records
from conformance.offline.stored_records import Positions, store_records
from conformance.protocol.commands import Kind, parse_command
from conformance.replay.recording import write_recording
from conformance.replay.recording_link import load_recording, parse_recording, recording_port
from conformance.tool_recorder.records import OK, Attempt, Exchange
from conformance.transcript import BUS, DUT, TOOL, Event, EventKind, Transcript
from tests.support.bus_of_sensors import record
from tests.support.paths import benchmark

#: bytes an exchange of one try may hold as a row (36, the arrays' room to grow besides)
ROW_BYTES = 100


def _load(path: Path, kind: str, *, listed: bool = False):
    link = load_recording(parse_recording(recording_port(str(path), kind)))
    if listed:  # today's records: a list of events holds no position, every record an object
        link.transcript = Transcript(list(link.transcript.events))
    return link


def _plain(x: Exchange) -> tuple:
    """What the cases read of an exchange, as plain values."""
    tries = [
        (a.reply_text, a.start, a.end, a.command_end, a.ok, list(a.reply_events), a.stall)
        for a in x.attempts
    ]
    judged = next(i for i, a in enumerate(x.attempts) if a is x.judged)
    return (x.reply_text, x.reply_bytes, x.answered, x.ok, x.start, x.end, judged, tries)


def _same_records(path: Path, kind: str, addresses: list[str | None]) -> int:
    """The pass over a compact load and over a listed one (today's objects) for each address:
    equal exchanges; the rows made of the first. How many exchanges were rows."""
    new_link, old_link = _load(path, kind), _load(path, kind, listed=True)
    rows = 0
    for address in addresses:
        new = sensor_records(new_link, bus_windows(new_link), address)
        old = sensor_records(old_link, bus_windows(old_link), address)
        held = new.exchanges
        assert isinstance(held, HeldExchanges) and isinstance(old.exchanges, HeldExchanges)
        assert len(old.exchanges.kept) == len(old.exchanges) and not old.exchanges.end  # no row
        assert list(held) == list(old.exchanges) and len(held) == len(old.exchanges)
        assert [_plain(x) for x in held] == [_plain(x) for x in old.exchanges]
        for m in new.measurements:  # a measurement's exchanges are the very ones listed
            for x in (m.start, *m.data):
                assert any(y is x for y in held)
        for kinds in ({Kind.IDENTIFY}, {Kind.DATA, Kind.CONCURRENT}, set(Kind)):
            assert held.of_kinds(kinds) == [
                x for x in old.exchanges if x.command is not None and x.command.kind in kinds
            ]
        rows += len(held) - len(held.kept)
    return rows


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"code": "M"},
        {"code": "HB"},
        {"meddle": {"1": "3I!"}},
        {"faults": {"0": ["crc-missing"], "3": ["response-too-late"]}},
        {"faults": {"1": ["no-service-request"]}, "code": "M"},
        {"faults": {"0": ["values-over-35"], "1": ["wrong-crc"]}, "code": "CC"},
    ],
    ids=str,
)
def test_bus_recordings_rows_make_the_pass_exchanges(tmp_path: Path, kwargs: dict):
    path = record(tmp_path / "bus", **kwargs)
    assert _same_records(path, "jsonl", [None, "0", "1", "3", "x"]) > 0


def _busy(path: Path, seconds: float) -> Path:
    write_recording(path, Transcript(benchmark("capture_decode").busy_bus(seconds)))
    return path


def test_busy_bus_rows_make_the_pass_exchanges(tmp_path: Path):
    path = _busy(tmp_path / "busy.jsonl", 20)
    assert _same_records(path, "jsonl", [None, "0", "7"]) > 90


def test_busy_bus_exchanges_hold_a_row_each(tmp_path: Path):
    """Every sensor's exchanges of three busy minutes together (~750): what letting go of
    them frees is under :data:`ROW_BYTES` an exchange (base-s68 held ~1.3 KB each)."""
    link = _load(_busy(tmp_path / "busy.jsonl", 180), "jsonl")
    bus = bus_windows(link)
    gc.collect()
    tracemalloc.start()
    try:
        records = sensor_records(link, bus, None)
        count = len(records.exchanges)
        gc.collect()
        held = tracemalloc.get_traced_memory()[0]
        records.exchanges = []
        gc.collect()
        freed = held - tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert count > 700
    assert freed / count < ROW_BYTES, f"{freed / count:.0f} bytes an exchange"


# -- hand-built exchanges over a store ------------------------------------------------------

CHARS = 400
EVENTS = [
    Event(EventKind.BREAK if i % 40 == 0 else EventKind.CHAR, (TOOL, DUT, BUS)[i % 3],
          0.01 * i, 0.01 * i + 0.008, 0x30 + i % 10)
    for i in range(CHARS)
]  # fmt: skip
STORE = CompactEvents.of(EVENTS)
TEXTS = ["0I!", "0!", "1D0!", "0XAB!", "?!", "0M!", "junk"]
REASONS = [OK, "no reply", "idle", "invalid: bus contention (1 characters during the command)"]
_run = st.tuples(st.integers(0, CHARS - 30), st.integers(0, 25))
_attempt = st.fixed_dictionaries(
    {
        "brk": st.none() | st.integers(0, CHARS - 1),
        "cmd": _run,
        "rep": _run,
        "scattered": st.booleans(),
        "reason": st.sampled_from(REASONS),
        "end": st.floats(allow_nan=False, allow_infinity=False, width=64),
        "sequence": st.integers(0, 300),
        "retry": st.integers(0, 3),
        "stray": st.integers(0, 2),
        "stall": st.booleans(),
    }
)
_exchange = st.fixed_dictionaries(
    {
        "text": st.sampled_from(TEXTS),
        "attempts": st.lists(_attempt, min_size=1, max_size=3),
        "binary": st.booleans(),
        "late": st.integers(0, 2),
        "measured": st.booleans(),
    }
)


def _command(text: str):
    try:
        return parse_command(text)
    except ValueError:
        return None


def _made(spec: dict, window: list[Event]) -> Exchange:
    """An exchange of ``spec`` whose events are ``window``'s objects (as a pass made it)."""
    attempts = []
    for a in spec["attempts"]:
        lo, n = a["rep"]
        reply = window[lo : lo + n]
        if a["scattered"] and n > 2:
            reply = reply[::2]  # not one run of the store
        attempts.append(
            Attempt(
                window[a["brk"]] if a["brk"] is not None else None,
                window[a["cmd"][0] : a["cmd"][0] + a["cmd"][1]],
                reply,
                a["reason"],
                a["end"],
                sequence=a["sequence"],
                retry=a["retry"],
                stray_events=window[: a["stray"]],
                stall=Stall(0.0, 1.0, 5.0) if a["stall"] else None,
            )
        )
    x = Exchange(_command(spec["text"]), spec["text"], attempts, binary=spec["binary"])
    x.heard_late = window[: spec["late"]]
    return x


@settings(max_examples=150, deadline=None)
@given(st.lists(_exchange, max_size=12), st.integers(0, 11), st.integers(-14, 14))
def test_hand_built_rows_make_the_exchanges(specs: list[dict], j: int, i: int):
    assert STORE is not None
    window = list(STORE[0:CHARS])
    positions = Positions(STORE, 0, window)
    made = [_made(s, window) for s in specs]
    kept_ids = {id(x) for x, s in zip(made, specs, strict=True) if s["measured"]}
    store_records(positions, made, [])
    texts = [a.reply_text for x in made for a in x.attempts]
    held = HeldExchanges(STORE)
    held.add(positions, made[:j], kept_ids)
    held.add(positions, made[j:], kept_ids)
    assert len(held) == len(made)
    assert list(held) == made and held[:] == made and held[i:j] == made[i:j]
    assert [a.reply_text for x in held for a in x.attempts] == texts
    for k, x in enumerate(made):
        plain = not (
            id(x) in kept_ids
            or x.heard_late
            or any(
                a.stall
                or a.stray_events
                or type(a.reply_events) is not list
                and a.reply_events.at
                or a.sequence > 255
                for a in x.attempts
            )
        )
        assert (held[k] is x) is not plain, specs[k]
        assert held[k] is held[k]  # the same object while one is held
    if -len(made) <= i < len(made):
        assert held[i] == made[i]
    else:
        with pytest.raises(IndexError):
            held[i]
    for kinds in ({Kind.IDENTIFY}, {Kind.ACKNOWLEDGE, Kind.EXTENDED}):
        assert held.of_kinds(kinds) == [
            x for x in made if x.command is not None and x.command.kind in kinds
        ]


def test_an_exchange_read_by_kind_makes_no_other():
    assert STORE is not None
    window = list(STORE[0:CHARS])
    positions = Positions(STORE, 0, window)
    made = [
        Exchange(_command(t), t, [Attempt(None, window[k : k + 3], window[k + 3 : k + 9], OK, 1.0)])
        for k, t in zip(range(0, 300, 10), TEXTS * 5, strict=False)
    ]
    store_records(positions, made, [])
    held = HeldExchanges(STORE)
    held.add(positions, made, set())
    assert not held.kept
    asked = held.of_kinds({Kind.IDENTIFY})
    assert asked == [x for x in made if x.text == "0I!"]
    assert sorted(held._made) == [k for k, x in enumerate(made) if x.text == "0I!"]
    del asked
    gc.collect()
    assert not held._made  # nothing held once the case lets go
