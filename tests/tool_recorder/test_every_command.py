"""Acceptance of the foundation: the tool recorder completes every command of Table 5 and of
v1.4 against the reference emulator in virtual time (CRC variants and the 99-value concurrent
measurement included), each on its first transmission."""

from __future__ import annotations

import pytest

from conformance.emulator import default_profile, sim_sensor
from conformance.protocol.commands import C_FAMILY, HV_FAMILY, M_FAMILY, parse_command
from conformance.tool_recorder import ToolRecorder
from tests.support.own_time import own_time

SINGLE = (
    ["0!", "?!", "0I!"]
    + [f"0R{i}!" for i in range(10)]
    + [f"0RC{i}!" for i in range(10)]
    + [f"0I{code}!" for code in M_FAMILY + C_FAMILY + HV_FAMILY]
    + ["0IM_001!", "0IMC_003!", "0IC9_099!", "0IHA_120!", "0IHB_001!", "0IR0_001!", "0IRC1_001!"]
    + ["0XSN!", "0XHELP!"]
)


@pytest.fixture()
def master() -> ToolRecorder:
    _bus, link, _emulator = sim_sensor(default_profile("14"))
    return ToolRecorder(link)


@pytest.mark.parametrize("text", SINGLE)
def test_single_commands_complete_first_time(master, text):
    ex = master.transact(parse_command(text))
    assert ex.ok and len(ex.attempts) == 1, (text, ex.reply_text, [a.reason for a in ex.attempts])


@pytest.mark.parametrize("code", M_FAMILY + C_FAMILY + HV_FAMILY)
def test_measurements_complete_first_time(master, code):
    m = master.measure(parse_command(f"0{code}!"))
    assert m.start.ok and len(m.start.attempts) == 1
    assert m.count is not None and m.value_count == m.count, (code, m.count, m.value_count)
    assert all(len(ex.attempts) == 1 for ex in m.data)


def test_99_value_concurrent_and_high_volume_past_d9(master):
    c9 = master.measure(parse_command("0CC9!"))
    assert c9.count == 99 and len(c9.values) == 99 and len(c9.data) <= 10
    ha = master.measure(parse_command("0HA!"))
    assert ha.value_count == ha.count and [ex.text for ex in ha.data][10] == "0D10!"


def test_address_change_and_back(master):
    assert master.change_address("5", address="0").reply_text == "5\r\n"
    assert master.transact(parse_command("5!")).ok
    assert master.change_address("0", address="5").reply_text == "0\r\n"


def test_ttt_999_takes_virtual_time_only():
    from dataclasses import replace

    from conformance.emulator import MeasurementSpec

    profile = default_profile("14")
    slow = dict(profile.measurements)
    slow["M"] = MeasurementSpec(("+1",), ttt=999, ready_after=998.0)
    _bus, link, _ = sim_sensor(replace(profile, measurements=slow))
    with own_time() as took:  # less any wait for a CPU: a busy machine does not stretch it
        m = ToolRecorder(link).measure(parse_command("0M!"))
    assert took.seconds < 1.0, took
    assert m.values == ["+1"] and m.service_request_end - m.reply_end == pytest.approx(998.0, 0.01)
