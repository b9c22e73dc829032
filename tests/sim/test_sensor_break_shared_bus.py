"""A sensor's break on a bus it shares with another sensor (``break-before-reply``): the
transcript names the sensor that held the line, the other sensor hears a break (it may wake
on it, as on a recorder's), and the reply after it stays whole and is the breaking sensor's.
The one-device bus had its own tests; this is the case where origins are the devices' names."""

from __future__ import annotations

from dataclasses import replace

from conformance.emulator.profile import default_profile
from conformance.emulator.sensor import SensorEmulator
from conformance.sim.bus import SENSOR_BREAK, SimBus, SimLink
from conformance.transcript import EventKind, encode_7e1


def _bus() -> tuple[SimLink, SensorEmulator, list[tuple[float, float]]]:
    breaking = SensorEmulator(default_profile(), ["break-before-reply"], name="s0")
    other = SensorEmulator(replace(default_profile(), address="1"), name="s1")
    heard: list[tuple[float, float]] = []
    plain = other.on_break

    def on_break(start: float, end: float) -> None:
        heard.append((start, end))
        plain(start, end)

    other.on_break = on_break  # type: ignore[method-assign]
    return SimLink(SimBus([breaking, other])), breaking, heard


def test_a_sensors_break_is_its_own_and_heard_by_the_other_sensor() -> None:
    link, _, heard = _bus()
    link.send_break(0.013)
    link.wait_until(link.now() + 0.010)  # the marking a command needs after the break
    del heard[:]  # the tool's own break: both hear it
    command = link.write(encode_7e1("0I!"))
    got = link.receive(command[-1].end + 0.6)
    events = link.transcript.events
    breaks = [e for e in events if e.kind is EventKind.BREAK and e.origin != "tool"]
    assert len(breaks) == 1, breaks
    (brk,) = breaks
    assert brk.origin == "s0" and brk.text == SENSOR_BREAK
    assert command[-1].end <= brk.start < brk.end
    assert heard == [(brk.start, brk.end)]  # the other sensor heard it, once, as it was
    reply = [e for e in got if e.kind is EventKind.CHAR]
    assert reply and {e.origin for e in reply} == {"s0"}
    assert reply[0].start >= brk.end
    text = bytes(e.wire & 0x7F for e in reply)
    assert text.startswith(b"0") and text.endswith(b"\r\n"), text
