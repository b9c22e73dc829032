"""How a fault edits the emulator: the reply rewrites and profile transforms that faults
of several families share.

A rewrite sees each :class:`~conformance.emulator.replies.Reply` before it is encoded and
returns it changed, unchanged, or None (silence); a profile transform changes values, counts
or metadata so that value-level faults still go through the normal packing. Helpers that only
one family needs live in that family's module.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any

from ...protocol.commands import Kind
from ..profile import MeasurementSpec, Profile
from ..replies import Reply, ReplyKind
from .model import ProfileTransform, Rewrite

#: The replies that carry measurement data (aDn!).
DATA_REPLIES = (ReplyKind.DATA,)


def only(kinds: Iterable[ReplyKind], change: Callable[[Reply], Reply | None]) -> Rewrite:
    wanted = frozenset(kinds)

    def rewrite(reply: Reply) -> Reply | None:
        return change(reply) if reply.kind in wanted else reply

    return rewrite


def source_kind(reply: Reply) -> Kind | None:
    return reply.source.kind if reply.source is not None else None


def when(match: Callable[[Reply], bool], change: Callable[[Reply], Reply | None]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply | None:
        return change(reply) if match(reply) else reply

    return rewrite


def has_values(reply: Reply) -> bool:
    return len(reply.body) > 1


def set_to(**changes: Any) -> Callable[[Reply], Reply]:
    return lambda reply: replace(reply, **changes)


def silence(reply: Reply) -> None:
    return None


def measure_family(reply: Reply, digits: int) -> bool:
    return reply.kind in (ReplyKind.START, ReplyKind.IDENTIFY) and reply.digits == digits


def packet_rewrite(change: Callable[[Reply], None]) -> Rewrite:
    def rewrite(reply: Reply) -> Reply:
        if reply.kind is ReplyKind.BINARY and reply.binary is not None:
            reply = replace(reply, binary=replace(reply.binary))
            change(reply)
        return reply

    return rewrite


def with_spec(key: str, change: Callable[[MeasurementSpec], MeasurementSpec]) -> ProfileTransform:
    def transform(profile: Profile) -> Profile:
        measurements = dict(profile.measurements)
        measurements[key] = change(measurements[key])
        return replace(profile, measurements=measurements)

    return transform


def toggle_crc(kind: ReplyKind, *, crc: bool, values: bool = True) -> Rewrite:
    """Replies of ``kind`` to commands that ask for a CRC (``crc``) or not, with values or
    without (the bare ``a[<CRC>]`` form), get the opposite: a CRC missing or one nobody
    asked for. Matched on the command, not on the reply's ``crc``: two toggles matched on
    what the other left undid each other (continuous-crc-missing + crc-on-continuous put
    aRC0!'s CRC back, seed 4143)."""
    return when(
        lambda r: r.kind is kind and _asked_crc(r) == crc and has_values(r) == values,
        set_to(crc=not crc),
    )


def _asked_crc(reply: Reply) -> bool:
    """Whether the command ``reply`` answers asked for a CRC: a metadata command by the
    measurement it describes (aIMC_001!, aIHA_001!), others by their own C (its own ``crc``
    where the reply answers no command)."""
    if reply.kind is ReplyKind.METADATA and reply.source is not None:
        return reply.source.returns_crc
    return reply.command.crc if reply.command is not None else bool(reply.crc)
