"""The kinds of link a ``--port`` string can name, each with its opener and capabilities.

A kind of link is one module that calls :func:`register` when it is imported: a
:class:`LinkKind` saying which port strings it takes, what its links can do at best
(:class:`~conformance.links.base.LinkInfo`) and how to open one in each role: the sensor role
(the tool is the recorder and transmits on the link) and the recorder role (the tool plays
sensors to a recorder under test). The recorder-role openers build played sensors and
recorder drivers, a layer above this one, so :mod:`conformance.recorder.openers` attaches them
(:func:`attach_recorder_role`). :mod:`conformance.ports` imports every built-in kind module;
``open_port`` and ``open_recorder_line`` look the port up here, and nothing else chooses
between kinds. This is python-can's interface table (``can.interfaces.BACKENDS``: a name ->
the module and class that open it) keyed by the port string instead of a name, because
SDI-12 benches are named by device paths (``COM3``, ``/dev/ttyUSB0``) as often as by URLs.

A kind a process may well never need is registered late: :func:`defer` takes a function that
imports such kinds' modules, called the first time a port string is looked up that no *sole*
kind claims, or the whole table is asked for (:func:`kinds`, :func:`kind_named`,
:func:`attach_recorder_role`). A sole kind is one whose port strings no other kind claims
(``sim``, ``replay:``; ``tests/links/test_registry.py`` checks each against every other
kind), so a ``--port sim`` run finds its kind without importing pyserial, the serial links,
the harness or the capture readers (issue 22: 1.6% of a sim process's instructions).

Exactly one kind may be the *fallback*: the one a port string belongs to when no other kind
claims it (a serial device name, or a pyserial URL such as ``spy://`` or ``hwgrep://``).
Every other port string must be claimed by exactly one kind; two claims are a bug in the
kinds, found when the port is looked up.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from ..declaration import Declaration
from .base import Link, LinkInfo
from .errors import PortError

if TYPE_CHECKING:  # the real interfaces' modules: imported by modes() when one opens
    from .driver_enable import DirectionLine
    from .echo import EchoMode


@dataclass(frozen=True)
class PortOptions:
    """What the user said about the bench besides the port (the CLI's --echo, --direction
    and --timing-uncertainty-ms). Kinds without a real interface ignore them."""

    echo: str = "auto"  # auto, on, off: does the interface echo the tool's own characters
    direction: str = "none"  # none, rts, dtr: the line that enables the tool's driver
    timing_uncertainty: float | None = None  # s: only ever widens what the link measures

    def modes(self) -> tuple[EchoMode, DirectionLine]:
        """``echo`` and ``direction`` for a real interface; PortError if either is unknown."""
        from .driver_enable import DirectionLine
        from .echo import EchoMode

        try:
            return EchoMode(self.echo), DirectionLine(self.direction)
        except ValueError as exc:
            raise PortError(
                f"{exc}: --echo is auto, on or off; --direction is rts, dtr or none"
            ) from exc


@dataclass
class OpenedPort:
    """An opened port: the link, the simulated devices behind it (if the tool made them) and
    what a simulated device declares about itself."""

    link: Link
    devices: list[object] = field(default_factory=list)
    declaration: Declaration | None = None


#: Opens ``port`` for the sensor role (the tool is the recorder); raises
#: :class:`~conformance.links.errors.PortError` for a string it cannot use.
Opener = Callable[[str, PortOptions], OpenedPort]

#: Opens ``port`` for the recorder role, given the recorder driver the user named
#: (``--trigger``; None: the one the port implies): the line the played sensors go on and
#: who the recorder under test is (a :class:`conformance.recorder.openers.RecorderLine`).
RecorderOpener = Callable[[str, PortOptions, Any], Any]


@dataclass(frozen=True)
class LinkKind:
    """One kind of link: which port strings name it, what it can do, how it opens in each
    role (None: the kind serves the other role only; ``wrong_role`` says what to use)."""

    name: str  # the LinkInfo.kind of the links it opens
    matches: Callable[[str], bool]  # does this port string name a link of this kind
    open_sensor_role: Opener | None
    info: LinkInfo  # what its links can do at best; an opener may only take away from it
    example: str  # a port string of this kind, for documentation and tests
    fallback: bool = False  # takes every port string no other kind claims
    open_recorder_role: RecorderOpener | None = None
    #: what the user should write instead, for a role this kind has no opener for
    wrong_role: str = ""
    #: how the kind is named to a user choosing a port for the recorder role
    recorder_role_hint: str = ""
    #: no other kind claims a port string this one claims: found without the deferred kinds
    sole: bool = False


_KINDS: dict[str, LinkKind] = {}
#: functions registering more kinds when they are first needed (:func:`defer`)
_DEFERRED: list[Callable[[], object]] = []


def defer(load: Callable[[], object]) -> None:
    """Register kinds later: ``load`` (importing their modules) runs once, before the first
    look-up that a sole kind does not answer and before the whole table is read."""
    _DEFERRED.append(load)


def _load_deferred() -> None:
    while _DEFERRED:
        _DEFERRED.pop(0)()


def register(kind: LinkKind) -> LinkKind:
    """Add ``kind`` (its module calls this on import); a second kind of the same name, or a
    second fallback, is a programming error."""
    if kind.name in _KINDS and _KINDS[kind.name] != kind:
        raise ValueError(f"link kind {kind.name!r} is registered twice")
    if kind.fallback and any(k.fallback and k.name != kind.name for k in _KINDS.values()):
        raise ValueError(f"link kind {kind.name!r}: there is a fallback kind already")
    _KINDS[kind.name] = kind
    return kind


def attach_recorder_role(name: str, opener: RecorderOpener, hint: str) -> LinkKind:
    """Give the registered kind ``name`` its recorder-role opener (``hint``: how the kind
    reads in the list of ports the recorder role takes)."""
    _load_deferred()
    kind = replace(_KINDS[name], open_recorder_role=opener, recorder_role_hint=hint)
    _KINDS[name] = kind
    return kind


def kinds() -> tuple[LinkKind, ...]:
    """Every registered kind, in registration order (the deferred ones loaded first)."""
    _load_deferred()
    return tuple(_KINDS.values())


def kind_named(name: str) -> LinkKind:
    _load_deferred()
    return _KINDS[name]


def find(port: str) -> LinkKind:
    """The kind ``port`` names: the one kind that claims it, else the fallback."""
    if _DEFERRED:
        sole = [k for k in _KINDS.values() if k.sole and k.matches(port)]
        if len(sole) == 1:
            return sole[0]
        _load_deferred()
    claims = [k for k in _KINDS.values() if not k.fallback and k.matches(port)]
    if len(claims) > 1:
        names = ", ".join(k.name for k in claims)
        raise ValueError(f"port {port!r} is claimed by several link kinds: {names}")
    if claims:
        return claims[0]
    for kind in _KINDS.values():
        if kind.fallback:
            return kind
    raise PortError(f"no kind of link takes port {port!r}")


def scheme_of(port: str) -> str:
    """``rfc2217`` for ``RFC2217://host:4001``; empty for a device name (``COM3``)."""
    return port.split("://", 1)[0].lower() if "://" in port else ""


def scheme_is(scheme: str) -> Callable[[str], bool]:
    """A matcher for the URLs of one scheme (case-insensitive, as pyserial reads them)."""
    return lambda port: scheme_of(port) == scheme
