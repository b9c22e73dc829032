"""The harness link (``--port exec:`` / ``unix:``): exact verdicts through another process, and
every way a harness can fail (crash, hang, flood, garbage, early exit) ends as a bounded ERROR
with the harness's stderr tail, never a traceback, a hang, a verdict about the DUT, or a zombie.
"""

from __future__ import annotations

import os
import socket
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from conformance.conduct import run_once
from conformance.harness.channel import ChildChannel, HarnessError
from conformance.harness.device import open_sensor_harness
from conformance.harness.protocol import Role
from conformance.links.errors import PortUnavailable
from conformance.ports import open_port
from conformance.replay.sensor import RecordedSensor
from conformance.results import CaseRecord
from conformance.sim.bus import SENSOR_BREAK, SimBus, SimLink
from conformance.transcript import DUT, EventKind
from conformance.verdicts import Finding, Verdict
from tests.support.own_time import own_time
from tests.support.paths import ROOT

#: A sensor harness (the reference sensor) that misbehaves at message number ``AT``.
MISBEHAVING = textwrap.dedent(
    """
    import os, sys, time
    from pathlib import Path
    from conformance.emulator import SensorEmulator, default_profile

    MODE, AT = sys.argv[1], int(sys.argv[2])
    if len(sys.argv) > 3:
        Path(sys.argv[3]).write_text(str(os.getpid()))
    sensor = SensorEmulator(default_profile())

    def plan(now):
        f = sensor.next_frame()
        return "idle" if f is None else f"tx {max(round(f.start * 1e6), now)} {f.wire:02x}"

    for n, line in enumerate(sys.stdin):
        word, *fields = line.split()
        if n == AT:
            print(f"harness goes {MODE} at message {n}: {line.strip()}", file=sys.stderr)
            sys.stderr.flush()
            if MODE == "crash":
                os.abort()
            if MODE == "exit":
                sys.exit(0)
            if MODE == "hang":
                time.sleep(3600)
            if MODE == "flood":
                while True:
                    print("idle", flush=True)
            if MODE == "garbage":
                print("\\x00\\x7f\\x1b[31mGARBAGE", flush=True)
            if MODE == "twice":
                print("idle\\nidle", flush=True)
            if MODE == "late-extra":
                print("idle", flush=True)
                time.sleep(0.2)
                print("idle", flush=True)
            if MODE == "badbyte":
                print("tx 99999999 1b4", flush=True)
            continue
        if word == "hello":
            print("hello 1 misbehaving", flush=True)
            continue
        if word == "bye":
            if MODE == "after-bye":  # one answer too many: the stream was out of step
                time.sleep(0.2)
                print("idle", flush=True)
            break
        t = [int(x) for x in fields[:2]]
        if word == "break":
            sensor.on_break(t[0] / 1e6, t[1] / 1e6)
        elif word == "char":
            sensor.on_char(int(fields[2], 16), t[0] / 1e6, t[1] / 1e6)
        elif word == "sent":
            sensor.pop_frame()
        print(plan(t[-1]), flush=True)
    """
)


@pytest.fixture
def misbehaving(tmp_path: Path):
    script = tmp_path / "misbehaving.py"
    script.write_text(MISBEHAVING)

    def port(mode: str, at: int) -> tuple[str, Path]:
        pidfile = tmp_path / f"{mode}.pid"
        return f"exec:{sys.executable} {script} {mode} {at} {pidfile}", pidfile

    return port


def reaped(pidfile: Path) -> bool:
    """The harness process is gone: not running and not a zombie waiting to be collected."""
    pid = int(pidfile.read_text())
    return not Path(f"/proc/{pid}").exists()


