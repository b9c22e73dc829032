"""sigrok session files (``.sr``), read with the standard library's :mod:`zipfile` only.

A session is a zip archive: ``version`` ("2" for every libsigrok since 0.4), ``metadata`` (an
INI file: ``samplerate``, ``total probes``, ``probeN`` names, ``unitsize`` bytes per sample,
``capturefile`` prefix) and the raw samples split into members ``logic-1-1``, ``logic-1-2``, ...
(probe N is bit N-1 of each little-endian ``unitsize``-byte word). Version 1 sessions kept the
samples in one member named after ``capturefile``; both are read. Members are decompressed block
by block, so memory stays a few megabytes whatever the capture's length.
"""

from __future__ import annotations

import configparser
import os
import re
import zipfile
import zlib
from array import array
from collections.abc import Iterator

import numpy as np

from .edges import Edges, transitions
from .errors import CaptureError
from .held_sr import held_edges
from .read_ahead import read_ahead

#: What Python's zipfile raises for a damaged archive or member: besides the obvious, an
#: unknown compression method (NotImplementedError), an "encrypted" flag (RuntimeError), a
#: mangled header field (ValueError): all the file's fault, none the tool's.
ZIP_DAMAGE = (
    zipfile.BadZipFile,
    zlib.error,
    EOFError,
    OSError,
    NotImplementedError,
    RuntimeError,
    ValueError,
)

BLOCK_SAMPLES = 1 << 22  # 4 Mi samples per decompressed block: a few MB, whatever the unitsize
_DTYPES = {1: np.uint8, 2: np.dtype("<u2"), 4: np.dtype("<u4"), 8: np.dtype("<u8")}
_UNITS = {"": 1, "k": 1e3, "m": 1e6, "g": 1e9}


def parse_samplerate(text: str) -> float:
    """``"625 kHz"``, ``"1 MHz"``, ``"100 Hz"`` or a bare number of Hz."""
    m = re.fullmatch(r"\s*([0-9.]+)\s*([kKmMgG]?)(?:[hH][zZ])?\s*", text)
    if not m:
        raise ValueError(text)
    return float(m.group(1)) * _UNITS[m.group(2).lower()]


class Members:
    """A session's sample members in order, each where the archive holds it (the fields
    :meth:`zipfile.ZipFile.open` reads of a :class:`zipfile.ZipInfo`: its header's place,
    compression, sizes, CRC and flags) as numbers, ~60 bytes a member where its ZipInfo and
    the archive's index of it took ~560 (issue 22: a long capture's directory grew with it,
    held while it was decoded). Its ZipInfo is made again when it is read (:meth:`info`);
    its name too, from ``prefix`` and its number (kept as names where one does not read
    back so: ``logic-1-01``)."""

    def __init__(self, prefix: str, infos: list[zipfile.ZipInfo]) -> None:
        self.prefix = prefix
        self.at, self.packed, self.size = array("q"), array("q"), array("q")
        self.crc, self.flags, self.how = array("L"), array("L"), array("L")
        numbers = [n.filename.rsplit("-", 1)[-1] for n in infos]
        self.numbers = array("q", [int(k) if k.isdigit() else -1 for k in numbers])
        names = [self._name(k) for k in self.numbers]
        self.names = None if names == [n.filename for n in infos] else [n.filename for n in infos]
        for info in infos:
            self.at.append(info.header_offset)
            self.packed.append(info.compress_size)
            self.size.append(info.file_size)
            self.crc.append(info.CRC)
            self.flags.append(info.flag_bits)
            self.how.append(info.compress_type)

    def _name(self, number: int) -> str:
        return f"{self.prefix}-{number}"

    def __len__(self) -> int:
        return len(self.at)

    def info(self, i: int) -> zipfile.ZipInfo:
        """Member ``i``'s ZipInfo, made again (what :meth:`zipfile.ZipFile.open` reads)."""
        name = self.names[i] if self.names is not None else self._name(self.numbers[i])
        info = zipfile.ZipInfo(name)
        info.header_offset, info.compress_size, info.file_size = (
            self.at[i], self.packed[i], self.size[i],
        )  # fmt: skip
        info.CRC, info.flag_bits, info.compress_type = self.crc[i], self.flags[i], self.how[i]
        return info


