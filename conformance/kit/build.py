"""Compiling a sketch with the kit's Arduino core (or a C harness with the C kit) for the
host: one compiler call, the binary cached under the build folder and rebuilt only when a
source or a flag changed.

Why one call with every source: a sketch is a handful of files, and compiling them together
(about a second with ``-O1``) is simpler to get right than a dependency graph. The ``.ino``
files are joined in the Arduino IDE's order (the one named after the folder first, then the
others by name) into one C++ file that includes ``Arduino.h`` first, with ``#line`` marks so
the compiler's messages name the sketch's own files. The kit does not generate function
prototypes as the IDE does: a sketch calls functions defined (or declared) above the call.
"""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from ..atomic import atomic_path
from . import ARDUINO_DIR, C_DIR

#: Optimisation: the run is about the sketch's decisions on a virtual clock, not its speed.
OPT = "-O1"
SOURCE_SUFFIXES = (".cpp", ".c", ".cc")


class KitBuildError(RuntimeError):
    """The sketch did not compile (or no compiler): the message holds the compiler's words."""


@dataclass(frozen=True)
class ArduinoBuild:
    """What to compile: the sketch folder, library folders, ``-D`` definitions."""

    sketch: Path
    libraries: tuple[Path, ...] = ()
    defines: tuple[str, ...] = ()
    data_pin: int | None = None
    build_dir: Path | None = None
    extra_flags: tuple[str, ...] = field(default=())

    @property
    def name(self) -> str:
        return self.sketch.resolve().name


def find_compiler() -> str | None:
    """The host C++ compiler: ``$CXX``, else ``c++``, ``g++`` or ``clang++`` on PATH."""
    wanted = os.environ.get("CXX")
    for candidate in ([wanted] if wanted else []) + ["c++", "g++", "clang++"]:
        if shutil.which(candidate):
            return candidate
    return None


def sketch_files(sketch: Path) -> tuple[list[Path], list[Path]]:
    """The sketch's ``.ino`` files (IDE order) and its other sources."""
    if not sketch.is_dir():
        raise KitBuildError(f"{sketch}: not a sketch folder")
    inos = sorted(sketch.glob("*.ino"), key=lambda p: (p.stem != sketch.resolve().name, p.name))
    if not inos:
        raise KitBuildError(f"{sketch}: no .ino file in the sketch folder")
    others = sorted(p for p in sketch.iterdir() if p.suffix in SOURCE_SUFFIXES)
    return inos, others


def library_sources(library: Path) -> tuple[list[Path], list[Path]]:
    """A library's include folders and sources: its ``src/`` (the Arduino 1.5 layout) or its
    top folder (the old flat layout), as the IDE finds them."""
    if not library.is_dir():
        raise KitBuildError(f"{library}: not a library folder")
    root = library / "src" if (library / "src").is_dir() else library
    sources = sorted(p for p in root.rglob("*") if p.suffix in SOURCE_SUFFIXES)
    return [root], sources


def joined_sketch(inos: list[Path]) -> str:
    """The ``.ino`` files as one C++ translation unit, as the IDE joins them."""
    parts = ["#include <Arduino.h>\n"]
    for ino in inos:
        parts.append(f'#line 1 "{ino.resolve()}"\n')
        parts.append(ino.read_text(encoding="utf-8", errors="replace"))
        parts.append("\n")
    return "".join(parts)


def compile_command(build: ArduinoBuild, compiler: str, main_cpp: Path, out: Path) -> list[str]:
    """The one compiler call for ``build`` (``main_cpp`` the joined sketch)."""
    _, others = sketch_files(build.sketch)
    includes = [ARDUINO_DIR, build.sketch.resolve()]
    sources = [main_cpp, *others]
    for library in build.libraries:
        dirs, files = library_sources(library)
        includes += dirs
        sources += files
    flags = [f"-D{d}" for d in build.defines]
    if build.data_pin is not None:
        flags.append(f"-DKIT_DATA_PIN={build.data_pin}")
    flags.append(f'-DKIT_NAME="{build.name}"')
    return [
        compiler,
        "-std=gnu++17",
        OPT,
        "-w",
        *(f"-I{path}" for path in includes),
        *flags,
        *build.extra_flags,
        *_by_language([*sources, ARDUINO_DIR / "kit_core.cpp"]),
        "-o",
        str(out),
    ]


