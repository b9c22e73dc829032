"""The one-line comment an exporter may leave in a capture (a .sr member, a VCD ``$comment``).

``sdi12-conform export`` leaves the run's options there, so judging the exported capture can
repeat that run's stimuli against it. Captures from anywhere else have none: None.
"""

from __future__ import annotations

import zipfile

from .formats import sniff
from .writers import SR_COMMENT_MEMBER

VCD_HEADER_LIMIT = 1 << 16  # characters read looking for the comment before giving up


def embedded_comment(path: str) -> str | None:
    """The exporter's comment in the capture at ``path``, or None."""
    fmt = sniff(path)
    if fmt == "sr":
        try:
            with zipfile.ZipFile(path) as zf:
                if SR_COMMENT_MEMBER not in zf.namelist():
                    return None
                return zf.read(SR_COMMENT_MEMBER).decode("utf-8", errors="replace")
        except (zipfile.BadZipFile, OSError):
            return None
    if fmt == "vcd":
        with open(path, encoding="utf-8", errors="replace") as fh:
            header = fh.read(VCD_HEADER_LIMIT)
        header = header.split("$enddefinitions", 1)[0]
        for chunk in header.split("$comment")[1:]:
            text = chunk.split("$end", 1)[0].strip()
            if text:
                return text
    return None
