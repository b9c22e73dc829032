"""Issue 22, matrix25: the per-event and per-exchange paths of a fault-matrix row read the enum
members they compare with from module constants, not off the enum class.

On Python 3.11 ``Kind.DATA`` (any ``EventKind``, ``Kind``, ``Verdict`` or ``ReplyKind``
member read off its class) goes through the metaclass's ``__getattr__`` hook
(``EnumType.__getattr__`` puts ``slot_tp_getattr_hook`` in front of every class attribute
look-up, and the interpreter's attribute cache does not specialise it): ~0.13 us a look
against a module global's ~0.01 us, and a row looked some 10^5 times (callgrind, one row:
``slot_tp_getattr_hook`` 3.1% of the process's instructions). The functions named here are
the ones a row calls most (cProfile call counts times their looks, README.md's matrix25
section); a look put back into one of them fails
:func:`test_hot_functions_read_no_member_off_its_enum`.

Two of the cuts are not a constant put in a member's place but a ``match`` on ``case Kind.X``
made an ``if`` chain over ``==`` (what a value pattern compares with): each is held to the
``match`` it replaced, kept below word for word, over every kind.
"""

from __future__ import annotations

import dis
import enum
import inspect
import types
from dataclasses import replace

import pytest

from conformance import results, transcript, verdicts
from conformance.emulator import sensor as emulator_sensor
from conformance.emulator import sim_sensor
from conformance.emulator.replies import Reply, ReplyKind
from conformance.emulator.sensor import SensorEmulator
from conformance.judges import timing
from conformance.links import base
from conformance.protocol import commands
from conformance.protocol.commands import Command, Kind, parse_command
from conformance.replay import sensor as replay_sensor
from conformance.sensor import buffer_watch
from conformance.tool_recorder import contention, engine, records, validity
from conformance.transcript import to_wire_7e1
from conformance.view import live_cut, rebuilt_records, runs, segments

#: (module, qualified name) of every function the cut reads its members from constants in
HOT = [
    (replay_sensor, "RecordedSensor.on_char"),
    (replay_sensor, "RecordedSensor.on_break"),
    (replay_sensor, "_same"),
    (timing, "Measured.__init__"),
    (timing, "_window_verdict"),
    (validity, "_shape_problem"),
    (validity, "_reply_address"),
    (validity, "_ascii_problem"),
    (validity, "fits_shape"),
    (emulator_sensor, "SensorEmulator._dispatch"),  # (its reply's kind: one look, see ALLOWED)
    (emulator_sensor, "SensorEmulator._command"),
    (emulator_sensor, "SensorEmulator._sent"),
    (transcript, "decode_7e1"),
    (transcript, "decode_8n1"),
    (engine, "ToolRecorder.transact"),
    (engine, "ToolRecorder._usual_attempt"),
    (engine, "closes_exchange"),
    (engine, "_own_break_last"),
    (engine, "_LastDutChar.after"),
    (contention, "_read_apart"),
    (contention, "collisions"),
    (commands, "measurement_code_of"),
    (commands, "described"),
    (verdicts, "Finding.__post_init__"),
    (results, "unreached"),
    (results, "decides"),
    (rebuilt_records, "_exchanges"),
    (rebuilt_records, "_is_data"),
    (segments, "Cut.feed"),
    (runs, "Segment.of"),
    (live_cut, "LiveCut.advance"),
    (base, "Link.last_activity"),
    (records, "_is_data"),
    (records, "Measurement.binary"),
    (buffer_watch, "WatchedToolRecorder._hear_late_reply"),
    (buffer_watch, "WatchedToolRecorder.buffer_holds_values"),
]


#: looks left where they are: the reply kind of the one branch a command takes (one look a
#: command, not one per case tried), and a foreign command's answer (a faulty sensor's only)
ALLOWED = {
    "SensorEmulator._dispatch": {
        "ReplyKind.ACKNOWLEDGE", "ReplyKind.ADDRESS", "ReplyKind.IDENTIFICATION",
        "ReplyKind.EXTENDED",
    },
    "SensorEmulator._command": {"Kind.ACKNOWLEDGE", "Kind.IDENTIFY", "ReplyKind.ACKNOWLEDGE"},
}  # fmt: skip


