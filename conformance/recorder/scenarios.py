"""The recorder-role scenarios: which sensors the tool plays and what the recorder is asked.

A scenario provokes one recorder behaviour (waiting for a service request, retrying a silent
sensor, continuing past D9...). The cases in ``testcases/recorder/`` pick the scenarios their
requirements are judged on; the session runs each scenario once and every case that needs it
shares the transcript ("one stimulus, many judges", as in the sensor role).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..emulator.behaviour import REPLY_DELAY
from ..recorder_jobs import Request, Task
from .played import SensorSpec, Spoil


@dataclass(frozen=True)
class Scenario:
    name: str
    title: str  # what the scenario provokes, for the report
    sensors: tuple[SensorSpec, ...]
    request: Request
    v14: bool = False  # needs a recorder claiming v1.4 (HA, HB, metadata pass-through)

    def describe(self) -> str:
        on_bus = "; ".join(s.describe() for s in self.sensors)
        return f"{self.title}. On the bus: {on_bus}. Asked: {self.request.sentence()}."


def _s(address: str = "0", **kw: object) -> SensorSpec:
    return SensorSpec(address, **kw)  # type: ignore[arg-type]


#: ttt of ``ttt-over-255`` and when its service request comes: a recorder keeping ttt in
#: 8 bits waits 260 % 256 = 4 s and asks for aD0! before the request (real time: 6 s, cheap).
#: 6 s, not 5: EnviroDIY's d_simple_logger keeps ttt in a ``uint8_t`` and waits a second
#: more, ``(wait + 1) * 1000`` ms from 0.1 s after the command, so 5.1 s: with the request
#: at 5 s it heard the request first and passed (outside32)
LONG_TTT = 260
LONG_TTT_READY = 6.0
#: When ``reply-at-window-edge``'s sensor starts each reply: 15.0 ms after the command's stop
#: bit, inside the 15.40 ms a sensor may take (R-7.0-10)
EDGE_REPLY = 15.0e-3


def _measure(*commands: str) -> Request:
    return Request(Task.MEASURE, commands)


_SCENARIOS = (
    Scenario(
        "service-request",
        "a sensor that sends its service request long before ttt",
        (_s(),),
        _measure("0M!"),
    ),
    Scenario(
        "no-service-request",
        "a sensor whose data are ready early but that never sends a service request",
        (_s(faults=("no-service-request",)),),
        _measure("0M!"),
    ),
    Scenario("ttt-zero", "a measurement announcing ttt = 000", (_s(),), _measure("0M1!")),
    Scenario("d0-to-d2", "nine values spread over D0, D1 and D2", (_s(),), _measure("0M2!")),
    Scenario(
        "empty-data",
        "a sensor that loses its first measurement, so D0 gets the valid empty reply",
        (_s(aborts_once=True),),
        _measure("0M!"),
    ),
    Scenario(
        "silent-twice",
        "a sensor that answers only the third transmission of a command",
        (_s(unheard=2),),
        _measure("0M!"),
    ),
    Scenario(
        "silent-six",
        "a sensor that answers only after two full break+command+retries sequences",
        (_s(unheard=6),),
        _measure("0M!"),
    ),
    Scenario(
        "bad-crc-once",
        "a D0 reply whose CRC does not match its values, once",
        (_s(spoil=Spoil("crc"), spoil_command="0D0!"),),
        _measure("0MC!"),
    ),
    Scenario(
        "parity-once",
        "a long D0 reply with a parity error in its second character, once",
        (_s(spoil=Spoil("parity", at=1), spoil_command="0D0!"),),
        _measure("0M2!"),
    ),
    Scenario(
        "pause-once",
        "a D0 reply that stops for 20 ms after four characters, once",
        (_s(spoil=Spoil("pause", at=3), spoil_command="0D0!"),),
        _measure("0M2!"),
    ),
    Scenario(
        "format-once",
        "a measurement reply with a '?' where a digit belongs, once",
        (_s(spoil=Spoil("format", at=2), spoil_command="0M!"),),
        _measure("0M!"),
    ),
    Scenario(
        "parity-mid-reply",
        "a D0 reply with a parity error in a middle character (inside its second value), once",
        (_s(spoil=Spoil("parity", at=10), spoil_command="0D0!"),),
        _measure("0M!"),
    ),
    Scenario(
        "ttt-over-255",
        f"a measurement announcing ttt = {LONG_TTT} s, over what 8 bits hold, with its "
        f"service request after {LONG_TTT_READY:g} s",
        (_s(timing=(("M", LONG_TTT, LONG_TTT_READY),)),),
        _measure("0M!"),
    ),
    Scenario(
        "reply-at-window-edge",
        f"a sensor that starts every reply {EDGE_REPLY * 1e3:.1f} ms after the command, at "
        "the edge of the 15.40 ms it may take",
        (_s(reply_extra=EDGE_REPLY - REPLY_DELAY),),
        _measure("0M!"),
    ),
    Scenario(
        "two-sensors",
        "two sensors measured one after the other",
        (_s("0"), _s("1")),
        _measure("0M!", "1M!"),
    ),
    Scenario(
        "concurrent-two",
        "two sensors measuring concurrently",
        (_s("0"), _s("1")),
        Request(Task.CONCURRENT, ("0C!", "1C!")),
    ),
    Scenario(
        "concurrent-ttt-zero",
        "two sensors measuring concurrently, one of them announcing ttt = 000 (data ready at once)",
        (_s("0", timing=(("C", 0, 0.0),)), _s("1")),
        Request(Task.CONCURRENT, ("0C!", "1C!")),
    ),
    Scenario(
        "concurrent-99",
        "a concurrent measurement of 99 values (D0..D9)",
        (_s(),),
        Request(Task.CONCURRENT, ("0C9!",)),
    ),
    Scenario(
        "high-volume-ascii",
        "120 high-volume ASCII values in D0..D14",
        (_s(),),
        _measure("0HA!"),
        v14=True,
    ),
    Scenario(
        "high-volume-binary",
        "high-volume binary packets of ten data types",
        (_s(),),
        _measure("0HB!"),
        v14=True,
    ),
    Scenario(
        "families",
        "every measurement command family a recorder must log",
        (_s(),),
        _measure("0M!", "0M1!", "0MC!", "0V!", "0C!", "0C1!", "0CC!", "0R0!", "0RC0!"),
    ),
    Scenario(
        "basic-commands",
        "the basic commands: query, acknowledge, identify, change address and back",
        (_s(),),
        Request(Task.COMMAND, ("?!", "0!", "0I!", "0A5!", "5A0!", "0!")),
    ),
    Scenario(
        "addresses",
        "one sensor at every address 0-9 and two at letter addresses",
        tuple(_s(a) for a in "0123456789Az"),
        Request(Task.COMMAND, tuple(f"{a}!" for a in "0123456789Az")),
    ),
    Scenario(
        "transparent",
        "host commands passed through: basic and extended",
        (_s(),),
        Request(Task.TRANSPARENT, ("0!", "0I!", "0XSN!")),
    ),
    Scenario(
        "transparent-v14",
        "host commands passed through: multi-line text, identify and metadata (v1.4)",
        (_s(),),
        Request(Task.TRANSPARENT, ("0XHELP!", "0IM!", "0IM_001!", "0IHA_001!", "0IHB!")),
        v14=True,
    ),
    Scenario(
        "multiline-no-etx",
        "multi-line text that ends without ETX: complete after 150 ms of silence",
        (_s(faults=("multiline-no-etx",)),),
        Request(Task.TRANSPARENT, ("0XHELP!", "0XSN!")),
        v14=True,
    ),
)

SCENARIOS: dict[str, Scenario] = {s.name: s for s in _SCENARIOS}