@pytest.mark.slow
def test_the_python_example_sensor_is_compliant_with_exact_timing():
    data = run_once(f"exec:{sys.executable} {ROOT / 'examples/python/sensor_harness.py'}")
    assert data["summary"]["verdict"] == "COMPLIANT"
    counts = data["summary"]["counts"]
    assert counts["FAIL"] == counts["ERROR"] == counts["WARN"] == 0
    assert data["run"]["link"]["kind"] == "exec"
    # the one thing a harness link cannot see: the bit rate (the tool makes the frames)
    unsure = {r["id"]: r for r in data["requirements"] if r["verdict"] == "INCONCLUSIVE"}
    assert list(unsure) == ["R-4.1-01"]
    assert "bit rate is not observed" in unsure["R-4.1-01"]["findings"][0]["detail"]
    timed = [f for r in data["requirements"] for f in r["findings"] if f["measured_ms"] is not None]
    assert timed and all(f["uncertainty_ms"] == 0.0 for f in timed)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("mode", "at", "words"),
    [
        ("crash", 300, ["killed by signal SIGABRT", "harness goes crash at message 300"]),
        ("exit", 300, ["closed its output", "exit status 0", "harness goes exit"]),
        ("garbage", 300, ["not printable ASCII", "GARBAGE"]),
        ("twice", 300, ["more than one reply"]),
        # the flood is read with the answer (a reply too many) or before the next message
        ("flood", 300, ["more than one reply|unsolicited output", "idle"]),
        ("badbyte", 300, ["not two hex digits", "tx 99999999 1b4"]),
        # one answer late: caught by the next check, or the harness chokes on what follows
        ("late-extra", 300, ["unsolicited output|more than one reply|out of step|closed its"]),
    ],
)
def test_a_failing_harness_ends_the_run_with_an_error_not_a_verdict(misbehaving, mode, at, words):
    port, pidfile = misbehaving(mode, at)
    # a harness that fails must end the run, not leave it to time out reply after reply (5 s
    # each): held on the run's own time, a hang's blocked waits in full but not the time the
    # tool's thread stood in a run queue (this test failed at 43.7 s of wall at load 20)
    with own_time() as took:
        data = run_once(port)
    assert took.seconds < 30, f"{took.wall:.1f} s of wall, {took.queued:.1f} s of it queued"
    assert data["summary"]["verdict"] == "INCOMPLETE"
    assert data["run"]["complete"] is False
    reason = data["run"]["stop_reason"]
    assert reason.startswith("link failed: harness")
    for word in words:
        assert any(w in reason for w in word.split("|")), reason
    counts = data["summary"]["counts"]
    assert counts["FAIL"] == 0  # never a verdict about the DUT
    assert reaped(pidfile)


@pytest.mark.parametrize("held", [0.0, 1.5])
def test_answers_out_of_step_are_caught_when_the_harness_ends(tmp_path: Path, held: float):
    """A line written unasked while the tool already waits for the next answer is taken as
    that answer, and the stream is one line late from then on; no single line shows it. The
    end does: an answer arrives after ``bye``, and the records are not trusted.

    The harness writes each late line once the tool's next message is in its input (select),
    not after a sleep: a tool held longer than the sleep (a busy machine) found the line
    before sending, an "unsolicited output", a right answer to another interleaving. The
    last one comes ``held`` s after ``bye`` (a harness a busy machine held): the tool waits
    for it as for any answer, up to the reply timeout (30 s here, so that no load decides);
    it used to stop after 1 s and trusted the records."""
    script = tmp_path / "late.py"
    script.write_text(
        textwrap.dedent(
            """
            import os, select, sys, time

            def line():  # a byte at a time: no message waits in a buffer select cannot see
                got = b""
                while not got.endswith(b"\\n") and (byte := os.read(0, 1)):
                    got += byte
                return got

            def sent_next():  # the tool's next message has arrived (not read yet)
                select.select([0], [], [])

            print("hello 1 late", flush=True) if line() else None
            line()
            print("idle", flush=True)
            sent_next()
            print("idle", flush=True)  # unasked: written before the message it answers is read
            line()
            sent_next()
            time.sleep(float(sys.argv[1]))
            print("tx 99 30", flush=True)  # the real answer, one line late: after bye
            line()
            """
        )
    )
    channel = ChildChannel(f"{sys.executable} {script} {held}", reply_timeout=30.0)
    channel.greet(Role.SENSOR)
    assert channel.ask("time 1") == "idle"
    assert channel.ask("time 2") == "idle"  # the unasked line, read as the answer
    with pytest.raises(HarnessError, match="out of step"):
        channel.finish("bye")
    assert channel.proc.returncode is not None


