"""What changed between two runs (``sdi12-conform diff A B``, ``--baseline DIR``).

A firmware team gates each commit on "nothing got worse than the last good run", not only on
COMPLIANT: a device with known deviations still must not gain new ones. So the comparison is
a pure function over two ``verdicts.json`` documents, and "worse" is decided from verdicts and
findings only:

- a requirement whose verdict moved up :data:`SEVERITY` (PASS to INCONCLUSIVE, WARN to FAIL ..);
- a FAIL, WARN or ERROR finding in B that A does not have (a new deviation under a rule that
  was already failing counts: it is new work for the team).

Timing margins and the identification are listed, never "worse" by themselves: a measured
figure moves between two runs of the same firmware by up to its uncertainty, so a margin is
reported only when it moved by more than both runs' uncertainties together, and the verdict
of its rule already says whether the limit still holds.

Findings are matched by requirement, case, verdict and their text with the numbers taken
out, so "4 values were returned for 9 announced" and "3 values ..." are the same deviation
seen twice, while a deviation of another kind under the same rule is new.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

#: how bad a verdict is, for "worse": N/A is as good as PASS (a rule that does not apply),
#: INCONCLUSIVE worse (a rule that was judged no longer is), ERROR as bad as FAIL
SEVERITY = {"PASS": 0, "N/A": 0, "INCONCLUSIVE": 1, "WARN": 2, "FAIL": 3, "ERROR": 3}
#: findings whose appearance is a new deviation (or a broken case)
FLAGGED = ("FAIL", "WARN", "ERROR")
#: smallest move of a measured figure worth a line when both runs' uncertainty is 0 (sim)
MIN_MOVE_MS = 0.005
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


class DiffError(ValueError):
    """A run that cannot be compared: missing, not a verdicts file, another role."""


@dataclass(frozen=True)
class Change:
    """One line of the comparison."""

    kind: str  # verdict | finding-added | finding-gone | margin | identification | catalog
    requirement: str | None
    text: str
    worse: bool = False
    better: bool = False


def load_run(path: str | Path) -> dict:
    """A run folder (its ``verdicts.json``) or a ``verdicts.json`` file, as a dict."""
    p = Path(path)
    file = p / "verdicts.json" if p.is_dir() else p
    if not file.is_file():
        where = "no verdicts.json in the folder" if p.is_dir() else "no such file"
        raise DiffError(f"{path}: {where}")
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DiffError(f"{file}: not a readable verdicts.json ({exc})") from None
    if not isinstance(data, dict) or not str(data.get("schema", "")).startswith(
        "sdi12-conform/verdicts/"
    ):
        raise DiffError(f"{file}: not an sdi12-conform verdicts.json (no schema key)")
    return data


def role_of(data: dict) -> str:
    return str(data.get("run", {}).get("role", "sensor"))


def diff_runs(a: dict, b: dict) -> list[Change]:
    """Every change from run ``a`` to run ``b``, worst first within each kind."""
    if role_of(a) != role_of(b):
        raise DiffError(f"one run judged a {role_of(a)}, the other a {role_of(b)}")
    changes = [
        *_verdicts(a, b),
        *_findings(a, b),
        *_margins(a, b),
        *_identification(a, b),
    ]
    return changes


def worse(changes: Iterable[Change]) -> bool:
    return any(c.worse for c in changes)


def _by_id(data: dict) -> dict[str, dict]:
    return {r["id"]: r for r in data.get("requirements", [])}


def _verdicts(a: dict, b: dict) -> list[Change]:
    ra, rb = _by_id(a), _by_id(b)
    out: list[Change] = []
    for rid in sorted(ra.keys() | rb.keys(), key=_order):
        if rid not in ra or rid not in rb:
            side = "B only" if rid not in ra else "A only"
            out.append(Change("catalog", rid, f"{rid} is in {side} (another catalog version)"))
            continue
        if not (ra[rid].get("selected", True) and rb[rid].get("selected", True)):
            continue  # a partial run: a rule one side did not select says nothing
        va, vb = ra[rid]["verdict"], rb[rid]["verdict"]
        if va == vb:
            continue
        sa, sb = SEVERITY.get(va, 3), SEVERITY.get(vb, 3)
        why = _first_detail(rb[rid], vb)
        out.append(
            Change(
                "verdict",
                rid,
                f"{rid}: {va} -> {vb}" + (f" ({why})" if why else ""),
                worse=sb > sa,
                better=sb < sa,
            )
        )
    return out


def _first_detail(req: dict, verdict: str) -> str:
    for f in req.get("findings", []):
        if f.get("verdict") == verdict:
            return _cut(str(f.get("detail", "")), 160)
    return ""


def _cut(text: str, width: int) -> str:
    """``text`` cut to ``width`` with an ellipsis: a detail cut bare ("... wait it out and)")
    reads as the whole finding."""
    return text if len(text) <= width else text[: width - 3] + "..."


def _key(rid: str, f: dict) -> tuple[str, str, str, str]:
    return (rid, str(f.get("test", "")), str(f.get("verdict")), _NUMBER.sub("#", f["detail"]))


def _flagged(data: dict) -> Counter:
    return Counter(
        _key(r["id"], f)
        for r in data.get("requirements", [])
        if r.get("selected", True)
        for f in r.get("findings", [])
        if f.get("verdict") in FLAGGED
    )


def _findings(a: dict, b: dict) -> list[Change]:
    fa, fb = _flagged(a), _flagged(b)
    texts = _details(b) | _details(a)
    out: list[Change] = []
    for key in sorted((fb - fa).keys(), key=lambda k: _order(k[0])):
        out.append(Change("finding-added", key[0], f"{key[0]} {key[2]}: {texts[key]}", worse=True))
    for key in sorted((fa - fb).keys(), key=lambda k: _order(k[0])):
        out.append(Change("finding-gone", key[0], f"{key[0]} {key[2]}: {texts[key]}", better=True))
    return out


def _details(data: dict) -> dict[tuple[str, str, str, str], str]:
    return {
        _key(r["id"], f): _cut(str(f["detail"]), 200)
        for r in data.get("requirements", [])
        for f in r.get("findings", [])
    }


def _timed(data: dict) -> dict[tuple[str, str, float, int], dict]:
    """Timing findings keyed by requirement, case, limit and their order among equals."""
    out: dict[tuple[str, str, float, int], dict] = {}
    for r in data.get("requirements", []):
        seen: Counter = Counter()
        for f in r.get("findings", []):
            if f.get("measured_ms") is None or f.get("limit_ms") is None:
                continue
            base = (r["id"], str(f.get("test", "")), float(f["limit_ms"]))
            out[(*base, seen[base])] = f
            seen[base] += 1
    return out


def _margins(a: dict, b: dict) -> list[Change]:
    ta, tb = _timed(a), _timed(b)
    out: list[Change] = []
    for key in sorted(ta.keys() & tb.keys(), key=lambda k: _order(k[0])):
        fa, fb = ta[key], tb[key]
        ma, mb = float(fa["measured_ms"]), float(fb["measured_ms"])
        ua, ub = float(fa.get("uncertainty_ms") or 0), float(fb.get("uncertainty_ms") or 0)
        if abs(mb - ma) <= max(ua + ub, MIN_MOVE_MS):
            continue
        limit = key[2]
        upper = _upper(fa, fb, limit)
        sign = 1.0 if upper else -1.0
        before, after = sign * (limit - ma), sign * (limit - mb)
        where = (
            "over the limit"
            if after < 0
            else "closer to it"
            if after < before
            else ("further from it")
        )
        out.append(
            Change(
                "margin",
                key[0],
                f"{key[0]}: {ma:.2f} ms ± {ua:.2f} -> {mb:.2f} ms ± {ub:.2f} "
                f"(limit {'≤' if upper else '≥'} {limit:.2f} ms: margin {before:.2f} -> "
                f"{after:.2f} ms, {where})",
            )
        )
    return out


def _upper(fa: dict, fb: dict, limit: float) -> bool:
    """Whether ``limit`` is an upper one: from the finding's own "≤"/"≥", else from the side
    a PASS measured on, else upper (most timed rules are "within")."""
    for f in (fa, fb):
        text = str(f.get("detail", ""))
        if "≥" in text and "≤" not in text:
            return False
        if "≤" in text and "≥" not in text:
            return True
    for f in (fa, fb):
        if f.get("verdict") == "PASS":
            return float(f["measured_ms"]) <= limit
    return True


IDENTITY = ("address", "identification", "sdi12_version")


def _identification(a: dict, b: dict) -> list[Change]:
    da, db = a.get("dut") or {}, b.get("dut") or {}
    return [
        Change("identification", None, f"{k}: {da.get(k)!r} -> {db.get(k)!r}")
        for k in IDENTITY
        if da.get(k) != db.get(k)
    ]


def _order(rid: str) -> tuple:
    """R-4.4.10-02 after R-4.4.9-01: the clause numbers as numbers."""
    return tuple((0, int(p), "") if p.isdigit() else (1, 0, p) for p in re.split(r"[-.]", rid))


KINDS = (
    ("verdict", "verdicts changed"),
    ("finding-added", "findings added"),
    ("finding-gone", "findings gone"),
    ("margin", "timing figures that moved by more than their uncertainty"),
    ("identification", "identification changed"),
    ("catalog", "requirements in one run only"),
)


def diff_text(changes: list[Change], a_name: str, b_name: str) -> list[str]:
    """The comparison as plain lines (console, CI log)."""
    lines = [f"comparing {a_name} (A) with {b_name} (B)"]
    if not changes:
        return [*lines, "no change: the same verdicts and findings"]
    for kind, title in KINDS:
        group = [c for c in changes if c.kind == kind]
        if not group:
            continue
        lines.append(f"{title} ({len(group)}):")
        for c in group:
            mark = "worse" if c.worse else "better" if c.better else "     "
            lines.append(f"  {mark}  {c.text}")
    n = sum(c.worse for c in changes)
    lines.append(
        f"{n} change(s) for the worse" if n else "nothing got worse (exit 0)",
    )
    return lines


def diff_json(changes: list[Change], a_name: str, b_name: str) -> dict:
    return {
        "a": a_name,
        "b": b_name,
        "worse": worse(changes),
        "changes": [asdict(c) for c in changes],
    }