def _by_language(sources: list[Path]) -> list[str]:
    """Each source with its language: a ``.c`` file is C (a C library in a sketch, included
    in ``extern "C"`` as on a board), everything else C++."""
    out: list[str] = []
    for source in sources:
        out += ["-x", "c" if source.suffix == ".c" else "c++", str(source)]
    return out


def build_arduino(build: ArduinoBuild, compiler: str | None = None) -> Path:
    """Compile ``build``; the binary's path. Cached: the same sources and flags reuse it."""
    compiler = compiler or find_compiler()
    if compiler is None:
        raise KitBuildError("no C++ compiler found (set CXX, or install g++ or clang++)")
    inos, _ = sketch_files(build.sketch)
    folder = (build.build_dir or Path(".sdi12-kit") / build.name).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    main_cpp = folder / f"{build.name}.ino.cpp"
    text = joined_sketch(inos)
    if not main_cpp.exists() or main_cpp.read_text() != text:
        with atomic_path(main_cpp) as joined:  # a compiler reading it meanwhile sees it whole
            joined.write_text(text)
    probe = compile_command(build, compiler, main_cpp, folder / "sketch")
    digest = _digest(probe)
    out = folder / f"sketch-{digest[:12]}"
    if out.exists():
        return out
    # Built under a temporary name, renamed onto ``out`` once whole: ``out`` existing means
    # built. Two builds of one sketch at once (two ``kit`` commands, test workers) each
    # compile; written in place, the second found the first's ``out`` half linked and ran it.
    with atomic_path(out) as partial:
        done = subprocess.run(
            compile_command(build, compiler, main_cpp, partial),
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            command = shlex.join(compile_command(build, compiler, main_cpp, out))
            raise KitBuildError(f"the sketch did not compile ({command}):\n{done.stderr.strip()}")
    return out


def _digest(command: list[str]) -> str:
    """A hash of the command and of every file it reads (the kit's own sources included)."""
    h = hashlib.sha256(" ".join(command).encode())
    paths = [Path(a) for a in command if a.endswith((*SOURCE_SUFFIXES, ".h"))]
    paths += sorted(ARDUINO_DIR.glob("*"))
    for include in (a[2:] for a in command if a.startswith("-I")):
        paths += sorted(Path(include).glob("*.h"))
    for path in paths:
        if path.is_file():
            h.update(path.read_bytes())
    return h.hexdigest()


def c_pin_commands(
    sources: list[Path], out: Path, defines: tuple[str, ...] = ()
) -> list[list[str]]:
    """The calls that build C firmware on the pin adapter (``c/sdi12_kit_pin.h``): each C
    file with the C compiler into ``out``'s folder, then one C++ link with the adapter and
    the Arduino core (docs/kit.md, "The C kit"). ``$CC``, else ``cc``; ``$CXX``, else c++."""
    cc = os.environ.get("CC") or "cc"
    flags = [f"-D{d}" for d in defines]
    objects = [out.parent / f"{out.name}-{source.stem}.o" for source in sources]
    calls = [
        [cc, OPT, f"-I{C_DIR}", *flags, "-c", str(source), "-o", str(obj)]
        for source, obj in zip(sources, objects, strict=True)
    ]
    cxx = find_compiler() or "c++"
    name = f'-DKIT_NAME="{out.name}"'
    core = [str(C_DIR / "kit_pin.cpp"), str(ARDUINO_DIR / "kit_core.cpp")]
    link = [cxx, "-std=gnu++17", OPT, "-w", f"-I{ARDUINO_DIR}", f"-I{C_DIR}", name]
    calls.append([*link, *map(str, objects), *core, "-o", str(out)])
    return calls


def build_c_pin(sources: list[Path], out: Path, defines: tuple[str, ...] = ()) -> Path:
    """Build C firmware that bit-bangs (``c_pin_commands``) as ``out``; KitBuildError with
    the compiler's messages when it does not compile."""
    for command in c_pin_commands(sources, out, defines):
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise KitBuildError(f"did not compile ({shlex.join(command)}):\n{done.stderr.strip()}")
    return out
