"""The reference sensor emulator, driven over the sim bus the way a recorder drives a sensor.

Every check goes through the wire (break, 7E1 command characters, stamped reply frames), so
the emulator's section 7 rules are exercised, not just its command table. ``Rig`` is reused
by the fault tests.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import pytest

from conformance.emulator import MeasurementSpec, Profile, default_profile, sim_sensor
from conformance.protocol.binary import DataType, parse_binary_packet
from conformance.protocol.commands import parse_command
from conformance.protocol.crc import ascii_crc
from conformance.protocol.responses import (
    parse_data_reply_for,
    parse_ident,
    parse_measurement_reply_for,
    parse_metadata_reply,
)
from conformance.protocol.timing import (
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    RESPONSE_START_MAX,
    RESPONSE_START_MIN,
    TOLERANCE,
)
from conformance.protocol.values import check_value, split_values
from conformance.transcript import Event, decode_7e1, decode_8n1, to_wire_7e1
from tests.support.own_time import own_time

BREAK = 13e-3
MARKING = 9e-3
LISTEN = 1.0  # long enough for the longest reply (81 characters, 0.68 s); idle ends it sooner


@dataclass
class Answer:
    """What came back for one command: the frames, and when the command ended."""

    command_end: float
    events: list[Event]

    @property
    def text(self) -> str:
        return decode_7e1(self.events)

    @property
    def raw(self) -> bytes:
        return decode_8n1(self.events)

    @property
    def body(self) -> str:
        """Text without the final CR LF."""
        return self.text[:-2] if self.text.endswith("\r\n") else self.text

    @property
    def delay(self) -> float:
        return self.events[0].start - self.command_end

    @property
    def gaps(self) -> list[float]:
        return [b.start - a.end for a, b in zip(self.events, self.events[1:], strict=False)]


class Rig:
    """One emulator on a sim bus and the tool's link to it."""

    def __init__(self, profile: Profile | None = None, faults: tuple[str, ...] = ()) -> None:
        self.bus, self.link, self.emulator = sim_sensor(profile, faults)

    @property
    def now(self) -> float:
        return self.link.now()

    def wait(self, seconds: float) -> None:
        self.link.wait_until(self.now + seconds)

    def wake(self, duration: float = BREAK, marking: float = MARKING) -> None:
        self.link.send_break(duration)
        self.wait(marking)

    def send(self, text: str, gap: float = 0.0) -> list[Event]:
        return self.link.write(bytes(to_wire_7e1(ord(c)) for c in text), gap=gap)

    def listen(self, timeout: float = LISTEN, idle: float = 20e-3) -> list[Event]:
        return self.link.receive(self.now + timeout, idle=idle)

    def ask(self, text: str, *, brk: bool = True, timeout: float = LISTEN) -> Answer:
        if brk:
            self.wake()
        sent = self.send(text)
        return Answer(sent[-1].end, self.listen(timeout))

    def line(self, timeout: float) -> list[Event]:
        """Listen (no break, nothing sent) until a CR LF arrives or ``timeout`` passes."""
        return self.link.receive(
            self.now + timeout, until=lambda got: decode_7e1(got).endswith("\r\n")
        )

    def measure(self, text: str) -> tuple[Answer, list[Event]]:
        """Start a measurement, then wait for the first line after it (the service request)
        or until ttt + 0.5 s; returns the reply and what followed."""
        start = self.ask(text)
        ttt = int(start.body[1:4]) if start.body[1:4].isdigit() else 0
        if not ttt:
            return start, []
        follow = self.link.receive(
            self.now + ttt + 0.5, until=lambda got: decode_7e1(got).endswith("\r\n")
        )
        return start, follow

    def data(self, command: str, count: int | None = None, *, first_brk: bool = True) -> list[str]:
        """Collect D0, D1, ... bodies (CR LF stripped) until ``count`` values or an empty one."""
        letter = "D"
        bodies, values = [], 0
        for i in range(1000):
            answer = self.ask(f"0{letter}{i}!", brk=first_brk or i > 0)
            bodies.append(answer.body)
            parsed = parse_data_reply_for(answer.body, parse_command(command))
            if not parsed.values:
                break
            values += len(parsed.values)
            if count is not None and values >= count:
                break
        return bodies