@pytest.mark.parametrize("then", ["sleep", "flood"])
def test_a_harness_that_stops_reading_never_holds_the_tool_in_a_write(tmp_path: Path, then):
    """A harness that answers hello, then reads no more (asleep, or flooding its output,
    which fills its own pipe): the tool's messages fill the harness's input, and a plain
    write would wait for ever (a CI run hung on a flood harness in lockstep). Every write
    waits at most the reply timeout, and output written meanwhile is a reply too many.
    The flooding harness gets a long reply timeout (30 s): with 0.5 s, a harness a busy
    machine held past it before its flood began was called not reading ("has not read its
    input": right, but not the flood), and which reason came depended on the load (CI-like
    stress: nice 19 beside two CPU burners, 1 of 1 round); now the flood is always what is
    named, and the write still ends at once when it comes (the bound below)."""
    script = tmp_path / "deaf.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys, time
            sys.stdin.readline()
            print("hello 1 deaf", flush=True)
            time.sleep(60 if {then!r} == "sleep" else 0.3)  # the tool fills the input meanwhile
            while True:
                sys.stdout.write("idle\\n" * 2000)
                sys.stdout.flush()
            """
        )
    )
    timeout = 0.5 if then == "sleep" else 30.0
    channel = ChildChannel(f"{sys.executable} {script}", reply_timeout=timeout)
    channel.greet(Role.SENSOR)
    outcome: list[BaseException] = []

    def fill() -> None:
        try:
            for n in range(100_000):  # ~3 MB: far beyond any pipe's buffer
                channel.send(f"time {n:020d}")  # never answered: the harness is not reading
        except BaseException as exc:  # noqa: BLE001 - handed to the test's thread
            outcome.append(exc)

    worker = threading.Thread(target=fill, daemon=True)
    started = time.monotonic()
    worker.start()
    worker.join(10)
    try:
        assert not worker.is_alive(), "the tool is stuck writing to a harness that stopped reading"
        assert time.monotonic() - started < 5
        assert outcome and isinstance(outcome[0], HarnessError), outcome
        # the flood is read while the tool waits to write (a reply too many), or, when the
        # tool's writer had not filled the pipe yet, before its next message (unsolicited)
        expected = ["has not read its input"] if then == "sleep" else [
            "more than one reply", "unsolicited output"
        ]  # fmt: skip
        assert any(e in str(outcome[0]) for e in expected), outcome[0]
    finally:
        channel.close()


def test_a_run_whose_harness_fell_out_of_step_is_incomplete(misbehaving):
    """The same at run level: verdicts are not drawn from records read out of step."""
    port, pidfile = misbehaving("after-bye", 10**9)
    data = run_once(port, keyword="acknowledge")
    assert data["summary"]["verdict"] == "INCOMPLETE"
    assert "out of step" in data["run"]["stop_reason"]
    assert reaped(pidfile)


@pytest.mark.slow
def test_a_hung_harness_is_stopped_after_the_reply_timeout(misbehaving):
    port, pidfile = misbehaving("hang", 40)
    link = open_sensor_harness(port, reply_timeout=0.5)
    started = time.monotonic()
    with pytest.raises(HarnessError) as caught:
        for _ in range(20):
            link.send_break(0.0125)
            link.write(b"0!")
            link.receive(link.now() + 0.1)
    assert time.monotonic() - started < 5
    message = str(caught.value)
    assert "no reply within 0.5 s" in message and "harness goes hang" in message
    assert "killed by signal SIGTERM" in message
    link.close()
    assert reaped(pidfile)


def test_a_harness_that_never_answers_hello_is_a_usage_error(tmp_path: Path):
    script = tmp_path / "silent.py"
    script.write_text("import sys\nprint('starting up', file=sys.stderr)\nsys.exit(2)\n")
    with pytest.raises(PortUnavailable) as caught:
        open_port(f"exec:{sys.executable} {script}")
    assert "exit status 2" in str(caught.value) and "starting up" in str(caught.value)


def test_a_missing_program_is_a_usage_error(tmp_path: Path):
    with pytest.raises(PortUnavailable, match="cannot start harness"):
        open_port(f"exec:{tmp_path / 'no-such-harness'}")
    with pytest.raises(PortUnavailable, match="needs a program"):
        open_port("exec:")


def test_the_harness_is_reaped_after_a_clean_run(misbehaving):
    port, pidfile = misbehaving("never", 10**9)
    link = open_sensor_harness(port)
    link.send_break(0.0125)
    link.wait(0.009)
    link.write(b"0!")  # "0!"
    reply = link.receive(link.now() + 0.1, idle=0.02)
    assert bytes(e.wire & 0x7F for e in reply) == b"0\r\n"
    link.close()
    assert link.device.channel.proc.returncode == 0
    assert reaped(pidfile)


def test_a_unix_socket_harness(tmp_path: Path):
    """``unix:PATH``: the same protocol from a program that listens on a socket."""
    path = str(tmp_path / "h.sock")
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(path)
    server.listen(1)
    seen: list[str] = []

    def serve() -> None:
        conn, _ = server.accept()
        with conn, conn.makefile("rw") as stream:
            for line in stream:
                seen.append(line.strip())
                if line.startswith("bye"):
                    return
                answer = "hello 1 socket" if line.startswith("hello") else "idle"
                if line.startswith("char") and line.split()[3] == "21":  # '!': answer '0'
                    end = int(line.split()[2])
                    answer = f"tx {end + 9000} 30"
                stream.write(answer + "\n")
                stream.flush()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    link = open_port(f"unix:{path}").link
    link.send_break(0.0125)
    link.wait(0.009)
    events = link.write(b"0!")
    got = link.receive(link.now() + 0.1, idle=0.02)
    link.close()
    thread.join(timeout=5)
    server.close()
    assert [chr(e.wire & 0x7F) for e in got] == ["0"]
    assert got[0].start == pytest.approx(events[-1].end + 9e-3, abs=1e-6)
    assert seen[0] == "hello 1 sensor" and seen[1] == "break 0 12500" and seen[-1] == "bye"
    assert link.info.kind == "unix" and link.info.timing_uncertainty == 0.0


def test_no_harness_process_outlives_the_tests():
    """No zombie children of this process (a zombie is a child never waited for)."""
    mine = str(os.getpid())
    zombies = []
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            fields = dict(
                line.split(":\t", 1) for line in status.read_text().splitlines() if ":\t" in line
            )
        except OSError:
            continue
        if fields.get("PPid", "").strip() == mine and fields.get("State", "").startswith("Z"):
            zombies.append(status.parent.name)
    assert not zombies


def test_a_crashing_recorder_harness_ends_the_run_with_an_error(tmp_path: Path):
    """Recorder role: the harness breaks the line, then crashes; the run stops with an ERROR
    naming the crash and the stderr tail, and the process is reaped."""
    script = tmp_path / "crashing-recorder.py"
    pidfile = tmp_path / "recorder.pid"
    script.write_text(
        textwrap.dedent(
            f"""
            import os, sys
            from pathlib import Path
            Path({str(pidfile)!r}).write_text(str(os.getpid()))
            for line in sys.stdin:
                word, *fields = line.split()
                if word == "hello":
                    print("hello 1 crashing-recorder", flush=True)
                elif word == "job":
                    now = int(fields[0])
                    print(f"brk {{now}} {{now + 12500}}", flush=True)
                else:
                    print("recorder firmware assertion failed", file=sys.stderr, flush=True)
                    os.abort()
            """
        )
    )
    data = run_once(f"exec:{sys.executable} {script}", role="recorder")
    assert data["summary"]["verdict"] == "INCOMPLETE"
    reason = data["run"]["stop_reason"]
    assert "SIGABRT" in reason and "recorder firmware assertion failed" in reason
    assert data["summary"]["counts"]["FAIL"] == 0
    assert reaped(pidfile)


@pytest.mark.slow
def test_a_unix_socket_recorder_harness_is_judged_per_scenario(tmp_path: Path):
    """``--role recorder --port unix:PATH``: the tool connects afresh for each scenario; here
    the golden recorder serves each connection through the Python client."""
    from conformance.harness.client import serve_recorder
    from conformance.recorder.faults import faulty_recorder

    path = str(tmp_path / "recorder.sock")
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(path)
    server.listen(4)
    served: list[int] = []

    def serve() -> None:
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return  # closed: the run is over
            with conn, conn.makefile("r") as inp, conn.makefile("w") as out:
                served.append(serve_recorder(faulty_recorder(()), inp, out))

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        data = run_once(f"unix:{path}", role="recorder")
    finally:
        server.close()
    assert data["summary"]["verdict"] == "COMPLIANT", data["summary"]
    assert data["run"]["link"]["kind"] == "unix"
    assert len(served) >= 10 and set(served) == {0}  # the probe, then one per scenario


def test_fails_recorded_through_a_harness_that_failed_are_not_trusted(misbehaving):
    """A harness that fails may have been out of step before it showed, so a FAIL recorded
    through it becomes INCONCLUSIVE (saying why) and the run is INCOMPLETE, never
    NON-COMPLIANT because of the harness; PASS and N/A stay (no overall verdict rests on
    them: the run is incomplete)."""
    port, pidfile = misbehaving("after-bye", 10**9)
    link = open_sensor_harness(port)
    record = CaseRecord("t::x", "x", ("R-4.4.6-02", "R-4.4.1-01"))
    record.findings = [
        Finding("R-4.4.6-02", Verdict.FAIL, "no service request", observed=1, evidence=["0M!"]),
        Finding("R-4.4.1-01", Verdict.PASS, "a! answered", observed=1),
    ]
    record.summarise()
    link.send_break(0.0125)
    with pytest.raises(HarnessError, match="out of step"):
        link.check_records([record])
    assert [f.verdict for f in record.findings] == [Verdict.INCONCLUSIVE, Verdict.PASS]
    assert record.findings[0].detail.startswith("not trusted, the harness failed")
    assert record.verdict is Verdict.INCONCLUSIVE
    assert reaped(pidfile)


WAITS = textwrap.dedent(
    """
    import sys
    log = open(sys.argv[1], "w")
    for line in sys.stdin:
        log.write(line)
        log.flush()
        word = line.split()[0]
        if word == "hello":
            print("hello 1 waiter", flush=True)
        elif word == "char":
            print("wait 20000", flush=True)  # nothing to send before 20 ms: wake me then
        elif word != "bye":
            print("idle", flush=True)
    """
)


def test_a_harness_is_not_woken_inside_the_tools_break(tmp_path):
    """A ``wait`` due inside the tool's break is answered by the break's message (told when
    it ends), never by a ``time`` that says nothing happened until then: that let a service
    request due at that time go out over the break, and a kit's sketch run past its start."""
    script, log = tmp_path / "waits.py", tmp_path / "messages.txt"
    script.write_text(WAITS)
    link = open_sensor_harness(f"exec:{sys.executable} {script} {log}")
    try:
        link.write(bytes([0x30]))  # 0 .. 8333 us: answered "wait 20000"
        link.wait_until(0.015)
        link.send_break(0.013)  # 15 ms .. 28 ms: the wake-up at 20 ms falls inside it
        link.receive(link.now() + 0.005)
    finally:
        link.close()
    told = [line.split()[0] for line in log.read_text().splitlines()]
    assert told[:3] == ["hello", "char", "break"], told
    assert "time" not in told, told


