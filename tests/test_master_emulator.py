"""The master engine against the reference emulator: a conforming sensor needs no retries,
and every announced value comes back. Skipped until ``conformance.emulator.sim_sensor`` exists."""

from __future__ import annotations

import pytest

from conformance.links.base import Link
from conformance.master import Master
from conformance.protocol import commands as cmds

emulator = pytest.importorskip("conformance.emulator")
if not hasattr(emulator, "sim_sensor"):
    pytest.skip("conformance.emulator.sim_sensor is not there yet", allow_module_level=True)


def _link_of(built: object) -> Link:
    """``sim_sensor()`` builds bus + link + emulator; find the link in what it returns."""
    if isinstance(built, Link):
        return built
    parts = list(built) if isinstance(built, tuple) else list(vars(built).values())
    return next(part for part in parts if isinstance(part, Link))


@pytest.fixture
def master() -> Master:
    return Master(_link_of(emulator.sim_sensor()))


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