class SrSession:
    """The metadata of one session file, checked, with the zip kept open for reading."""

    def __init__(self, path: str) -> None:
        self.path = path
        try:
            self.zip = zipfile.ZipFile(path)
        except ZIP_DAMAGE as exc:
            raise CaptureError(path, f"not a readable sigrok session (zip): {exc}") from None
        names = set(self.zip.namelist())
        if "metadata" not in names:
            raise CaptureError(
                path, "zip archive without a 'metadata' member: not a sigrok session"
            )
        ini = configparser.ConfigParser(interpolation=None, strict=False)
        try:
            ini.read_string(self.zip.read("metadata").decode("utf-8", "replace"))
        except (configparser.Error, *ZIP_DAMAGE) as exc:
            raise CaptureError(path, f"unreadable 'metadata': {exc}") from None
        if not ini.has_section("device 1"):
            raise CaptureError(path, "'metadata' has no [device 1] section")
        dev = ini["device 1"]
        try:
            self.samplerate = parse_samplerate(dev.get("samplerate", ""))
        except ValueError:
            raise CaptureError(path, f"bad samplerate {dev.get('samplerate')!r}") from None
        if self.samplerate <= 0:
            raise CaptureError(path, "samplerate is zero")
        self.unitsize = dev.getint("unitsize", fallback=1)
        if self.unitsize not in _DTYPES:
            raise CaptureError(path, f"unsupported unitsize {self.unitsize}")
        prefix = dev.get("capturefile", "logic-1")
        self.probes: dict[str, int] = {}  # name -> bit
        for key, value in dev.items():
            m = re.fullmatch(r"probe(\d+)", key)
            if m:
                self.probes[value] = int(m.group(1)) - 1
        if not self.probes:
            raise CaptureError(path, "no logic channels (probeN) in 'metadata'")
        chunked = [n for n in names if re.fullmatch(re.escape(prefix) + r"-\d+", n)]
        chunked.sort(key=lambda n: int(n.rsplit("-", 1)[1]))
        members = chunked or ([prefix] if prefix in names else [])
        if not members:
            raise CaptureError(path, f"no sample data ('{prefix}-1', ...) in the archive")
        self.members = Members(prefix, [self.zip.getinfo(n) for n in members])
        # the archive's own directory of every entry let go: read from here by the members'
        # numbers alone (an hour at 1 MHz is ~860 members of 4 Mi samples; their ZipInfo
        # objects, names and index took 0.55 MB, four hours' 2.0 MB, held while decoding)
        self.zip.filelist, self.zip.NameToInfo = [], {}

    def blocks(self) -> Iterator[np.ndarray]:
        """The samples as arrays of ``unitsize`` words, a block at a time, across members."""
        dtype = _DTYPES[self.unitsize]
        size = BLOCK_SAMPLES * self.unitsize
        rest = b""
        for i in range(len(self.members)):
            member = self.members.info(i)
            try:
                with self.zip.open(member) as fh:
                    while True:
                        data = fh.read(size)
                        if not data:
                            break
                        if rest:
                            data, rest = rest + data, b""
                        cut = len(data) - len(data) % self.unitsize
                        data, rest = data[:cut], data[cut:]
                        yield np.frombuffer(data, dtype=dtype)
            except ZIP_DAMAGE as exc:
                raise CaptureError(
                    self.path, f"corrupt sample data in '{member.filename}': {exc}"
                ) from None

    def busiest_probe(self) -> str:
        """The probe that changes most in the first block (the one carrying traffic)."""
        first = next(self.blocks(), None)
        if first is None:
            return next(iter(self.probes))
        counts = probe_changes(first, self.probes)
        return max(counts, key=lambda n: counts[n])


def probe_changes(block: np.ndarray, probes: dict[str, int]) -> dict[str, int]:
    """How often each probe (name -> bit) changes level within ``block``: the words that
    differ from the one before are found once for all probes, and each probe's changes
    counted among those few (a block is millions of samples, a line changes level a few
    thousand times), not a whole-block pass per probe."""
    changed = np.flatnonzero(block[1:] != block[:-1])
    flips = block[changed] ^ block[changed + 1]
    return {name: int(np.count_nonzero((flips >> bit) & 1)) for name, bit in probes.items()}


def _transitions(
    block: np.ndarray,
    bit: int,
    previous: int | None,
    offset: int,
    changed: np.ndarray | None = None,
) -> tuple[list[int], int]:
    """:func:`~.edges.transitions` of probe ``bit`` in a block of sample words, as ticks
    (``offset``: the block's first sample), and the probe's last level. The words that
    differ from the one before are found first, across all probes in one pass (``changed``,
    when already found for another probe), and only those few are looked at for the probe's
    bit: a block is millions of samples, a line changes level a few thousand times."""
    if changed is None:
        changed = np.flatnonzero(block[1:] != block[:-1])
    changed = changed[((block[changed] ^ block[changed + 1]) >> bit) & 1 != 0]
    idx = (changed + (offset + 1)).tolist()
    if previous is not None and int(block[0]) >> bit & 1 != previous:
        idx.insert(0, offset)
    return idx, int(block[-1]) >> bit & 1


#: The other probes' edges found in the last whole pass over a session, by the file's
#: identity: ``judge`` decodes a capture's bus channel and then the tool's TX channel, and
#: the second pass inflated and scanned every sample again for the one bit it had skipped
#: (a matrix row's capture: 31 M samples, two fifths of the TX channel's decode). Kept only
#: while their edges stay under :data:`OTHERS_MAX_EDGES` (a long busy capture's are read
#: again), one session at a time.
OTHERS_MAX_EDGES = 1 << 20
_OTHERS: dict[tuple, dict[str, tuple[int, list[list[int]], int]]] = {}


