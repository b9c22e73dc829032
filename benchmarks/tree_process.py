"""One Python process running a snippet against a checkout: what the side-by-side CPU
benchmarks (matrix_cpu.py, capture_half_cpu.py, run_cpu_repeated.py) start once per tree.

The tree goes first on ``PYTHONPATH`` and bytecode caching is on (as in CI: the figures are
of a run, not of compiling it); a read-only tree (an unpacked ``git archive``) gets its
bytecode cache in a folder of its own under ``cache``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path


def start_in_tree(
    tree: Path,
    code: str,
    args: Sequence[str],
    cache: Path,
    cwd: Path | str,
    drop_env: Sequence[str] = (),
) -> subprocess.Popen:
    """``python -c code *args`` with ``tree`` on the path, run in ``cwd`` (never inside
    another checkout: python puts the working folder first on the path), stdout piped as
    text; ``drop_env`` names variables the child must not inherit."""
    dropped = {"PYTHONDONTWRITEBYTECODE", *drop_env}
    env = {k: v for k, v in os.environ.items() if k not in dropped}
    env["PYTHONPATH"] = str(tree)
    if not os.access(tree, os.W_OK):  # a read-only tree: its bytecode cached elsewhere
        env["PYTHONPYCACHEPREFIX"] = str(cache / tree.name)
    return subprocess.Popen(
        [sys.executable, "-c", code, *args], cwd=cwd, env=env, stdout=subprocess.PIPE, text=True
    )
