"""An output file that is either whole or not there: written under a temporary name in the
same folder and renamed onto its own name only once complete.

A Ctrl-C (or a full disk, or a bug) halfway through an export used to leave a truncated
capture at the output path, which a later ``judge`` then read as a short recording. A rename
within one folder is atomic on every file system the tool runs on, so a reader of the path
sees the old file, the new one, or none, never part of one.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: names tried for the temporary file before giving up (a random name is taken only when
#: another writer made the same one in the same folder at the same moment)
TRIES = 100


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` to write; on a clean exit it becomes ``path``,
    on any exception (KeyboardInterrupt too) it is removed and ``path`` is left as it was.

    A Ctrl-C can come at any moment, also while the temporary file is being made: its name
    is chosen before the file exists, so the cleanup knows what to remove wherever the
    interrupt lands (``tempfile.mkstemp`` names it only once made, and an interrupt as it
    returned left a ``.partial`` behind)."""
    target = Path(path)
    for _ in range(TRIES):
        temp = target.with_name(f".{target.name}.{secrets.token_hex(4)}.partial")
        try:
            # mode 0o666 less the umask: the permissions a plain open() would have given
            os.close(os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        except BaseException:
            temp.unlink(missing_ok=True)  # interrupted as it was made: the file is ours
            raise
        break
    else:
        raise FileExistsError(f"no free temporary name beside {target} in {TRIES} tries")
    try:
        yield temp
        os.replace(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
