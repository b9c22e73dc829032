"""An output file that is either whole or not there: written under a temporary name in the
same folder and renamed onto its own name only once complete.

A Ctrl-C (or a full disk, or a bug) halfway through an export used to leave a truncated
capture at the output path, which a later ``judge`` then read as a short recording. A rename
within one folder is atomic on every file system the tool runs on, so a reader of the path
sees the old file, the new one, or none, never part of one.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` to write; on a clean exit it becomes ``path``,
    on any exception (KeyboardInterrupt too) it is removed and ``path`` is left as it was."""
    target = Path(path)
    fd, name = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=".partial", dir=target.parent or Path(".")
    )
    os.close(fd)
    temp = Path(name)
    mask = os.umask(0)
    os.umask(mask)
    temp.chmod(0o666 & ~mask)  # the permissions a plain open() would have given
    try:
        yield temp
        os.replace(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