def _function(owner: object, name: str) -> types.FunctionType:
    obj: object = owner
    for part in name.split("."):
        obj = inspect.getattr_static(obj, part) if isinstance(obj, type) else getattr(obj, part)
    if isinstance(obj, property):
        obj = obj.fget
    if isinstance(obj, (classmethod, staticmethod)):
        obj = obj.__func__
    assert isinstance(obj, types.FunctionType), (owner, name, obj)
    return obj


def _codes(code: types.CodeType):
    yield code
    for const in code.co_consts:
        if isinstance(const, types.CodeType):  # its comprehensions and generators too
            yield from _codes(const)


def _members_read_off_their_enum(function: types.FunctionType) -> list[str]:
    """``Enum.MEMBER`` reads in ``function`` (and the code nested in it): a global that is an
    enum class, then an attribute of it that is one of its members."""
    found = []
    for code in _codes(function.__code__):
        ops = list(dis.get_instructions(code))
        for a, b in zip(ops, ops[1:], strict=False):
            if a.opname != "LOAD_GLOBAL" or b.opname != "LOAD_ATTR":
                continue
            cls = function.__globals__.get(a.argval)
            if isinstance(cls, enum.EnumType) and b.argval in cls.__members__:
                found.append(f"{a.argval}.{b.argval}")
    return found


@pytest.mark.parametrize(("owner", "name"), HOT, ids=[n for _, n in HOT])
def test_hot_functions_read_no_member_off_its_enum(owner, name):
    found = set(_members_read_off_their_enum(_function(owner, name)))
    assert found <= ALLOWED.get(name, set())


def test_the_check_sees_a_member_read_off_its_enum():
    """The bytecode check finds what it looks for (so an empty answer above means none)."""

    def reads() -> bool:
        return Kind.DATA is not None

    assert _members_read_off_their_enum(reads) == ["Kind.DATA"]


def _old_measurement_code_of(kind: Kind, crc: bool, group: int) -> str:
    """commands.measurement_code_of before matrix25, word for word."""
    c = "C" if crc else ""
    match kind:
        case Kind.MEASURE:
            return "M" + c + (str(group) if group else "")
        case Kind.CONCURRENT:
            return "C" + c + (str(group) if group else "")
        case Kind.VERIFY:
            return "V"
        case Kind.HIGH_VOLUME_ASCII:
            return "HA"
        case Kind.HIGH_VOLUME_BINARY:
            return "HB"
        case Kind.CONTINUOUS:
            return "R" + c + str(group)
    raise ValueError(f"{kind} has no measurement code")


def _outcome(f, *args):
    try:
        return ("value", f(*args))
    except ValueError as exc:
        return ("error", str(exc))


@pytest.mark.parametrize("kind", list(Kind))
def test_measurement_code_of_is_the_match_it_replaced(kind):
    for crc in (False, True):
        for group in range(10):
            got = _outcome(commands.measurement_code_of, kind, crc, group)
            assert got == _outcome(_old_measurement_code_of, kind, crc, group)
            # a plain str equal to the member's value compares equal as the match did
            assert _outcome(commands.measurement_code_of, str(kind.value), crc, group) == (
                _outcome(_old_measurement_code_of, str(kind.value), crc, group)
            )


