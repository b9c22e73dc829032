"""sdi12-conform: SDI-12 protocol conformance test suite and certification tool."""

from __future__ import annotations


def __getattr__(name: str) -> str:
    """``__version__`` on first use: importlib.metadata costs ~50 ms at start-up, and the
    command line takes over Ctrl-C only once its module is imported (see interrupts.py)."""
    if name != "__version__":
        raise AttributeError(f"module 'conformance' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        found = version("sdi12-conform")
    except PackageNotFoundError:  # running from a source tree that was not installed
        found = "0.0.0+source"
    globals()["__version__"] = found
    return found
