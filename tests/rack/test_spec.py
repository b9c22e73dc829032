"""A rack's DUTs from the command line and from a rack file; every mistake in a rack file is
one line naming the file (a usage error before any worker starts)."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance.rack.spec import (
    LOCAL_TX,
    RackError,
    default_name,
    duts_from_ports,
    expand_tx,
    load_rack_file,
)


def _rack(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "rack.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_ports_make_one_dut_each_named_by_place_and_port():
    duts = duts_from_ports(["sim", "sim://?faults=wrong-crc", "rfc2217://127.0.0.1:4001"])
    assert [d.name for d in duts] == ["1-sim", "2-sim", "3-rfc2217-127.0.0.1-4001"]
    assert [d.port for d in duts] == ["sim", "sim://?faults=wrong-crc", "rfc2217://127.0.0.1:4001"]
    assert {d.tx for d in duts} == {LOCAL_TX}
    assert all(d.role is None and d.address is None and d.declaration is None for d in duts)


def test_tx_specs_are_read_as_xdist_reads_them_and_given_in_turn():
    assert expand_tx(["2*popen", "ssh=pi@bench2//python=/opt/x/bin/python"]) == [
        "popen", "popen", "ssh=pi@bench2//python=/opt/x/bin/python",
    ]  # fmt: skip
    duts = duts_from_ports(["sim"] * 3, ["popen", "ssh=pi@bench2"])
    assert [d.tx for d in duts] == ["popen", "ssh=pi@bench2", "popen"]


@pytest.mark.parametrize("spec", ["", "nothing", "chdir=/tmp"])
def test_a_tx_spec_naming_no_worker_is_refused(spec):
    with pytest.raises(RackError, match="--tx"):
        duts_from_ports(["sim", "sim"], [spec])


def test_a_rack_file_names_ports_roles_declarations_names_and_workers(tmp_path):
    (tmp_path / "decl").mkdir()
    (tmp_path / "decl" / "bay1.toml").write_text('address = "3"\n', encoding="utf-8")
    path = _rack(
        tmp_path,
        """
tx = "popen"
[[dut]]
name = "bay1"
port = "sim://?address=3"
declaration = "decl/bay1.toml"
address = "3"
[[dut]]
port = "sim"
role = "recorder"
tx = "ssh=pi@bench2//python=/opt/sdi12/bin/python"
""",
    )
    bay1, second = load_rack_file(path)
    assert bay1.name == "bay1" and bay1.address == "3" and bay1.tx == "popen"
    assert bay1.declaration == str((tmp_path / "decl" / "bay1.toml").resolve())  # the file's
    assert second.name == "2-sim" and second.role == "recorder"
    assert second.tx == "ssh=pi@bench2//python=/opt/sdi12/bin/python"  # its own beats the rack's
    (only,) = load_rack_file(_rack(tmp_path, '[[dut]]\nport = "sim"\n'), ["socket=h:8888"])
    assert only.tx == "socket=h:8888"  # the command line's --tx


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("[[dut]\nport = 'sim'\n", "line 1"),  # TOML syntax
        ("", "no DUT to run"),
        ("[[dut]]\nname = 'a'\n", "dut 1: no port"),
        ("[[dut]]\nport = 'sim'\nspeed = 9600\n", "unknown key(s) speed"),
        ("ports = ['sim']\n", "unknown key(s) ports"),
        ("[[dut]]\nport = 5\n", "port must be a non-empty string"),
        ("[[dut]]\nport = 'sim'\nrole = 'logger'\n", "role must be one of sensor, recorder"),
        ("[[dut]]\nport = 'sim'\nname = 'a/b'\n", "name 'a/b' must be letters"),
        ("[[dut]]\nport = 'sim'\nname = 'rack.json'\n", "may not be named 'rack.json'"),
        ("[[dut]]\nport='sim'\nname='x'\n[[dut]]\nport='sim'\nname='x'\n", "two DUTs are named"),
        ("dut = 'sim'\n", "array of tables"),
        ("tx = 3\n[[dut]]\nport = 'sim'\n", "tx must be a string or a list"),
        ("[[dut]]\nport = 'sim'\ntx = 'bogus'\n", "names no worker"),
    ],
)
def test_every_mistake_in_a_rack_file_is_one_line_naming_it(tmp_path, text, says):
    path = _rack(tmp_path, text)
    with pytest.raises(RackError) as caught:
        load_rack_file(path)
    message = str(caught.value)
    assert says in message and str(path) in message and "\n" not in message


def test_a_missing_rack_file_is_a_usage_error(tmp_path):
    with pytest.raises(RackError, match="No such file"):
        load_rack_file(tmp_path / "none.toml")


def test_a_default_name_is_a_folder_name():
    assert default_name(7, "exec:./dev --fast") == "7-exec-.-dev-fast"
    assert default_name(1, "???") == "1-port"


def test_one_port_is_one_dut_on_a_host_but_sim_ports_and_other_hosts_repeat():
    assert len(duts_from_ports(["sim", "sim", "sim"])) == 3  # three simulated sensors
    with pytest.raises(RackError, match="both name port '/dev/ttyUSB0'"):
        duts_from_ports(["/dev/ttyUSB0", "/dev/ttyUSB0"])
    on_two_hosts = duts_from_ports(["/dev/ttyUSB0"] * 2, ["ssh=bench1", "ssh=bench2"])
    assert [d.tx for d in on_two_hosts] == ["ssh=bench1", "ssh=bench2"]
