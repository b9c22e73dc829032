"""The recorder role's machinery: played sensors, drivers, the session and the command line."""

from __future__ import annotations

import io
import os
import sys

import pytest

from conformance.cli import main
from conformance.judges.recorder.collection import judge_data_collection
from conformance.judges.recorder.measurements import observed_measurements
from conformance.ports import PortError
from conformance.protocol.commands import measure
from conformance.recorder.drivers import Interactive, RecorderDriverError, Trigger
from conformance.recorder.played import SensorSpec, Spoil
from conformance.recorder.scenario_runner import RecorderSession, check_port
from conformance.recorder_jobs import RecorderOutput, Request, Task
from conformance.sim.bus import SimBus, SimLink
from conformance.sim.line_monitor import LineMonitor
from conformance.tool_recorder import Policy, ToolRecorder
from conformance.transcript import to_wire_7e1
from conformance.verdicts import Verdict
from tests.support.shared_runs import copied_run


def _bus(spec: SensorSpec) -> ToolRecorder:
    bus = SimBus([LineMonitor(), spec.build()])
    return ToolRecorder(SimLink(bus), Policy.golden())


def test_unheard_sensor_answers_the_third_transmission():
    ex = _bus(SensorSpec(unheard=2)).transact("0!")
    assert [a.reason for a in ex.attempts] == ["no reply", "no reply", "ok"]


def test_garbled_sensor_spoils_one_reply_only():
    master = _bus(SensorSpec(spoil=Spoil("crc"), spoil_command="0D0!"))
    m = master.measure(measure("0", crc=True))
    first, second = m.data[0].attempts
    assert "should be" in first.reason and second.ok
    assert m.values == ["+22.15", "+1013.2", "+45.7"]
    master = _bus(SensorSpec(spoil=Spoil("parity"), spoil_command="0!"))
    assert [a.reason[:14] for a in master.transact("0!").attempts] == ["invalid: parit", "ok"]


def test_aborting_sensor_gives_an_empty_first_d0():
    master = _bus(SensorSpec(aborts_once=True))
    lost = master.measure(measure("0"))
    assert lost.data[0].reply_text == "0\r\n" and not lost.values
    again = master.measure(measure("0"))
    assert again.values == ["+22.15", "+1013.2", "+45.7"]


def test_session_runs_each_scenario_once_and_names_the_sensors():
    session = RecorderSession("sim")
    run = session.run("two-sensors")
    assert session.run("two-sensors") is run
    origins = {e.origin for e in run.events if e.kind == "char"}
    assert origins == {"tool", "sensor0", "sensor1"}
    assert run.output.logged["1M!"] == ["+22.15", "+1013.2", "+45.7"]


@pytest.mark.parametrize(
    "port",
    [
        "sim://?recorder-faults=nonsense",
        "sim://?recorder-faults=retry-too-early,retry-too-late",
        "COM9",
    ],
)
def test_unusable_recorder_ports_are_refused(port):
    with pytest.raises(PortError):
        check_port(port)


def test_external_recorders_need_a_real_time_bus():
    with pytest.raises(PortError, match="rfc2217-serve:"):
        check_port("sim", "true")
    with pytest.raises(PortError, match="rfc2217-serve:"):
        check_port("sim", "interactive")


def test_trigger_gets_the_request_and_keeps_its_output():
    request = Request(Task.MEASURE, ("0M!",))
    trigger = Trigger('echo "$SDI12_SCENARIO $SDI12_TASK $SDI12_COMMANDS"', timeout=10)
    out = trigger.act("service-request", request, None)  # type: ignore[arg-type]
    assert out.notes == ["service-request measure 0M!"]
    with pytest.raises(RecorderDriverError, match="exited with 5"):
        Trigger("exit 5").act("x", request, None)  # type: ignore[arg-type]
    with pytest.raises(RecorderDriverError, match="did not finish"):
        Trigger(f"{sys.executable} -c 'import time; time.sleep(5)'", timeout=0.2).act(
            "x",
            request,
            None,  # type: ignore[arg-type]
        )


def test_interactive_prompts_and_times_out():
    request = Request(Task.CONCURRENT, ("0C!", "1C!"))
    read_fd, write_fd = os.pipe()
    with os.fdopen(read_fd) as answers, os.fdopen(write_fd, "w") as operator:
        shown = io.StringIO()
        driver = Interactive(timeout=0.2, prompt_out=shown, answer_in=answers)
        with pytest.raises(RecorderDriverError, match="no answer"):
            driver.act("concurrent-two", request, None)  # type: ignore[arg-type]
        assert "start these concurrent measurements together" in shown.getvalue()
        operator.write("logged both\n")
        operator.flush()
        assert driver.act("concurrent-two", request, None).notes == ["logged both"]  # type: ignore[arg-type]


@pytest.mark.slow
def test_cli_recorder_role(tmp_path, tmp_path_factory):
    # the main command's runs, made once a session (tests/support/shared_runs.py): the clean
    # and short-break recorder runs are judged again in tests/commands/test_passive.py
    clean, code = copied_run(tmp_path_factory, tmp_path / "a", "sim", "recorder")
    assert code == 0
    assert (clean / "report.html").exists()
    _faulty, code = copied_run(
        tmp_path_factory, tmp_path / "b", "sim://?recorder-faults=short-break", "recorder"
    )
    assert code == 1
    assert main(["--port", "sim://?recorder-faults=bogus", "--role", "recorder"]) == 4
    assert main(["--port", "sim", "--role", "recorder", "--trigger", "true"]) == 4


class _GivesUpAtTheStopBit:
    """A recorder that sends a break and its first command, then ends its job at the stop
    bit, as HydroSense/SDI12's ``refresh()`` (a 15 ms timeout counted from queueing the
    command) made the seventeenth round's logger do (docs/kit.md)."""

    kind = "gives-up"
    needs_real_time = False

    def act(self, scenario, request, link, budget=None):
        link.bus.tool_break(0.0125)
        link.wait_until(link.now() + 0.009)
        for c in request.commands[0]:
            link.bus.tool_char(to_wire_7e1(ord(c)), link.now())
        return RecorderOutput()


def test_a_job_ended_before_the_reply_keeps_its_end_and_owes_no_values():
    """The session keeps when each job ended (``ScenarioRun.ended_at``, the view's
    ``ended_parts``): the played sensor's 000299 to 0C9!, begun after the recorder was done,
    starts no measurement it should have collected (R-4.4.8-05 FAILed it before)."""
    session = RecorderSession("sim", driver=_GivesUpAtTheStopBit())
    run = session.run("concurrent-99")
    sent = [e for e in run.events if e.kind == "char" and e.origin == "tool"]
    assert run.ended_at == pytest.approx(sent[-1].end)
    view = session.view("concurrent-99")
    assert view.ended_parts == {0: run.ended_at}
    assert any(e.origin == "sensor0" and e.start > run.ended_at for e in run.events)
    taken = observed_measurements(view, 0.0)
    assert taken == []
    assert judge_data_collection(taken)[0].verdict is not Verdict.FAIL
