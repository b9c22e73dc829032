"""Why a port or a link could not do what was asked, as exceptions the layers above can sort.

``PortError`` is a port string the tool cannot use; the CLI turns it into a usage error (exit
4). ``PortUnavailable`` is both a ``PortError`` (the user named a port that cannot be opened)
and a :class:`~conformance.links.base.LinkError` (code that only knows links still catches
it). ``BreakUnsupported`` lets the tool recorder send a command without its wake-up break on
a link that has none, while a case that presents a break of its own becomes INCONCLUSIVE.
:func:`explain_open_failure` is the one place that turns pyserial's complaint into advice.
"""

from __future__ import annotations

import errno
import re

from .base import LinkError


class PortError(ValueError):
    """A port string the tool cannot use; the message says what to do instead."""


class PortUnavailable(PortError, LinkError):
    """The port could not be opened (missing, busy, no permission, nobody listening)."""


class PortMissing(PortUnavailable):
    """No device by that name. The main command adds that ``--port sim`` runs without one;
    the subcommands that refuse sim (monitor, calibrate) do not suggest it."""


#: what a ``--port`` that was meant as a pyserial URL starts with
URL_SCHEMES = ("rfc2217", "socket", "loop", "spy", "hwgrep", "alt", "sim", "exec", "unix")


class PortVanished(LinkError):
    """The port went away during the run (cable pulled, server stopped)."""


class BreakUnsupported(LinkError):
    """This link cannot put a break on the line (``socket://``, ``loop://``)."""


def unavailable(port: str, kind: str, exc: BaseException) -> PortUnavailable:
    """The exception for a port that could not be opened: :class:`PortMissing` when there is
    no such device, else :class:`PortUnavailable`; either with the advice."""
    message = explain_open_failure(port, kind, exc)
    if message.startswith("serial port ") and "does not exist" in message:
        return PortMissing(message)
    return PortUnavailable(message)


def url_typo(port: str) -> str | None:
    """The URL a port that is no device was probably meant as (``rfc2217//HOST:PORT``,
    ``socket:/HOST:PORT``), or None if it does not look like one."""
    found = re.match(r"([A-Za-z][A-Za-z0-9]*)[:/]+(.+)", port)
    if "://" in port or found is None or found[1].lower() not in URL_SCHEMES:
        return None
    return f"{found[1].lower()}://{found[2]}"


def explain_open_failure(port: str, kind: str, exc: BaseException) -> str:
    """One message that says what went wrong and what to try."""
    code = getattr(exc, "errno", None)
    text = str(exc)
    if kind in ("rfc2217", "socket"):
        return (
            f"cannot connect to {port}: {text}. Is the server running and listening there "
            "(for the emulator: sdi12-conform emulate --listen HOST:PORT)?"
        )
    if code == errno.ENOENT or "No such file" in text or "FileNotFoundError" in text:
        meant = url_typo(port)
        if meant is not None:
            return (
                f"port {port!r} does not exist as a device, and it is not a URL: a URL is "
                f"written SCHEME://HOST:PORT (did you mean {meant}?)"
            )
        return (
            f"serial port {port} does not exist. Check the cable and the device name "
            "(Linux: ls /dev/ttyUSB* /dev/ttyACM*; Windows: COMn in Device Manager)"
        )
    if code == errno.EACCES or "Permission denied" in text:
        return (
            f"permission denied on serial port {port}. Add your user to the group that owns "
            "it (Linux: sudo usermod -aG dialout $USER, then log in again)"
        )
    if code == errno.ENOTTY or "Inappropriate ioctl" in text:  # pyserial hides the errno
        return (
            f"{port} is not a serial device (a regular file?): pass a serial port such as "
            "/dev/ttyUSB0 or COM3"
        )
    if code == errno.EBUSY or "busy" in text.lower():
        return f"serial port {port} is busy: close the other program using it"
    return f"cannot open port {port}: {text}"
