"""The tool recorder against the reference emulator: a conforming sensor needs no retries,
and every announced value comes back. Skipped until ``conformance.emulator.sim_sensor`` exists."""

from __future__ import annotations

import pytest

from conformance.protocol import commands as cmds
from conformance.tool_recorder import ToolRecorder

emulator = pytest.importorskip("conformance.emulator")
if not hasattr(emulator, "sim_sensor"):
    pytest.skip("conformance.emulator.sim_sensor is not there yet", allow_module_level=True)


@pytest.fixture
def master() -> ToolRecorder:
    _, link, _ = emulator.sim_sensor()
    return ToolRecorder(link)


def master_with(*faults: str) -> ToolRecorder:
    _, link, _ = emulator.sim_sensor(faults=faults)
    return ToolRecorder(link)


def single_attempts(*exchanges) -> bool:
    return all(ex.ok and len(ex.attempts) == 1 for ex in exchanges)


def test_identify_and_acknowledge(master):
    ack, ident = master.acknowledge(), master.identify()
    assert single_attempts(ack, ident)
    assert ident.reply_text[1:3].isdigit()


@pytest.mark.parametrize(
    "command",
    [cmds.measure("0"), cmds.measure("0", crc=True), cmds.concurrent("0"), cmds.verify("0")],
    ids=str,
)
def test_measurements_collect_every_value_first_time(master, command):
    m = master.measure(command)
    assert single_attempts(m.start, *m.data)
    assert m.count is not None and m.count >= 1
    assert m.complete and len(m.values) == m.count
    assert all(v[0] in "+-" for v in m.values)  # CRC stripped, split at signs


@pytest.mark.parametrize(
    "command", [cmds.high_volume_ascii("0"), cmds.high_volume_binary("0")], ids=str
)
def test_high_volume_if_supported(master, command):
    m = master.measure(command)
    assert m.start.ok
    if m.count == 0:
        pytest.skip(f"emulator profile does not support {command}")
    assert single_attempts(*m.data)
    assert m.complete


def test_foreign_address_stays_silent(master):
    master.acknowledge()
    probe = master.raw("9!")
    assert not probe.answered


# -- observer role: faulty sensors leave evidence, the engine still finishes -----------------
def test_wrong_crc_is_retried_every_time_and_collection_stops():
    m = master_with("wrong-crc").measure(cmds.measure("0", crc=True))
    assert m.start.ok and len(m.data) == 1
    assert len(m.data[0].attempts) == 9
    assert all("CRC" in a.reason for a in m.data[0].attempts)


def test_parity_error_triggers_retries():
    ex = master_with("parity-error").acknowledge()
    assert any(a.reason.startswith("invalid: parity error") for a in ex.attempts)


def test_missing_service_request_falls_back_to_break_at_ttt():
    m = master_with("no-service-request").measure(cmds.measure("0"))
    assert m.ttt and m.service_request_end is None
    d0 = m.data[0].attempts[0]
    assert d0.break_event is not None and d0.break_event.start >= m.reply_end + m.ttt
    assert m.complete


def test_late_service_request_is_evidence():
    m = master_with("late-service-request").measure(cmds.measure("0"))
    assert m.service_request_end is not None
    assert m.service_request_end > m.reply_end + m.ttt
    assert m.complete


def test_sensor_needing_the_full_wake_time_is_reached_by_the_late_retry():
    ex = master_with("slow-wake").acknowledge()
    assert ex.ok and [a.reason for a in ex.attempts] == ["no reply", "no reply", "ok"]