def _old_dispatch(self: SensorEmulator, cmd: Command, at: float) -> None:
    """SensorEmulator._dispatch before matrix25, word for word."""
    a = cmd.address if cmd.address != "?" else self.address
    match cmd.kind:
        case Kind.ACKNOWLEDGE:
            self._send(Reply(ReplyKind.ACKNOWLEDGE, a, command=cmd), at)
        case Kind.QUERY_ADDRESS:
            self._send(Reply(ReplyKind.ADDRESS, a, command=cmd), at)
        case Kind.IDENTIFY:
            body = a + self.profile.identification()
            self._send(Reply(ReplyKind.IDENTIFICATION, body, command=cmd), at)
        case Kind.CHANGE_ADDRESS:
            self._change_address(cmd, at)
        case Kind.DATA:
            self._data_reply(cmd, at)
        case Kind.BINARY_DATA:
            self._binary_reply(cmd, at)
        case Kind.CONTINUOUS:
            self._continuous(cmd, at)
        case Kind.IDENTIFY_MEASUREMENT:
            self._identify_measurement(cmd, at)
        case Kind.METADATA:
            self._metadata(cmd, at)
        case Kind.EXTENDED:
            text = self.profile.extended.get(cmd.body)
            if text is not None and "\n" in text:
                self._multiline(cmd, a, text.split("\n"), at)
            elif text is not None:
                self._send(Reply(ReplyKind.EXTENDED, a + text, command=cmd), at)
            else:
                self._unknown(cmd, at)
        case _:
            self._start_measurement(cmd, at)


#: a command of every kind, in an order that has data, a running measurement and an address
#: change to answer from (each text is sent after a break, the wire read to its quiet)
SCRIPT = [
    "0!", "?!", "0I!", "0M!", "0D0!", "0MC1!", "0D0!", "0C!", "0D0!", "0CC2!", "0D0!", "0V!",
    "0D0!", "0HA!", "0D0!", "0D1!", "0HB!", "0DB0!", "0DB1!", "0R0!", "0RC1!", "0R9!", "0IM!",
    "0IMC1!", "0IC!", "0IHA!", "0IR0!", "0IM_001!", "0IMC1_002!", "0IHB_001!", "0IR0_001!",
    "0IM_099!", "0XHELP!", "0XSN!", "0XNONE!", "0A1!", "1!", "1A0!", "0!", "0D9!", "0DB9!",
]  # fmt: skip


def _script_on(faults: tuple[str, ...], dispatch) -> list[tuple[float, float, int, str]]:
    bus, link, emulator = sim_sensor(None, faults)
    emulator._dispatch = types.MethodType(dispatch, emulator)
    for text in SCRIPT:
        link.send_break(13e-3)
        link.wait_until(link.now() + 9e-3)
        link.write(bytes(to_wire_7e1(ord(c)) for c in text))
        link.receive(link.now() + 2.5, idle=0.2)
    return [(e.start, e.end, e.wire, e.origin) for e in link.transcript.events]


@pytest.mark.parametrize(
    "faults",
    [(), ("metadata-missing-record",), ("unknown-command-text",), ("answers-foreign-address",)],
)
def test_dispatch_is_the_match_it_replaced(faults):
    """The emulator's wire, every event, with the new dispatch and with the old one, over
    commands of every kind (a profile's extended commands, one unknown, a v1.4 sensor)."""
    new = _script_on(faults, SensorEmulator._dispatch)
    assert new == _script_on(faults, _old_dispatch)
    assert sum(1 for *_, origin in new if origin != "tool") > 300  # the sensor answered


def test_dispatch_compares_as_the_match_did():
    """A value pattern compares with ``==``: a command whose kind is the member's plain
    string value is dispatched alike both ways."""
    cmd = parse_command("0I!")
    odd = replace(cmd, kind=str(Kind.IDENTIFY.value))  # type: ignore[arg-type]
    seen = {}
    for label, dispatch in (("new", SensorEmulator._dispatch), ("old", _old_dispatch)):
        bus, link, emulator = sim_sensor(None, ())
        sent = []
        emulator._send = lambda reply, at, sent=sent: sent.append((reply.kind, reply.body))  # type: ignore[method-assign]
        dispatch(emulator, odd, 1.0)
        seen[label] = sent
    assert seen["new"] == seen["old"] and seen["new"]