def _values(bodies: list[str], command: str) -> list[str]:
    out: list[str] = []
    for body in bodies:
        out += parse_data_reply_for(body, parse_command(command)).values
    return out


@pytest.fixture
def rig() -> Rig:
    return Rig()


# -- basic commands --------------------------------------------------------------------------
@pytest.mark.parametrize("version", ["14", "13"])
def test_acknowledge_query_and_identification(version):
    rig = Rig(default_profile(version))
    assert rig.ask("0!").text == "0\r\n"
    assert rig.ask("?!", brk=False).text == "0\r\n"
    ident = parse_ident(rig.ask("0I!", brk=False).body, "0")
    assert ident.ok, ident.violations
    assert ident.version == version
    assert (ident.vendor, ident.model, ident.sensor_version) == ("CONFORM ", "EMU001", "100")


def test_fresh_sensor_is_in_standby_until_a_break(rig):
    assert rig.ask("0!", brk=False).events == []
    assert rig.ask("0!").text == "0\r\n"


def test_unknown_commands_and_other_addresses_are_silent(rig):
    for text in ("0Q!", "0D01!", "0XNOPE!", "?I!", "1!"):
        assert rig.ask(text).events == [], text


def test_extended_command(rig):
    assert rig.ask("0XSN!").text == "0EMU-0001\r\n"


# -- measurement replies ---------------------------------------------------------------------
V14_STARTS = {
    "0M!": "00023",
    "0MC!": "00023",
    "0M1!": "00002",
    "0MC1!": "00002",
    "0M2!": "00059",
    "0M5!": "00000",  # undefined: R-4.4.9-02
    "0MC7!": "00000",
    "0V!": "00013",
    "0C!": "000320",
    "0CC!": "000320",
    "0C9!": "000499",
    "0CC9!": "000499",
    "0C5!": "000000",  # undefined: R-4.4.10-02
    "0HA!": "0006120",
    "0HB!": "0002033",
}


@pytest.mark.parametrize(("command", "expected"), V14_STARTS.items())
def test_measurement_replies_v14(rig, command, expected):
    answer = rig.ask(command)
    assert answer.body == expected
    parsed = parse_measurement_reply_for(answer.body, parse_command(command))
    assert parsed.violations == []


@pytest.mark.parametrize(("command", "expected"), V14_STARTS.items())
def test_identify_measurement_repeats_the_reply_without_measuring(rig, command, expected):
    identify = "0I" + command[1:]
    answer = rig.ask(identify)
    assert answer.body == expected
    assert rig.emulator.running is None
    # no service request follows an identify command (R-6.1-03)
    assert rig.link.receive(rig.now + 10.0) == []


def test_v13_is_silent_to_v14_commands_and_keeps_concurrent_counts_low():
    rig = Rig(default_profile("13"))
    for text in ("0HA!", "0HB!", "0DB0!", "0IM!", "0IC!", "0IM_001!", "0IR0_001!", "0D10!"):
        assert rig.ask(text).events == [], text
    for group in ["", *"123456789"]:
        body = rig.ask(f"0C{group}!").body
        assert len(body) == 6 and int(body[4:]) <= 20, body
    assert rig.ask("0M!").body == "00023"


def test_v14_without_high_volume_answers_zero():
    profile = default_profile()
    measurements = {k: v for k, v in profile.measurements.items() if k not in ("HA", "HB")}
    rig = Rig(replace(profile, measurements=measurements))
    assert rig.ask("0HA!").body == "0000000"
    assert rig.ask("0HB!").body == "0000000"


# -- service requests and data ----------------------------------------------------------------
def test_measure_sends_service_request_before_ttt_and_data_follow(rig):
    start, follow = rig.measure("0M!")
    assert start.body == "00023"
    service_request = follow[:3]
    assert decode_7e1(service_request) == "0\r\n"
    assert len(follow) == 3  # nothing else (R-4.4.5-08)
    assert service_request[-1].end - start.events[-1].end < 2.0  # R-4.4.6-04
    # D0 without a break right after the service request (R-7.1-02)
    assert rig.ask("0D0!", brk=False).body == "0+22.15+1013.2+45.7"


def test_crc_variant_data_carry_a_valid_crc(rig):
    rig.measure("0MC!")
    body = rig.ask("0D0!", brk=False).body
    assert body == "0+22.15+1013.2+45.7" + ascii_crc("0+22.15+1013.2+45.7")


