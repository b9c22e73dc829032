"""The SDI-12 versions the tool knows (1.3 and 1.4), as the ``aI!`` reply spells them.

A version is kept as the two digits of the ``aI!`` reply's version field (``"13"``,
``"14"``), everywhere: in declarations, profiles, ``sim://`` specs and verdicts.json's
inputs. These helpers are the one place that writes it dotted for people (``"1.4"``), reads a
dotted one back, and says which of the two is the later.
"""

from __future__ import annotations

V13, V14 = "13", "14"
#: Every version the tool judges, oldest first.
VERSIONS = (V13, V14)


def format_version(version: str) -> str:
    """``"14"`` -> ``"1.4"``: the version as the standard and the user write it."""
    return f"{version[0]}.{version[1:]}"


def parse_version(text: str) -> str | None:
    """``"1.4"``, ``"14"`` (surrounding spaces allowed) -> ``"14"``; None for anything that is
    not a version the tool knows."""
    digits = text.replace(".", "").strip()
    return digits if digits in VERSIONS else None


def is_v14(version: str) -> bool:
    """A device (or rule set) of ``version`` is bound by the v1.4 rules."""
    return version >= V14
