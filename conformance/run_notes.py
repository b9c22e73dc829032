"""Notes the console prints under a run's summary when the run is not quite what was asked:
a ``--req`` that judged more requirements than it named, a ``--sdi-version`` that is not the
version the device reports. Pure functions of the run's ``verdicts.json`` data, so the report
and the console cannot disagree."""

from __future__ import annotations

from typing import Any

from .protocol.version import VERSIONS, format_version, parse_version

SHOWN = 6  # requirement IDs named before "..."


def _ids(ids: list[str]) -> str:
    head = ", ".join(ids[:SHOWN])
    return head + (", ..." if len(ids) > SHOWN else "")


def req_pulled_in(data: dict[str, Any], asked: set[str], wanted: list[str]) -> str | None:
    """Why a ``--req`` run judged requirements it did not name: a case is run whole, and the
    cases that judge the named ones judge these too (None: it judged only what it named)."""
    if not asked:
        return None
    selected = sorted(
        r["id"] for r in data["requirements"] if r["testable"] and r.get("selected", True)
    )
    extra = [rid for rid in selected if rid not in asked]
    if not extra:
        return None
    named = " ".join(f"--req {w}" for w in wanted)
    return (
        f"{named} names {len(asked)} requirement(s); {len(selected)} were judged: the cases "
        f"that judge {'it' if len(asked) == 1 else 'them'} also judge {len(extra)} other(s) "
        f"({_ids(extra)}), and a case runs whole"
    )


def version_mismatch(data: dict[str, Any], forced: str | None) -> str | None:
    """``--sdi-version`` forced a rule set the device's ``aI!`` does not report (None: it
    matches, was not forced, or the device gave no version)."""
    if not forced or data["run"]["role"] != "sensor":
        return None
    ident = (data["dut"].get("identification") or "").strip()
    reported = ident[1:3]
    if len(ident) < 3 or reported not in VERSIONS:
        return None
    wanted = parse_version(forced)
    if wanted is None or wanted == reported:
        return None
    return (
        f"--sdi-version {forced} judged the device by the v{format_version(wanted)} rules, but "
        f"its aI! reports v{format_version(reported)} ({ident!r}): a FAIL on a "
        f"v{format_version(wanted)}-only rule may be a rule the device never claimed"
    )