PAST_TX = textwrap.dedent(
    """
    import sys
    for line in sys.stdin:
        word, *fields = line.split()
        if word == "hello":
            print("hello 2 runs-ahead", flush=True)  # version 2: held to the clock
        elif word == "char":
            print(f"tx {int(fields[1]) - 1000} 30 8330", flush=True)  # a reply in the past
        elif word != "bye":
            print("idle", flush=True)
    """
)


def test_a_version_2_harness_answering_in_the_past_is_an_error_naming_the_line(tmp_path):
    """A harness whose device ran ahead of the tool's clock plans its reply 1 ms before the
    message it answers: an ERROR quoting that line, never a reply moved to "now" and judged."""
    script = tmp_path / "past.py"
    script.write_text(PAST_TX)
    link = open_sensor_harness(f"exec:{sys.executable} {script}")
    try:
        assert link.info.bit_timing and link.info.frame_lengths
        link.write(bytes([0x30]))
        with pytest.raises(HarnessError, match="wait for the line to be idle") as err:
            link.receive(link.now() + 0.05)
        assert "'tx 7333 30 8330'" in str(err.value)
    finally:
        link.close()


SENSOR_BRK = textwrap.dedent(
    """
    import sys
    log = open(sys.argv[1], "w")
    for line in sys.stdin:
        log.write(line)
        log.flush()
        word, *fields = line.split()
        if word == "hello":
            print("hello 1 breaks-first", flush=True)
        elif word == "char" and fields[2] == "21":  # '!': hold the line 12.1 ms, 8.4 ms on
            end = int(fields[1])
            print(f"brk {end + 8400} {end + 8400 + 12100}", flush=True)
        elif word == "break" and int(fields[1]) > 0:  # its own, told back: '0' CR LF
            print(f"tx {int(fields[1]) + 8400} 30", flush=True)
        elif word == "sent" and fields[2] != "0a":
            print(f"tx {fields[1]} {'8d' if fields[2] == '30' else '0a'}", flush=True)
        elif word != "bye":
            print("idle", flush=True)
    """
)


