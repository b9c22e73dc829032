""" "Did you mean": the nearest known names to a mistyped one, for every error that refuses
a name (a subcommand, a fault, a profile). A user who typed ``no-service-requst`` should not
have to read a table of 124 faults to find the one they meant."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

CUTOFF = 0.6  # difflib's ratio below which a name is no longer a plausible typo


def nearest(word: str, known: Iterable[str], n: int = 3) -> list[str]:
    """Up to ``n`` known names close to ``word``, nearest first."""
    return difflib.get_close_matches(word, list(known), n=n, cutoff=CUTOFF)


def did_you_mean(words: Iterable[str], known: Iterable[str]) -> str:
    """`` (did you mean X?)`` for the first of ``words`` that has a near name, else ``""``."""
    names = list(known)
    for word in words:
        close = nearest(word, names)
        if close:
            return f" (did you mean {' or '.join(close)}?)"
    return ""
