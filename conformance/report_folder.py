"""Report folders that two runs can never share.

Two runs started in the same second once wrote one default folder (its name was a
second-resolution stamp) and each printed the other's verdict. So a default folder is made
here with ``mkdir`` (atomic: of two processes asking for one name, one gets it and the other
takes the next suffix) and never reused; and a folder a run writes into holds a lock file
with the run's pid while it runs, so a second run named into it (``--report-dir``) is refused
instead of mixing its files in. A lock left by a process that no longer exists (a killed
run) is stale and taken over.
"""

from __future__ import annotations

import datetime as dt
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .options import UsageError

LOCK_NAME = ".sdi12-conform.lock"
_HELD: dict[Path, int] = {}  # folders this process holds, and how many holders nest there


def new_report_dir(kind: str, base: Path | str = "reports") -> Path:
    """A new, empty folder ``base/STAMP-kind`` (``-2``, ``-3``... when that name is taken),
    created by this call: no other run, in this process or another, gets the same one."""
    base = Path(base)
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    try:
        base.mkdir(parents=True, exist_ok=True)
        for n in range(1, 10_000):
            path = base / (f"{stamp}-{kind}" if n == 1 else f"{stamp}-{kind}-{n}")
            try:
                path.mkdir()
            except FileExistsError:
                continue
            return path
    except OSError as exc:  # a working directory nobody may write to: the user's to fix
        raise UsageError(
            f"cannot create a report folder under {base.resolve()}: {exc.strerror or exc}; "
            "pass --report-dir DIR"
        ) from exc
    raise UsageError(f"no free report folder name under {base}; pass --report-dir DIR")


def _alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    except OSError:
        return False
    return True


def _holder(lock: Path) -> int | None:
    """The pid written in ``lock`` (None: no lock, or one not (yet) readable as a pid)."""
    try:
        text = lock.read_text(encoding="ascii").strip()
    except (FileNotFoundError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


def acquire(path: Path) -> bool:
    """Mark ``path`` as holding this process's run; True if this call took the lock (and so
    must :func:`release` it), False if this process already held it (a nested step of the
    same run, e.g. the judging a ``monitor`` ends with). Raises :class:`UsageError` when a
    live process other than this one holds it."""
    key = path.resolve()
    if key in _HELD:
        _HELD[key] += 1
        return False
    lock = path / LOCK_NAME
    for _ in range(3):
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            pid = _holder(lock)
            if pid is None:  # being written this instant, or garbage: read once more
                pid = _holder(lock)
            if pid is not None and pid != os.getpid() and _alive(pid):
                raise UsageError(
                    f"report folder {path} holds a run in progress (pid {pid}); pass another "
                    "--report-dir, or leave it out for a new folder"
                ) from None
            lock.unlink(missing_ok=True)  # stale: its process is gone
            continue
        with os.fdopen(fd, "w", encoding="ascii") as f:
            f.write(f"{os.getpid()}\n")
        _HELD[key] = 1
        return True
    raise UsageError(
        f"report folder {path}: its run lock cannot be taken; pass another --report-dir"
    )


def release(path: Path) -> None:
    """Undo one :func:`acquire` of ``path``; the lock file goes with the outermost holder."""
    key = path.resolve()
    count = _HELD.get(key, 0)
    if count > 1:
        _HELD[key] = count - 1
        return
    _HELD.pop(key, None)
    lock = path / LOCK_NAME
    if _holder(lock) == os.getpid():
        lock.unlink(missing_ok=True)


@contextmanager
def held(path: Path) -> Iterator[Path]:
    """``path`` locked for this run for the ``with`` block (see :func:`acquire`)."""
    acquire(path)
    try:
        yield path
    finally:
        release(path)


def serial_folder_name(serial: str | None) -> str | None:
    """A serial number as a folder name (a character a path cannot hold becomes ``_``);
    None when nothing usable is left (no serial, or only dots and dashes)."""
    safe = "".join(c if c.isalnum() or c in "._-" else "_" for c in (serial or "").strip())
    return safe if safe.strip("._-") else None


def named_by_serial(folder: Path, serial: str | None, kind: str) -> Path:
    """A finished run's own new folder ``STAMP-kind`` renamed ``STAMP-SERIAL`` (the sensor's
    serial number from its ``aI!`` reply: a production line's reports found by unit), and
    its new path; ``folder`` itself when there is no usable serial or the name is taken.
    The run's lock is let go first: the run is over, and the lock would move with it."""
    safe = serial_folder_name(serial)
    if safe is None or not folder.name.endswith(f"-{kind}"):
        return folder
    target = folder.with_name(folder.name[: -len(kind)] + safe)
    release(folder)
    try:
        folder.rename(target)  # refuses an existing non-empty folder: the old name stays
    except OSError:
        return folder
    return target


def run_folder(report_dir: str | Path | None, kind: str) -> Path:
    """The folder a run writes into: the one named, or a new one of its own under the
    default reports folder (``kind`` names it: the role, "passive", "monitor")."""
    return Path(report_dir) if report_dir else new_report_dir(kind)
