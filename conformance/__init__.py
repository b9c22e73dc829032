"""sdi12-conform: SDI-12 protocol conformance test suite and certification tool."""

from __future__ import annotations

from typing import Any


def __getattr__(name: str) -> str:
    """``__version__`` on first use: importlib.metadata costs ~50 ms at start-up, and the
    command line takes over Ctrl-C only once its module is imported (see interrupts.py)."""
    if name != "__version__":
        raise AttributeError(f"module 'conformance' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, distribution

    try:
        found = version_of(distribution("sdi12-conform"))
    except PackageNotFoundError:  # running from a source tree that was not installed
        found = "0.0.0+source"
    globals()["__version__"] = found
    return found


def version_of(dist: Any) -> str:
    """``dist.version``, read from the metadata's headers alone. ``Distribution.version``
    parses the whole metadata as an e-mail message, and this package's holds the README as
    its description (266 KB): about 4 ms of CPU in every run, for one header that comes
    before it. Anything but one plain ``Version`` line among the headers (a folded or
    repeated header, another spelling) is left to importlib's own reading."""
    text = dist.read_text("METADATA") or dist.read_text("PKG-INFO") or dist.read_text("")
    found: list[str] = []
    in_version = False  # whether the line before began the version header
    for line in (text or "").splitlines():
        if not line:
            break  # the headers end at the first empty line; the description follows
        if line[:1] in (" ", "\t"):  # the header before goes on (folded)
            if in_version:
                return dist.version
            continue
        in_version = line[:8].lower() == "version:"
        if in_version:
            found.append(line[8:].lstrip(" \t"))
    if len(found) == 1 and found[0] and found[0] == found[0].strip():
        return found[0]
    return dist.version
