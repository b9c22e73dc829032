"""sdi12-conform: SDI-12 protocol conformance test suite and certification tool."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("sdi12-conform")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+source"
