"""Why a real link could not do what was asked, as exceptions the layers above can sort.

``PortUnavailable`` is both a :class:`~conformance.ports.PortError` (the CLI turns it into a
usage error, exit 4: the user named a port that cannot be opened) and a
:class:`~conformance.links.base.LinkError` (code that only knows links still catches it).
``BreakUnsupported`` lets the master engine send a command without its wake-up break on a
link that has none, while a case that presents a break of its own becomes INCONCLUSIVE.
"""

from __future__ import annotations

from ..ports import PortError
from .base import LinkError


class PortUnavailable(PortError, LinkError):
    """The port could not be opened (missing, busy, no permission, nobody listening)."""


class PortVanished(LinkError):
    """The port went away during the run (cable pulled, server stopped)."""


class BreakUnsupported(LinkError):
    """This link cannot put a break on the line (``socket://``, ``loop://``)."""
