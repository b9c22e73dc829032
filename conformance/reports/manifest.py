"""The manifest in ``verdicts.json``: what a third party needs to check a run folder without
the device (``sdi12-conform verify DIR``).

The recording is the evidence, so its hash is what the manifest pins: an edited
``transcript.jsonl`` no longer matches. An edited verdict cannot be pinned by a hash inside
the same file; ``verify`` catches it by judging the recording again and comparing. The
declaration's and the catalog's hashes say which claims and which rule texts the verdicts
were judged against (the declaration file itself stays with its owner).
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

ALGORITHM = "sha256"
#: files of the run folder the manifest pins (reports written after verdicts.json, such as
#: report.html and junit.xml, are renderings of it and are checked through it)
PINNED = ("transcript.jsonl", "plan.json")  # plan.json: only where the run was planned
CATALOG = Path(__file__).resolve().parent.parent / "catalog.json"


def digest(path: Path) -> str:
    with path.open("rb") as f:
        return hashlib.file_digest(f, ALGORITHM).hexdigest()


def build_manifest(directory: Path, declaration: str | None, tool_version: str) -> dict[str, Any]:
    decl = Path(declaration) if declaration else None
    return {
        "algorithm": ALGORITHM,
        "files": {name: digest(directory / name) for name in PINNED if (directory / name).exists()},
        "declaration": (
            {"path": str(decl), ALGORITHM: digest(decl)}
            if decl is not None and decl.is_file()
            else None
        ),
        "catalog": digest(CATALOG),
        "tool_version": tool_version,
    }


def check_files(directory: Path, manifest: dict[str, Any]) -> list[tuple[str, bool, str]]:
    """(file, ok, why) for each pinned file: missing, changed, or matching."""
    out = []
    for name, want in sorted((manifest.get("files") or {}).items()):
        path = directory / name
        if not path.is_file():
            out.append((name, False, "missing"))
        elif digest(path) != want:
            out.append((name, False, f"{ALGORITHM} differs from the manifest"))
        else:
            out.append((name, True, f"{ALGORITHM} matches"))
    return out
