"""Serving the reference sensor emulator in real time (``sdi12-conform emulate``)."""

from .realtime import RealTimeLine
from .servers import TcpEmulatorServer, VirtualPort, serve_serial

__all__ = ["RealTimeLine", "TcpEmulatorServer", "VirtualPort", "serve_serial"]