def _identity(path: str) -> tuple | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (os.path.realpath(path), st.st_mtime_ns, st.st_size)


def read_sr(path: str, channel: str | None = None) -> Edges:
    """Edges of one probe of a session (``channel`` by name; default the busiest one). The
    pass over the samples keeps the other probes' edges too (:data:`_OTHERS`), which a
    later read of one of them takes instead of a pass of its own. A session held without its
    samples (:mod:`.held_sr`: a matrix row's export) gives the edges they read back as."""
    held = held_edges(path, channel, BLOCK_SAMPLES)
    if held is not None:
        return held
    key = _identity(path)
    kept = _OTHERS.get(key, {}).get(channel or "") if key is not None else None
    if kept is not None:
        session = SrSession(path)  # its metadata checked as a pass would check it
        session.zip.close()
        return _kept_edges(path, channel or "", session, kept)
    session = SrSession(path)
    notes: list[str] = []
    if channel is None:
        channel = session.busiest_probe() if len(session.probes) > 1 else next(iter(session.probes))
        if len(session.probes) > 1:
            notes.append(f"channel {channel!r} chosen: it changes level most at the start")
    if channel not in session.probes:
        raise CaptureError(
            path, f"no channel {channel!r}; channels present: {', '.join(session.probes)}"
        )
    bit = session.probes[channel]
    total = [0]
    first_level: list[int] = []
    others = _Others(key, session, channel)

    def chunks() -> Iterator[list[int]]:
        previous: int | None = None
        offset = 0
        for block in session.blocks():
            if not block.size:  # as the general reader takes it (-1 if first)
                previous = transitions(block, previous)[1]
                others.empty(block)
                continue
            if previous is None:
                first_level.append(int(block[0]) >> bit & 1)
            changed = np.flatnonzero(block[1:] != block[:-1])
            idx, previous = _transitions(block, bit, previous, offset, changed)
            others.add(block, offset, changed)
            if idx:
                yield idx
            offset += block.size
        total[0] = offset
        others.keep(offset)
        session.zip.close()

    gen = chunks()
    # the starting level is needed before any edge: read the first block now
    first = next(gen, [])
    if not first_level:
        raise CaptureError(path, "the session holds no samples")

    def all_chunks() -> Iterator[list[int]]:
        if first:
            yield first
        yield from gen

    return Edges(
        path=path,
        channel=channel,
        channels=list(session.probes),
        tick_rate=session.samplerate,
        period=1.0 / session.samplerate,
        initial_level=first_level[0],
        chunks=read_ahead(all_chunks()),  # inflated and scanned beside the decoder
        end=lambda: total[0] or None,
        notes=notes,
    )


class _Others:
    """The other probes' edges gathered during one pass (see :data:`_OTHERS`): each probe's
    first level, chunks and last level, as a pass of its own would find them."""

    def __init__(self, key: tuple | None, session: SrSession, channel: str) -> None:
        self.key = key
        self.bits = {n: b for n, b in session.probes.items() if n != channel}
        self.state: dict[str, list] = {n: [None, [], None] for n in self.bits}
        self.edges = 0
        self.live = key is not None and bool(self.bits)

    def empty(self, block: np.ndarray) -> None:
        for st in self.state.values():
            st[2] = transitions(block, st[2])[1]

    def add(self, block: np.ndarray, offset: int, changed: np.ndarray) -> None:
        if not self.live:
            return
        for name, bit in self.bits.items():
            st = self.state[name]
            if st[2] is None:
                st[0] = int(block[0]) >> bit & 1
            idx, st[2] = _transitions(block, bit, st[2], offset, changed)
            if idx:
                st[1].append(idx)
                self.edges += len(idx)
        if self.edges > OTHERS_MAX_EDGES:
            self.live = False
            self.state.clear()

    def keep(self, total: int) -> None:
        if not self.live or self.key is None:
            return
        _OTHERS.clear()
        _OTHERS[self.key] = {
            n: (st[0], st[1], total) for n, st in self.state.items() if st[0] is not None
        }


def _kept_edges(
    path: str, channel: str, session: SrSession, kept: tuple[int, list[list[int]], int]
) -> Edges:
    """The edges of ``channel`` a pass over another probe kept (:class:`_Others`)."""
    first_level, chunks, total = kept
    return Edges(
        path=path,
        channel=channel,
        channels=list(session.probes),
        tick_rate=session.samplerate,
        period=1.0 / session.samplerate,
        initial_level=first_level,
        chunks=iter([list(c) for c in chunks]),
        end=lambda: total or None,
        notes=[],
    )
