"""The live progress keeps moving (issue 19: over RFC 2217 the bar sat at ``0/62 0:00:00``
for 95 s, and on sim nothing showed for 8 s): it is drawn before the cases are collected,
repainted on a timer while a slow case runs, and names what is running, the device being
found included. No pty: rich draws into a recording file that says when each frame came."""

from __future__ import annotations

import re
import time

import pytest
from rich.console import Console

from conformance.reports.console import ProgressPlugin
from tests.support.paths import ROOT

ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")

SLOW_CASES = """
import time
import pytest

@pytest.fixture(scope="session")
def sensor():
    time.sleep(1.2)  # a bench probe: discovery and timing measurement before the first case
    return object()

def test_first_case(sensor):
    pass

def test_slow_case(sensor):
    time.sleep(2.2)  # a case that waits on a slow link
"""


class Frames:
    """A file for rich that keeps each write with its time."""

    def __init__(self) -> None:
        self.writes: list[tuple[float, str]] = []

    def write(self, text: str) -> int:
        self.writes.append((time.monotonic(), ANSI.sub("", text)))
        return len(text)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return True

    def between(self, start: float, end: float, needle: str) -> list[str]:
        return [t for at, t in self.writes if start <= at <= end and needle in t]


class When:
    """A pytest plugin noting when each phase happened."""

    def __init__(self) -> None:
        self.at: dict[str, float] = {}

    def pytest_collection_finish(self, session):
        self.at["collected"] = time.monotonic()

    def pytest_runtest_logstart(self, nodeid, location):
        self.at[nodeid.split("::")[-1]] = time.monotonic()

    def pytest_runtest_logfinish(self, nodeid, location):
        self.at[nodeid.split("::")[-1] + " done"] = time.monotonic()


@pytest.fixture(scope="module")  # one run for all (its module would clash if imported twice)
def drawn(tmp_path_factory):
    tmp_path = tmp_path_factory.mktemp("slow")
    (tmp_path / "test_slow.py").write_text(SLOW_CASES)
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    frames = Frames()
    console = Console(file=frames, force_terminal=True, width=140, color_system=None)
    when = When()
    code = pytest.main(
        [str(tmp_path), "-c", str(tmp_path / "pytest.ini"), "-p", "no:terminal",
         "-p", "no:randomly", "-p", "no:cacheprovider", "-p", "no:xdist"],
        plugins=[ProgressPlugin(console), when],
    )  # fmt: skip
    assert code == 0
    return frames, when.at


def test_the_bar_is_drawn_before_the_cases_are_collected(drawn):
    frames, when = drawn
    assert frames.between(0, when["collected"], "collecting the cases"), frames.writes[:3]


def test_the_bar_repaints_and_its_clock_ticks_while_a_slow_case_runs(drawn):
    frames, when = drawn
    start, end = when["test_slow_case"], when["test_slow_case done"]
    painted = frames.between(start, end, "test_slow_case")
    assert len(painted) >= 5, painted  # 4 a second over 2.2 s
    clocks = {m.group(0) for t in painted for m in [re.search(r"\d:\d\d:\d\d", t)] if m}
    assert len(clocks) >= 2, clocks  # the elapsed time moved on screen


def test_the_device_being_found_is_shown_while_it_takes(drawn):
    frames, when = drawn
    probing = frames.between(
        when["test_first_case"], when["test_first_case done"], "probing the bench"
    )
    assert len(probing) >= 2, "the probe is named on screen while it runs"
    assert "test_first_case: finding the sensor" in probing[0]


def test_the_bar_counts_cases_and_says_so(drawn):
    frames, _ = drawn
    assert any(re.search(r"\b1/2 cases\b", t) for _, t in frames.writes)


def test_the_real_command_on_a_terminal_shows_cases_being_counted(tmp_path):
    """The CLI itself in a pty: the bar moves past 'collecting the cases' while the cases run.
    pytest's output capture used to swallow every repaint after the first case started, so a
    whole run showed '0/? cases 0:00:00 collecting the cases' and then the summary. The
    device is the Python example harness on ``exec:``, whose round trips take real time
    (~2 s of cases): against ``sim`` the cases now take ~0.3 s, about one repaint of the bar
    (4 a second), and a run could end with no count between 0 and all to show (issue 22)."""
    import os
    import pty
    import select
    import sys

    pid, fd = pty.fork()
    if pid == 0:  # the child: the command, its stdout a terminal
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST")}
        device = f"exec:{sys.executable} {ROOT / 'examples/python/sensor_harness.py'}"
        os.execve(sys.executable, [sys.executable, "-m", "conformance.cli", "--port", device,
                                   "--report-dir", str(tmp_path / "r")], env)  # fmt: skip
    out = b""
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.5)
        if not ready:
            continue
        try:
            chunk = os.read(fd, 65536)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        out += chunk
    os.waitpid(pid, 0)
    text = ANSI.sub("", out.decode("utf-8", "replace"))
    counted = re.findall(r"(\d+)/(\d+) cases", text)
    assert any(0 < int(done) < int(total) for done, total in counted), text[-2000:]