def test_ttt_zero_has_no_service_request_and_immediate_data(rig):
    start = rig.ask("0M1!")
    assert start.body == "00002"
    assert rig.listen(timeout=1.0) == []  # R-4.4.6-03
    assert rig.ask("0D0!").body == "0+12.61+3.3"


@pytest.mark.parametrize("command", ["0C!", "0CC1!", "0HA!", "0HB!"])
def test_concurrent_measurements_send_no_service_request(rig, command):
    _, follow = rig.measure(command)
    assert follow == []  # R-4.4.6-05, R-4.4.7-04


def test_ttt_999_completes_fast_in_wall_time():
    profile = default_profile()
    spec = MeasurementSpec(("+1.5",), ttt=999, ready_after=998.9)
    rig = Rig(replace(profile, measurements={**profile.measurements, "M3": spec}))
    with own_time() as took:  # less any wait for a CPU: a busy machine does not stretch it
        start, follow = rig.measure("0M3!")
    assert took.seconds < 1.0, took
    assert start.body == "09991"
    reply_end = start.events[-1].end
    assert decode_7e1(follow) == "0\r\n"
    assert 998.0 < follow[-1].end - reply_end < 999.0
    assert rig.ask("0D0!", brk=False).body == "0+1.5"


def test_multi_page_measure_packs_greedily_within_35(rig):
    rig.measure("0M2!")
    bodies = rig.data("0M2!", 9)
    assert len(bodies) == 3
    assert all(len(b) - 1 <= 35 for b in bodies)
    assert all(len(b) - 1 + 9 > 35 for b in bodies[:-1])  # the next value would not fit
    assert _values(bodies, "0M2!") == list(default_profile().measurements["M2"].values)
    assert rig.ask("0D3!").body == "0"


def test_99_value_concurrent_fits_d0_to_d9(rig):
    rig.measure("0C9!")
    bodies = rig.data("0C9!", 99)
    assert len(bodies) == 10
    assert all(len(b) - 1 <= 75 for b in bodies)
    assert len(_values(bodies, "0C9!")) == 99


def test_high_volume_ascii_goes_past_d9_with_crc(rig):
    rig.measure("0HA!")
    bodies = rig.data("0HA!", 120)
    assert len(bodies) == 15
    for body in bodies:
        parsed = parse_data_reply_for(body, parse_command("0HA!"))
        assert parsed.ok and parsed.crc_ok, parsed.violations
    assert rig.ask("0D15!").body == "0" + ascii_crc("0")


def test_high_volume_binary_packets_parse_back(rig):
    rig.measure("0HB!")
    expected = default_profile().measurements["HB"].packets
    for i, packet in enumerate(expected):
        answer = rig.ask(f"0DB{i}!")
        parsed = parse_binary_packet(answer.raw, "0")
        assert parsed.ok and parsed.crc_ok, parsed.violations
        assert parsed.dtype == packet.dtype
        assert parsed.values == pytest.approx(list(packet.values))
    assert {p.dtype for p in expected} == set(DataType) - {DataType.INVALID}
    empty = rig.ask(f"0DB{len(expected)}!").raw
    assert len(empty) == 6 and parse_binary_packet(empty, "0").is_empty


def test_continuous_commands(rig):
    assert rig.ask("0R0!").body == "0+22.1+45.6"
    assert rig.ask("0RC1!").body == "0+1013.25" + ascii_crc("0+1013.25")
    assert rig.ask("0R7!").text == "0\r\n"
    assert rig.ask("0RC7!").text == "0AP@\r\n"  # the spec's example


def test_data_request_with_nothing_measured(rig):
    assert rig.ask("0D0!").text == "0\r\n"


# -- metadata ---------------------------------------------------------------------------------
@pytest.mark.parametrize("key", sorted(default_profile().measurements))
def test_every_value_has_metadata_and_the_end_is_marked(rig, key):
    spec = default_profile().measurements[key]
    command = f"0I{key}"
    crc = key in ("HA", "HB")
    for index in range(1, spec.count + 1):
        body = rig.ask(f"{command}_{index:03d}!").body
        parsed = parse_metadata_reply(body, crc_expected=crc)
        assert parsed.ok and not parsed.invalid_index, (index, parsed.violations)
        assert len(parsed.fields) >= 2
    for index in (0, spec.count + 1):
        parsed = parse_metadata_reply(rig.ask(f"{command}_{index:03d}!").body, crc_expected=crc)
        assert parsed.invalid_index and parsed.ok


