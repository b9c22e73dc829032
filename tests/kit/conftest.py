"""Building sketches with the kit once per session (skipped, saying why, without a C++
compiler): ``kit_build(sketch, libs, defines)`` returns the binary, cached by its flags."""

from __future__ import annotations

import fcntl
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from conformance.harness.channel import ChildChannel
from conformance.harness.protocol import Role, parse_plan
from conformance.kit.build import ArduinoBuild, build_arduino, find_compiler
from tests.support.paths import ROOT
from tests.support.shared_runs import common_folder

ARDUINO = ROOT / "examples" / "arduino"
SENSOR = ARDUINO / "sdi12_sensor"
TINY_SDI12 = ARDUINO / "libraries" / "TinySDI12"
SKETCHES = Path(__file__).parent / "sketches"
LOGGER = ARDUINO / "sdi12_logger"
LOGGER_DECLARATION = str(ROOT / "examples" / "c" / "tiny_logger.toml")

Build = Callable[..., Path]


@pytest.fixture(scope="session")
def kit_builds(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The session's build folder (skipped without a compiler): a sketch built once with
    the same flags, by a fixture or by the kit subcommand given ``--build-dir``, is reused.
    Under pytest-xdist the workers share it (tests/support/shared_runs.py's common folder):
    the sensor and logger sketches, each about 3 s of a compiler's CPU, were built again by
    every worker that took a module using them (test_kit_batch beside test_arduino_sensor
    and test_arduino_logger). The kit's build is safe to share: keyed by a digest of its
    sources and flags, renamed into place once whole."""
    if find_compiler() is None:
        pytest.skip("no C++ compiler (c++, g++ or clang++): the kit cannot build a sketch")
    folder = common_folder(tmp_path_factory) / "kit-builds"
    folder.mkdir(exist_ok=True)
    return folder


def build_dir(folder: Path, sketch: Path, defines: tuple[str, ...] = ()) -> Path:
    return folder / "-".join((sketch.name, *defines))


@pytest.fixture(scope="session")
def kit_build(kit_builds: Path) -> Build:
    def build(sketch: Path, libs: tuple[Path, ...] = (), defines: tuple[str, ...] = ()) -> Path:
        where = build_dir(kit_builds, sketch, defines)
        # one worker compiles a sketch, any other that wants it meanwhile waits and reuses it
        with open(kit_builds / f"{where.name}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
            return build_arduino(ArduinoBuild(sketch, libs, defines, build_dir=where))

    return build


C_EXAMPLES = ROOT / "examples" / "c"


def c_compiler() -> str:
    """The host C compiler (``$CC``, else ``cc``, ``gcc`` or ``clang``); skips, saying why,
    without one."""
    for candidate in [os.environ.get("CC") or "cc", "gcc", "clang"]:
        if shutil.which(candidate):
            return candidate
    pytest.skip("no C compiler (cc, gcc or clang): the C kit's examples cannot be built")


def play_sensor(
    binary: Path, name: str, events: list[str], until: int | None = None, steps: int = 200
) -> tuple[list[tuple[int, int, int]], str]:
    """Play the tool's side for a bit-level sensor (version 2): tell `events` in order (each
    when the firmware's wait reaches its start), `time T` for every other wait (up to `until`
    us, or `steps` messages), `sent` for every tx; the frames it sent and its stderr."""
    channel = ChildChannel(str(binary))
    try:
        assert channel.greet(Role.SENSOR) == name and channel.version == 2
        events = list(events)
        message = events.pop(0)
        now, sent = int(message.split()[2]), []  # the first event's end
        for _ in range(steps):
            if until is not None and now >= until:
                break
            plan = parse_plan(channel.ask(message), Role.SENSOR, now, version=2)
            if plan.kind == "tx":
                end = plan.start + plan.duration
                sent.append((plan.start, end, plan.wire))
                message, now = f"sent {plan.start} {end} {plan.wire:02x}", end
            elif events and (plan.kind == "idle" or int(events[0].split()[1]) < plan.start):
                message = events.pop(0)
                now = int(message.split()[2])
            elif plan.kind == "wait":
                message, now = f"time {plan.start}", plan.start
            else:
                break
        channel.finish("bye")
        return sent, channel.stderr_tail()
    finally:
        channel.close()
