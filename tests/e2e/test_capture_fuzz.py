"""Damaged captures given to ``judge``: a clear error naming the file (exit 4) or a verdict,
never an internal error (exit 3).

A capture comes from outside the tool (an analyzer, a disk, a mail attachment), so whatever
shape it arrives in is the user's input. Seeded mutations of a real export in each of the
three formats: bytes flipped, a cut, a stretch duplicated, and for a sigrok session (a zip)
members dropped. Seen before: a flipped byte in a .sr member header raised
``NotImplementedError: That compression method is not supported`` (exit 3).
"""

from __future__ import annotations

import io
import random
import zipfile
from pathlib import Path

import pytest

from conformance.cli import main

FORMATS = ("sr", "csv", "vcd")
QUICK = 4  # mutations of each kind and format in the default selection
MANY = 25  # with -m slow


def flip(data: bytes, rng: random.Random) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        out[rng.randrange(len(out))] ^= 1 << rng.randrange(8)
    return bytes(out)


def cut(data: bytes, rng: random.Random) -> bytes:
    return data[: rng.randrange(1, len(data))]


def duplicate(data: bytes, rng: random.Random) -> bytes:
    start = rng.randrange(len(data))
    end = min(len(data), start + rng.randint(1, 4096))
    return data[:end] + data[start:end] + data[end:]


def drop_member(data: bytes, rng: random.Random) -> bytes:
    """A sigrok session with one of its zip members gone (others: a cut, as for any file)."""
    try:
        source = zipfile.ZipFile(io.BytesIO(data))
    except zipfile.BadZipFile:
        return cut(data, rng)
    names = source.namelist()
    gone = rng.choice(names)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as out:
        for name in names:
            if name != gone:
                out.writestr(name, source.read(name))
    return buffer.getvalue()


def member_header(data: bytes, rng: random.Random) -> bytes:
    """A byte of a zip member's local header changed (the compression method, flags, sizes):
    what a damaged .sr looked like when it gave exit 3."""
    out = bytearray(data)
    heads = [i for i in range(len(out) - 30) if out[i : i + 4] == b"PK\x03\x04"]
    if not heads:
        return flip(data, rng)
    at = rng.choice(heads) + rng.randrange(4, 30)
    out[at] = rng.randrange(256)
    return bytes(out)


MUTATIONS = {
    "flip": flip,
    "cut": cut,
    "duplicate": duplicate,
    "drop-member": drop_member,
    "member-header": member_header,
}


@pytest.fixture(scope="module")
def captures(tmp_path_factory) -> dict[str, bytes]:
    """A short clean simulated run, exported in each format."""
    where = tmp_path_factory.mktemp("captures")
    run = where / "run"
    assert main(["--port", "sim", "--report-dir", str(run), "-k", "test_identification"]) == 0
    found = {}
    for fmt in FORMATS:
        path = where / f"capture.{fmt}"
        assert main(["export", str(run), "--to", fmt, "-o", str(path)]) == 0
        found[fmt] = path.read_bytes()
    return found


def judged(data: bytes, fmt: str, where: Path, capsys) -> tuple[int, str]:
    path = where / f"damaged.{fmt}"
    path.write_bytes(data)
    code = main(["judge", str(path), "--report-dir", str(where / "report")])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def check(fmt: str, kind: str, seed: int, captures, tmp_path, capsys) -> None:
    rng = random.Random(f"{fmt}-{kind}-{seed}")
    data = MUTATIONS[kind](captures[fmt], rng)
    code, text = judged(data, fmt, tmp_path, capsys)
    assert code != 3, f"{kind} seed {seed}: exit 3\n{text[-2000:]}"
    assert "internal error" not in text and "Traceback" not in text, text[-2000:]
    if code == 4:
        assert "damaged." in text, text[-2000:]  # the error names the file


#: every mutation of every format (a zip member exists only in a sigrok session)
KINDS = [
    (fmt, kind)
    for fmt in FORMATS
    for kind in sorted(MUTATIONS)
    if fmt == "sr" or kind not in ("drop-member", "member-header")
]


@pytest.mark.parametrize("seed", range(QUICK))
@pytest.mark.parametrize(("fmt", "kind"), KINDS)
def test_a_damaged_capture_is_an_error_or_a_verdict(fmt, kind, seed, captures, tmp_path, capsys):
    check(fmt, kind, seed, captures, tmp_path, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(QUICK, MANY))
@pytest.mark.parametrize(("fmt", "kind"), KINDS)
def test_many_damaged_captures(fmt, kind, seed, captures, tmp_path, capsys):
    check(fmt, kind, seed, captures, tmp_path, capsys)


@pytest.mark.parametrize("member", ["metadata", "logic-1-1", "sdi12-conform-comment"])
def test_a_session_member_with_an_unknown_compression_method(member, captures, tmp_path, capsys):
    """The damage seen to give exit 3: a member's compression method no zip reader knows
    (in the central directory, which is what Python's zipfile reads it from)."""
    data = bytearray(captures["sr"])
    at = -1
    while True:
        at = data.index(b"PK\x01\x02", at + 1)
        size = int.from_bytes(data[at + 28 : at + 30], "little")
        if data[at + 46 : at + 46 + size].decode() == member:
            break
    data[at + 10 : at + 12] = (99).to_bytes(2, "little")
    code, text = judged(bytes(data), "sr", tmp_path, capsys)
    if member == "sdi12-conform-comment":  # the notes are lost: the capture judged passively
        assert code in (0, 1, 2) and "judged passively" in text, text
        return
    assert code == 4, text
    assert "damaged.sr" in text and "compression" in text, text