def test_metadata_of_crc_commands_carries_crc(rig):
    body = rig.ask("0IMC_001!").body
    assert body.endswith(";" + ascii_crc(body[:-3]))
    assert rig.ask("0IRC0_003!").body == "0" + ascii_crc("0")


# -- aborts and buffer retention --------------------------------------------------------------
def test_break_aborts_measure_and_next_command_works(rig):
    start = rig.ask("0M!")
    assert start.body == "00023"
    rig.wait(0.5)
    assert rig.ask("0D0!").text == "0\r\n"  # the break in front aborted it (R-4.4.5.1-01/02)
    assert rig.listen(timeout=3.0) == []  # no service request any more
    rig.measure("0M!")  # R-4.4.5.1-03
    assert rig.ask("0D0!", brk=False).body == "0+22.15+1013.2+45.7"


def test_aborted_crc_measure_answers_with_crc(rig):
    rig.ask("0MC!")
    rig.wait(0.2)
    assert rig.ask("0D0!").text == "0AP@\r\n"


def test_break_and_foreign_commands_do_not_abort_concurrent(rig):
    rig.ask("0C!")
    rig.wait(0.5)
    rig.wake()
    rig.ask("1M!", brk=False)
    rig.ask("2D0!")
    rig.wait(3.0)
    bodies = rig.data("0C!", 20)
    assert len(_values(bodies, "0C!")) == 20


def test_own_command_aborts_concurrent(rig):
    rig.ask("0CC!")
    rig.wait(0.5)
    assert rig.ask("0!").text == "0\r\n"
    rig.wait(3.0)
    assert rig.ask("0D0!").text == "0" + ascii_crc("0") + "\r\n"  # R-4.4.7.1-02


def test_early_data_request_returns_nothing_never_partial(rig):
    rig.ask("0C9!")
    rig.wait(1.0)
    assert rig.ask("0D0!").text == "0\r\n"


def test_data_survive_breaks_standby_and_other_commands(rig):
    rig.measure("0M2!")
    first = rig.data("0M2!", 9)
    rig.wait(1.0)  # standby
    for text in ("0!", "0I!", "0IM!", "0IM2_001!", "0R0!", "?!", "1M!", "0XSN!"):
        rig.ask(text)
    assert rig.data("0M2!", 9) == first  # R-4.4.5-10
    assert rig.data("0M2!", 9) == first


def test_new_measurement_replaces_the_data(rig):
    rig.measure("0M!")
    rig.ask("0M1!")
    assert rig.ask("0D0!").body == "0+12.61+3.3"


# -- section 7 timing -------------------------------------------------------------------------
def test_reply_timing_window_and_back_to_back_characters(rig):
    for text in ("0!", "0I!", "0M1!", "0D0!", "0HB!"):
        answer = rig.ask(text)
        assert RESPONSE_START_MIN <= answer.delay <= RESPONSE_START_MAX + TOLERANCE, text
        assert max(answer.gaps, default=0.0) <= INTER_CHAR_GAP_MAX
        assert all(e.duration == pytest.approx(CHAR_TIME) for e in answer.events)


def test_binary_packets_are_8n1_and_ascii_replies_7e1(rig):
    rig.ask("0HB!")
    rig.wait(3.0)
    packet = rig.ask("0DB1!").events  # uint8 200 and 255 have bit 7 set
    assert any(e.wire & 0x80 for e in packet)
    assert decode_8n1(packet)[:1] == b"0"
    ascii_reply = rig.ask("0I!").events
    assert all(e.parity_ok for e in ascii_reply)


def _wait_after(rig: Rig, answer: Answer, marking: float) -> None:
    """Wait until ``marking`` seconds have passed since the last reply character."""
    rig.link.wait_until(answer.events[-1].end + marking)


