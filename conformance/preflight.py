"""Checks of a run's settings before anything goes onto the bus or pytest starts.

A mistake in the settings is the user's to fix, so each check raises :class:`UsageError` with
one line saying what is wrong and what to type instead; the command line turns it into exit
4, the pytest plugin into pytest's own usage error. Nothing here touches a port.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

from .declaration import ALLOWED_ADDRESSES, address_problem
from .options import UsageError, check_address, check_uncertainty

__all__ = [
    "ALLOWED_ADDRESSES",
    "UsageError",
    "address_problem",
    "check_address",
    "check_role_options",
    "check_uncertainty",
]


def check_options_offline(options: Any) -> None:
    """Every check of a run's options that needs no port (``sdi12-conform`` makes them
    before it opens one; a rack makes them for each DUT before any worker starts).
    ``options``: a :class:`~conformance.run.RunOptions`."""
    from .declaration import load_declaration, normalise_version
    from .options import check_values
    from .selection import resolve

    check_role_options(
        options.role, options.trigger, options.address, options.sweep, options.job_timeout,
    )  # fmt: skip
    check_values(vars(options), plugin=False)
    resolve(options.role, list(options.requirements))  # --req names rules the role can test
    if options.version:
        normalise_version(options.version)
    if options.declaration:
        load_declaration(options.declaration)


def check_role_options(
    role: str,
    trigger: str | None,
    address: str | None = None,
    sweep: str | None = None,
    job_timeout: float | None = None,
) -> None:
    """Settings that only mean something in the other role are mistakes, not no-ops."""
    if role == "sensor" and job_timeout is not None:
        raise UsageError(
            "--job-timeout bounds each job of a data recorder (--role recorder); the sensor "
            "role times every reply by the standard's own limits"
        )
    if role == "sensor" and sweep:
        raise UsageError(
            "--sweep plays ever slower sensors to a data recorder (--role recorder); "
            "the sensor role has no tolerance sweep"
        )
    if role == "recorder" and address:
        raise UsageError(
            "--address picks the sensor to judge (--role sensor); in the recorder role the "
            "tool plays the sensors at the addresses its scenarios need"
        )
    if role == "sensor" and trigger:
        raise UsageError(
            "--trigger makes a data recorder act (--role recorder); a sensor needs no trigger"
        )


def check_report_dir(path: Path) -> Path:
    """Create ``path`` and prove a file can be written there, before a run that would fail
    only at its end (after minutes on a real bench) with nowhere to put its report."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=path)
        os.close(fd)
        os.unlink(probe)
    except FileExistsError:
        raise UsageError(
            f"report folder {path} exists as a file; pass a folder with --report-dir DIR"
        ) from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise UsageError(
            f"cannot write reports to {path} ({reason}); pass a writable folder with "
            "--report-dir DIR"
        ) from None
    return path