def test_a_sensor_harness_may_hold_the_line_spacing_before_its_reply(tmp_path):
    """``brk`` from a sensor harness (the protocol's extension; before, "'brk' is for
    recorder harnesses only", an ERROR and no verdict): the break goes in the transcript
    as the sensor's (origin DUT, :data:`SENSOR_BREAK`), where the harness put it, the
    harness is told it back as ``break S E`` as a recorder is, and the reply after it is
    read as the tool's characters; the break itself is no character of the reply."""
    script, log = tmp_path / "brk.py", tmp_path / "messages.txt"
    script.write_text(SENSOR_BRK)
    link = open_sensor_harness(f"exec:{sys.executable} {script} {log}")
    try:
        sent = link.write(bytes([0x30, 0x21]))
        got = link.receive(link.now() + 0.1)
    finally:
        link.close()
    end = sent[-1].end
    assert [e.wire for e in got] == [0x30, 0x8D, 0x0A]
    breaks = [e for e in link.transcript.events if e.kind is EventKind.BREAK]
    assert [(b.origin, b.text) for b in breaks] == [(DUT, SENSOR_BREAK)]
    assert breaks[0].start == pytest.approx(end + 8400e-6, abs=1e-6)
    assert breaks[0].duration == pytest.approx(12100e-6, abs=1e-6)
    assert got[0].start == pytest.approx(breaks[0].end + 8400e-6, abs=1e-6)
    told = [line.split() for line in log.read_text().splitlines()]
    assert ["break", str(round(breaks[0].start * 1e6)), str(round(breaks[0].end * 1e6))] in told


