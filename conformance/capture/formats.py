"""Which kind of recording a file is, from its content (the extension is only a hint: files
get renamed, and an analyzer's export may carry any suffix)."""

from __future__ import annotations

import os

from .edges import Edges
from .errors import CaptureError
from .saleae import read_csv
from .sigrok import read_sr
from .vcd import read_vcd

CAPTURE_FORMATS = ("sr", "vcd", "csv")
_VCD_KEYWORDS = (b"$date", b"$version", b"$timescale", b"$comment", b"$scope", b"$var")


def sniff(path: str) -> str:
    """``"sr"``, ``"vcd"``, ``"csv"`` or ``"jsonl"`` (a transcript); :class:`CaptureError`
    for anything else."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise CaptureError(path, f"cannot read: {exc.strerror or exc}") from None
    if not head:
        raise CaptureError(path, "empty file")
    if head.startswith(b"PK\x03\x04") or head.startswith(b"PK\x05\x06"):
        return "sr"
    # binary first: the text formats are told apart by their first characters, and random
    # bytes that happen to start with '{' (after bytes that strip as whitespace) are no
    # transcript (1 file in about 200 was sniffed as one)
    printable = sum(32 <= c < 127 or c in b"\r\n\t" for c in head)
    if b"\0" in head or printable < 0.9 * len(head):
        raise CaptureError(
            path, "binary data that is neither a sigrok session (zip) nor any known capture"
        )
    text = head.lstrip()
    if text.startswith(_VCD_KEYWORDS):
        return "vcd"
    if text.startswith(b"{"):
        return "jsonl"
    first = text.split(b"\n", 1)[0].replace(b" ", b"").lower()
    if first.startswith(b"time") and b"," in first:
        return "csv"
    ext = os.path.splitext(path)[1].lower()
    raise CaptureError(
        path,
        f"unknown format{f' (extension {ext})' if ext else ''}: expected a sigrok .sr session, "
        "a VCD, a Saleae CSV export or a transcript.jsonl",
    )


def read_edges(path: str, channel: str | None = None, fmt: str | None = None) -> Edges:
    """Edges of one channel of a capture of any supported format (detected by content)."""
    fmt = fmt or sniff(path)
    if fmt == "sr":
        return read_sr(path, channel)
    if fmt == "vcd":
        return read_vcd(path, channel)
    if fmt == "csv":
        return read_csv(path, channel)
    raise CaptureError(path, f"a {fmt} file is a transcript, not a logic-analyzer capture")
