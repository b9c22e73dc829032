"""The transparent-adapter link, against a fake adapter in front of the reference emulator.

The fake is a loopback TCP server that behaves like a USB SDI-12 adapter in transparent mode:
it reads a command line, makes the break and sends the command on an in-process ``SimBus``
whose virtual clock follows real time, and writes back the sensor's reply line once the
sensor has finished it (paced like the real bus), dropping anything unsolicited.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from conformance.emulator import sim_sensor
from conformance.links.adapter_link import AdapterLink, parse_adapter_port
from conformance.links.errors import BreakUnsupported
from conformance.links.factory import open_real_link
from conformance.transcript import DUT, TOOL, EventKind, decode_7e1, to_wire_7e1

BREAK = 12.5e-3
MARKING = 8.5e-3
REPLY_WAIT = 0.1  # s of bus time: no first character by then means no reply


class FakeAdapter:
    """An adapter on ``127.0.0.1:port`` in front of the emulator (with ``faults``)."""

    def __init__(self, faults: tuple[str, ...] = ()) -> None:
        self.bus, _link, self.emulator = sim_sensor(faults=faults)
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.listener.settimeout(0.1)
        self.port = self.listener.getsockname()[1]
        self.stop = threading.Event()
        self.commands: list[str] = []
        self.t0 = time.perf_counter()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    @property
    def url(self) -> str:
        return f"adapter+socket://127.0.0.1:{self.port}"

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=2)

    def _serve(self) -> None:
        with self.listener:
            while not self.stop.is_set():
                try:
                    conn, _ = self.listener.accept()
                except TimeoutError:
                    continue
                with conn:
                    self._talk(conn)

    def _talk(self, conn: socket.socket) -> None:
        conn.settimeout(0.05)
        buffer = b""
        while not self.stop.is_set():
            try:
                data = conn.recv(4096)
            except TimeoutError:
                continue
            except OSError:
                return
            if not data:
                return
            buffer += data
            while b"\r" in buffer:
                line, buffer = buffer.split(b"\r", 1)
                reply = self._exchange(line.decode("ascii", "replace"))
                if reply:
                    try:
                        conn.sendall(reply)
                    except OSError:
                        return

    def _exchange(self, command: str) -> bytes:
        """Break, command, and the reply line, on a bus clock that follows real time."""
        self.commands.append(command)
        bus = self.bus
        real_start = time.perf_counter()
        bus.advance(max(real_start - self.t0, bus.clock.now))
        bus.rx.clear()  # service requests and other unsolicited bytes: not passed on
        bus.tool_break(BREAK)
        bus.advance(bus.clock.now + MARKING)
        at = bus.clock.now
        for char in command:
            at = bus.tool_char(to_wire_7e1(ord(char)), at).end
        reply = bytearray()
        limit = at + REPLY_WAIT
        while (event := bus.step(limit)) is not None:
            reply.append(event.wire & 0x7F)
            limit = event.end + REPLY_WAIT / 4
            if reply.endswith(b"\r\n"):
                break
        bus.rx.clear()
        # the line is handed over when the sensor finished it on the (virtual) bus
        time.sleep(max(0.0, self.t0 + bus.clock.now - time.perf_counter()))
        return bytes(reply)


@pytest.fixture
def adapter():
    fake = FakeAdapter()
    yield fake
    fake.close()


def test_port_strings_parse_into_url_and_options():
    spec = parse_adapter_port("adapter:///dev/ttyUSB0?baud=19200&eol=crlf&timeout=0.5")
    assert (spec.url, spec.baud, spec.eol, spec.timeout) == ("/dev/ttyUSB0", 19200, b"\r\n", 0.5)
    spec = parse_adapter_port("adapter+socket://127.0.0.1:4001?wake=5&logging=debug")
    assert spec.url == "socket://127.0.0.1:4001?logging=debug"
    assert spec.wake == pytest.approx(5e-3)
    assert parse_adapter_port("adapter:COM3").url == "COM3"
    with pytest.raises(ValueError):
        parse_adapter_port("adapter:///dev/ttyUSB0?eol=tab")
    with pytest.raises(ValueError):
        parse_adapter_port("adapter:COM3?bogus=1")


@pytest.mark.realtime
def test_exchange_through_the_adapter_and_no_break(adapter):
    link = open_real_link(adapter.url)
    try:
        assert isinstance(link, AdapterLink)
        assert (link.info.kind, link.info.can_break, link.info.passes_unsolicited) == (
            "adapter",
            False,
            False,
        )
        assert link.info.timing_uncertainty >= 0.05
        with pytest.raises(BreakUnsupported):
            link.send_break(0.013)
        assert any(e.kind is EventKind.NOTE for e in link.transcript.events)
        # one exchange first: the timed one below must not pay the adapter thread's first
        # wake-up (CI runs this test first after minutes of CPU-heavy matrices)
        warm = link.write(bytes(to_wire_7e1(ord(c)) for c in "0!"))
        link.receive(warm[-1].end + 1.0, until=lambda chars: chars[-1].wire & 0x7F == 10)
        sent = link.write(bytes(to_wire_7e1(ord(c)) for c in "0I!"))
        started = time.perf_counter()
        first = link.receive(sent[-1].end + 0.03, until=lambda chars: True)
        assert len(first) == 1  # the first character starts within the bus deadline
        rest = link.receive(sent[-1].end + 1.0, until=lambda chars: chars[-1].wire & 0x7F == 10)
        got = first + rest
        assert time.perf_counter() - started < 1.5  # bounded, even though the line is late
        assert decode_7e1(got).startswith("014")
        assert decode_7e1(got).endswith("\r\n")
        assert all(e.origin == DUT and e.parity_ok for e in got)
        assert all(e.origin == TOOL for e in sent)
        assert got[0].start >= sent[-1].end  # the reply never starts before the command ends
        assert adapter.commands == ["0!", "0I!"]
        # a command nobody answers costs the timeout, not more
        sent = link.write(bytes(to_wire_7e1(ord(c)) for c in "5I!"))
        started = time.perf_counter()
        assert link.receive(sent[-1].end + 0.03) == []
        assert time.perf_counter() - started < link.spec.timeout + 0.5
    finally:
        link.close()


def _run_cli(url: str, report_dir: Path, *extra: str) -> tuple[int, dict]:
    proc = subprocess.run(
        [sys.executable, "-m", "conformance.cli", "--port", url, "--report-dir", str(report_dir)]
        + list(extra),
        capture_output=True,
        text=True,
        timeout=120,
    )
    verdicts_path = report_dir / "verdicts.json"
    assert verdicts_path.exists(), proc.stdout[-2000:] + proc.stderr[-2000:]
    return proc.returncode, json.loads(verdicts_path.read_text())


def _verdicts(doc: dict) -> dict[str, str]:
    return {r["id"]: r["verdict"] for r in doc["requirements"]}


#: quick cases: protocol-level (a!, aI!, ?!), a break case and a timing case
SELECTION = (
    "acknowledge_active or identification or query_address or short_spacing"
    " or response_start_window"
)


@pytest.mark.realtime
def test_cli_judges_protocol_level_requirements_through_the_adapter(adapter, tmp_path):
    code, doc = _run_cli(adapter.url, tmp_path, "-k", SELECTION)
    verdicts = _verdicts(doc)
    assert doc["run"]["link"]["kind"] == "adapter"
    for rid in ("R-4.4.1-01", "R-4.4.2-01", "R-4.4.3-01"):
        assert verdicts[rid] == "PASS", rid
    assert not [r for r in doc["requirements"] if r["verdict"] in ("FAIL", "ERROR")]
    assert code == 0  # nothing failed in what the -k selection judged (a partial run)
    assert doc["run"]["partial"] is True
    details = {r["id"]: " ".join(f["detail"] for f in r["findings"]) for r in doc["requirements"]}
    assert verdicts["R-7.0-03"] == "INCONCLUSIVE"  # a break case
    assert "adapter link cannot send breaks" in details["R-7.0-03"]
    assert verdicts["R-7.0-09"] == "INCONCLUSIVE"  # a timing case: 50 ms straddles the limit
    assert "uncertainty straddles" in details["R-7.0-09"]


@pytest.mark.realtime
def test_cli_reports_a_fault_served_through_the_adapter(tmp_path):
    fake = FakeAdapter(faults=("ack-trailing-space",))
    try:
        code, doc = _run_cli(fake.url, tmp_path, "-k", "acknowledge_active")
    finally:
        fake.close()
    assert _verdicts(doc)["R-4.4.1-01"] == "FAIL"
    assert code == 1