def test_standby_after_100_ms_of_marking(rig):
    answer = rig.ask("0!")
    _wait_after(rig, answer, 0.086)
    answer = rig.ask("0!", brk=False)
    assert answer.text == "0\r\n"  # R-7.0-16
    assert rig.emulator.awake(answer.events[-1].end + 0.099)
    assert not rig.emulator.awake(answer.events[-1].end + 0.1005)
    _wait_after(rig, answer, 0.1005)
    assert rig.ask("0!", brk=False).events == []  # R-7.0-15
    assert rig.ask("0!").text == "0\r\n"


def test_standby_after_a_command_for_another_address(rig):
    rig.ask("0!")
    rig.send("1!")
    assert rig.listen(timeout=0.03) == []  # 30 ms of marking: well inside the awake time
    assert rig.ask("0!", brk=False).events == []  # R-7.0-14


def test_address_needs_marking_after_break(rig):
    rig.wake(marking=4e-3)
    rig.send("0!")
    assert rig.listen() == []  # R-7.0-05
    rig.wake(marking=8.4e-3)
    rig.send("0!")
    assert decode_7e1(rig.listen()) == "0\r\n"


def test_wakes_within_100_ms_of_the_break(rig):
    rig.wake(marking=0.095)
    rig.send("0!")
    assert decode_7e1(rig.listen()) == "0\r\n"  # R-7.0-07


def test_break_length_rules(rig):
    rig.wait(0.2)
    rig.wake(duration=5e-3)
    rig.send("0!")
    assert rig.listen() == []  # R-7.0-03: 5 ms is no break
    rig.wake(duration=12.5e-3)
    rig.send("0!")
    assert decode_7e1(rig.listen()) == "0\r\n"  # R-7.0-04


def test_partial_command_is_dropped(rig):
    rig.wake()
    rig.send("0I", gap=CHAR_TIME + 0.1e-3)
    rig.send("!")
    assert rig.listen() == []  # R-AppB-01
    rig.wake()
    rig.send("0I!", gap=1.5e-3)
    assert decode_7e1(rig.listen()).startswith("014")


def test_parity_error_spoils_the_command(rig):
    rig.wake()
    rig.link.write(bytes([to_wire_7e1(ord("0")) ^ 0x80, to_wire_7e1(ord("!"))]))
    assert rig.listen() == []


def test_service_request_then_d0_without_break(rig):
    rig.measure("0V!")
    assert rig.ask("0D0!", brk=False).body == "0+1+0+12.6"


# -- change address ---------------------------------------------------------------------------
def test_change_address(rig):
    assert rig.ask("0A3!").text == "3\r\n"
    assert rig.ask("3!").text == "3\r\n"
    assert rig.ask("0!").events == []
    assert rig.ask("?!").text == "3\r\n"
    assert rig.ask("3I!").body.startswith("314")


def test_fixed_address_answers_old_address():
    rig = Rig(replace(default_profile(), address_settable=False))
    assert rig.ask("0A3!").text == "0\r\n"
    assert rig.ask("0!").text == "0\r\n"


def test_address_change_quiet_time():
    rig = Rig(replace(default_profile(), address_change_quiet=1.0))
    assert rig.ask("0A5!").text == "5\r\n"
    assert rig.ask("5!").events == []
    rig.wait(1.0)
    assert rig.ask("5!").text == "5\r\n"


# -- profile ------------------------------------------------------------------------------------
def test_profile_rejects_wrong_identification_widths():
    with pytest.raises(ValueError):
        replace(default_profile(), vendor="SHORT")
    with pytest.raises(ValueError):
        MeasurementSpec(("+1",), ttt=2, ready_after=2.5)


def test_default_profiles_are_conforming_data():
    for version in ("14", "13"):
        profile = default_profile(version)
        for key, spec in profile.measurements.items():
            assert len(spec.metadata) == spec.count, key
            for fields in spec.metadata:
                record = "0," + ",".join(fields) + ";"
                assert len(record) <= 75, record
            if key.startswith("C") and version == "13":
                assert spec.count <= 20
            for value in spec.values:
                assert split_values(value) == [value] and check_value(value) == [], value


def test_short_spacing_after_standby_does_not_keep_the_sensor_awake(rig):
    answer = rig.ask("0!")
    _wait_after(rig, answer, 0.101)  # standby by now (R-7.0-15)
    rig.wake(duration=5e-3)  # noise, not a break (R-7.0-03)
    rig.send("0!")
    assert rig.listen() == []
