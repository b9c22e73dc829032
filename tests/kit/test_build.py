"""The kit's build cache (conformance/kit/build.py): a cached binary is there only once whole,
so a second build of the same sketch arriving while the first links never runs half a file.

The compiler is a stand-in (no C++ compiler needed): it writes the binary in two halves and,
between them, lets a second build of the same sketch into the same folder run to the end,
as a second ``kit`` command or a second test worker would. Deterministic: the interleaving
is the one that broke, made on purpose instead of waited for."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from conformance.kit import build as kit_build
from conformance.kit.build import ArduinoBuild, KitBuildError, build_arduino
from tests.kit.conftest import SENSOR

BINARY = b"\x7fELF" + bytes(range(256)) * 64  # what a whole link writes


def _output(command: list[str]) -> Path:
    return Path(command[command.index("-o") + 1])


def test_a_build_arriving_while_another_links_gets_a_whole_binary(tmp_path, monkeypatch):
    build = ArduinoBuild(SENSOR, build_dir=tmp_path / "builds")
    seen: dict[str, bytes] = {}  # what each build returned, read as it returned

    def compiler(command: list[str], **_kwargs) -> subprocess.CompletedProcess[str]:
        out = _output(command)
        with open(out, "wb") as binary:
            binary.write(BINARY[: len(BINARY) // 2])
            binary.flush()
            if "second" not in seen:  # the other build, while this one is half written
                seen["second"] = b""
                seen["second"] = build_arduino(build, compiler="c++").read_bytes()
            binary.write(BINARY[len(BINARY) // 2 :])
        return subprocess.CompletedProcess(command, 0, "", "")

    monkeypatch.setattr(kit_build.subprocess, "run", compiler)
    first = build_arduino(build, compiler="c++")
    assert seen["second"] == BINARY  # not the half the first build had written
    assert first.read_bytes() == BINARY
    assert sorted(p.name for p in first.parent.iterdir()) == sorted(
        [first.name, f"{build.name}.ino.cpp"]
    )  # no temporary file left behind
    # cached: a third build reuses the binary without compiling
    monkeypatch.setattr(kit_build.subprocess, "run", None)
    assert build_arduino(build, compiler="c++") == first


def test_a_failed_compile_leaves_no_binary_and_names_the_real_output(tmp_path, monkeypatch):
    build = ArduinoBuild(SENSOR, build_dir=tmp_path / "builds")

    def failing(command: list[str], **_kwargs) -> subprocess.CompletedProcess[str]:
        _output(command).write_bytes(BINARY[:10])  # a linker that died half way
        return subprocess.CompletedProcess(command, 1, "", "error: 'loop' was not declared")

    monkeypatch.setattr(kit_build.subprocess, "run", failing)
    with pytest.raises(KitBuildError, match="was not declared") as raised:
        build_arduino(build, compiler="c++")
    assert ".partial" not in str(raised.value)
    assert [p.name for p in (tmp_path / "builds").iterdir()] == [f"{build.name}.ino.cpp"]
