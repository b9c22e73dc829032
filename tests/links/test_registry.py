"""The registry of link kinds (``conformance.links.registry``): which kind a port string
names, which roles each kind opens in, and the user's timing uncertainty applied where a port
opens (issue 21: one port dispatcher)."""

from __future__ import annotations

import pytest

from conformance.ports import PortError, open_port


def test_every_link_kind_claims_its_example_and_the_rest_are_serial_devices():
    from conformance.links.registry import find, kinds

    registered = {k.name for k in kinds()}
    assert {"sim", "replay", "exec", "unix", "adapter", "rfc2217", "socket", "loop"} <= registered
    assert {"serial", "rfc2217-serve"} <= registered
    for kind in kinds():
        assert find(kind.example) is kind
        assert kind.info.kind == kind.name
    for device in ("COM3", "/dev/ttyUSB0", "spy:///dev/ttyUSB0", "hwgrep://0403:6001", "SIM"):
        assert find(device).name == "serial"


def test_a_sole_kinds_port_strings_are_claimed_by_no_other_kind():
    """A sole kind is looked up without loading the deferred kinds (a ``--port sim`` run
    imports no serial, harness or capture module): right only while no other kind claims a
    string it claims, which the full look-up would refuse as a double claim."""
    from conformance.links.registry import find, kinds

    sole = [k for k in kinds() if k.sole]
    assert {k.name for k in sole} == {"sim", "replay", "rfc2217-serve"}
    ports = {
        "sim": ["sim", "sim:", "sim://?faults=wrong-crc", "sim://?sensors=0,1:no-crc"],
        "replay": ["replay:run", "replay:/tmp/x y", "replay:"],
        "rfc2217-serve": ["rfc2217-serve://127.0.0.1:0", "rfc2217-serve://h:4001?x=1"],
    }
    for kind in sole:
        for port in [kind.example, *ports[kind.name]]:
            assert kind.matches(port)
            others = [
                k.name for k in kinds() if k is not kind and not k.fallback and k.matches(port)
            ]
            assert not others, f"{port!r} is claimed by {kind.name} and {others}"
            assert find(port) is kind


def test_a_sim_port_is_found_without_the_deferred_kinds():
    """In a fresh process ``open_port('sim')`` leaves the deferred kinds unloaded; the table
    read whole (``kinds()``) loads them, and a port no sole kind claims does too."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from conformance.ports import open_port\n"
        "from conformance.links import registry\n"
        "open_port('sim').link.close()\n"
        "print('conformance.links.factory' in sys.modules, 'serial' in sys.modules)\n"
        "print(registry.find('loop://').name, 'conformance.links.factory' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert done.stdout.split() == ["False", "False", "loop", "True"], done.stdout + done.stderr


def test_each_kind_opens_in_the_roles_it_serves_and_names_the_others():
    """One dispatcher: the registry says which kinds open in which role; a port of the wrong
    role is refused with what to write instead, before anything goes on a bus."""
    from conformance.links.registry import PortOptions, kinds
    from conformance.recorder.openers import open_recorder_line

    recorder_side = {k.name for k in kinds() if k.open_recorder_role is not None}
    assert recorder_side == {"sim", "exec", "unix", "replay", "rfc2217-serve"}
    assert {k.name for k in kinds() if k.open_sensor_role is None} == {"rfc2217-serve"}
    with pytest.raises(PortError, match="cannot judge a sensor: it serves played sensors"):
        open_port("rfc2217-serve://127.0.0.1:0")
    with pytest.raises(PortError, match="plays the sensors itself") as refused:
        open_recorder_line("loop://", PortOptions(), None)
    for hint in ("--port sim", "exec:PROGRAM", "unix:PATH", "replay:FOLDER", "rfc2217-serve://"):
        assert hint in str(refused.value)


def test_the_users_timing_uncertainty_is_applied_where_the_port_opens_and_only_widens():
    from conformance.links.registry import PortOptions
    from conformance.recorder.openers import open_recorder_line

    assert open_port("sim").link.timing_uncertainty() == 0.0
    assert open_port("sim", timing_uncertainty=2e-3).link.timing_uncertainty() == 2e-3
    recorder = open_recorder_line("sim", PortOptions(timing_uncertainty=3e-3), None)
    assert recorder.link.timing_uncertainty() == 3e-3
    loop = open_port("loop://", timing_uncertainty=1e-9).link
    try:  # a figure below what the interface declares leaves the declared one
        assert loop.timing_uncertainty() == loop.info.timing_uncertainty > 1e-9
    finally:
        loop.close()
