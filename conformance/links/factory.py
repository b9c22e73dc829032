"""Real links (serial ports and pyserial URLs)."""

from __future__ import annotations

from .base import Link


def open_real_link(port: str) -> Link:
    from ..ports import PortError

    raise PortError(
        f"port {port!r}: this version runs only on the built-in simulated bus (--port sim); "
        "serial, rfc2217:// and socket:// links are not implemented yet"
    )
