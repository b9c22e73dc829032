"""A sigrok session's sample members held as numbers (``capture.sigrok.Members``, issue 22,
branch memory25): the archive's own directory (a ZipInfo and an index entry a member, ~580
bytes; four hours at 1 MHz are 3,437 members) is let go once the members are found, each
member's ZipInfo made again when it is read; the samples read are the same."""

from __future__ import annotations

import gc
import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

from conformance.capture import sigrok
from conformance.capture.errors import CaptureError

META = (
    "[global]\nsigrok version=0.5.2\n\n[device 1]\ncapturefile=logic-1\ntotal probes=1\n"
    "samplerate=1 MHz\ntotal analog=0\nprobe1=SDI12\nunitsize=1\n"
)


def session(path: Path, members: dict[str, bytes], compression: int = zipfile.ZIP_DEFLATED):
    with zipfile.ZipFile(path, "w", compression) as zf:
        zf.writestr("version", "2")
        zf.writestr("metadata", META)
        for name, data in members.items():
            zf.writestr(name, data)


def samples(i: int) -> bytes:
    return bytes((i + k) % 2 for k in range(50 + i % 7))


@pytest.mark.parametrize("compression", [zipfile.ZIP_DEFLATED, zipfile.ZIP_STORED])
def test_the_members_read_as_the_archive_reads_them(tmp_path: Path, compression: int):
    path = tmp_path / "s.sr"
    names = [f"logic-1-{i}" for i in (3, 1, 10, 2)]  # out of order in the archive
    session(path, {n: samples(int(n.rsplit("-", 1)[1])) for n in names}, compression)
    read = sigrok.SrSession(str(path))
    assert read.zip.filelist == [] and read.members.names is None  # names made again
    got = b"".join(block.tobytes() for block in read.blocks())
    with zipfile.ZipFile(path) as zf:
        want = b"".join(zf.read(f"logic-1-{i}") for i in (1, 2, 3, 10))
    assert got == want


def test_names_that_do_not_read_back_from_their_number_are_kept(tmp_path: Path):
    path = tmp_path / "s.sr"
    session(path, {"logic-1-01": samples(1), "logic-1-2": samples(2)})
    read = sigrok.SrSession(str(path))
    assert read.members.names == ["logic-1-01", "logic-1-2"]
    assert b"".join(b.tobytes() for b in read.blocks()) == samples(1) + samples(2)
    one = tmp_path / "v1.sr"  # a version 1 session: one member named after capturefile
    session(one, {"logic-1": samples(5)})
    read = sigrok.SrSession(str(one))
    assert read.members.names == ["logic-1"]
    assert np.array_equal(next(read.blocks()), np.frombuffer(samples(5), np.uint8))


def test_a_damaged_member_is_still_named(tmp_path: Path):
    path = tmp_path / "s.sr"
    session(path, {"logic-1-1": samples(1), "logic-1-2": samples(2)})
    read = sigrok.SrSession(str(path))
    read.members.crc[1] ^= 1  # what the directory said of its CRC, wrong: a bad CRC read
    with pytest.raises(CaptureError, match="corrupt sample data in 'logic-1-2'"):
        list(read.blocks())


def test_a_long_session_holds_its_members_as_numbers(tmp_path: Path):
    path = tmp_path / "s.sr"
    n = 3000
    session(path, {f"logic-1-{i}": b"\x00\x01" for i in range(1, n + 1)})
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        read = sigrok.SrSession(str(path))
        gc.collect()  # the archive's directory, let go, freed whatever its cycles
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert len(read.members) == n
    # ~60 bytes a member here (seven arrays); base-s69 ~560 (the archive's directory)
    assert held < 100 * n
    assert sum(len(b) for b in read.blocks()) == 2 * n