def test_a_sensors_break_is_replayed_where_it_was_recorded(tmp_path):
    """A saved run's replay plays the sensor's break too (``judge``/``verify`` of the run):
    before, the replay offered the reply characters alone, the break was gone from the
    replayed line, and R-7.0-09 came out other than recorded (verify: 17 problems on the
    twenty-fifth round's AgriApps run)."""
    script = tmp_path / "brk.py"
    script.write_text(SENSOR_BRK)
    link = open_sensor_harness(f"exec:{sys.executable} {script} {tmp_path / 'log.txt'}")
    try:
        link.send_break(0.0125)
        link.wait_until(link.now() + 0.009)
        link.write(b"0!")
        link.receive(link.now() + 0.1)
    finally:
        link.close()
    recorded = [e for e in link.transcript.events if e.kind is not EventKind.NOTE]
    replay = SimLink(SimBus([RecordedSensor(recorded)]))
    replay.send_break(0.0125)
    replay.wait_until(replay.now() + 0.009)
    replay.write(b"0!")
    replay.receive(replay.now() + 0.1)
    again = [e for e in replay.transcript.events if e.kind is not EventKind.NOTE]
    assert [(e.kind, e.origin, e.start, e.end, e.wire, e.text) for e in again] == [
        (e.kind, e.origin, e.start, e.end, e.wire, e.text) for e in recorded
    ]
    assert any(e.kind is EventKind.BREAK and e.origin == DUT for e in again)
