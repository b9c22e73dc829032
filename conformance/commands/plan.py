"""``sdi12-conform plan``: the test plan without touching the bus (issue 24).

The suite runs once in virtual time against a simulated sensor playing the declaration (the
golden recorder in the recorder role), and :mod:`conformance.reports.plan` turns that dry
run into the plan. Exit 0 with the plan written; 4 for a usage error (an unreadable
declaration, a selection that matches no case).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any
from urllib.parse import quote

from ..declaration import DeclarationError, load_declaration, normalise_version
from ..emulator.declared import assumptions
from ..exits import EXIT_OK, EXIT_USAGE, say_error
from ..options import ROLES
from ..profiles import PROFILES
from ..protocol.version import format_version
from ..reports.plan import build_plan, plan_html, plan_markdown

FORMATS = ("markdown", "html", "json")


class PlanError(ValueError):
    """Nothing to plan (a usage error)."""


def plan_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform plan",
        description="The test plan, without touching the bus: every case with its "
        "requirement IDs, what it will send, the preconditions it checks, what makes it N/A "
        "for the declaration, and the run's expected bus time (from a dry run in virtual "
        "time against a simulated sensor playing the declaration).",
    )
    p.add_argument("--role", choices=ROLES, default="sensor", help="default: sensor")
    p.add_argument("--declaration", help="the DUT's declaration (TOML; [ttt] times the plan)")
    p.add_argument("--sdi-version", help="1.3 or 1.4 (default: the declaration's, else 1.4)")
    p.add_argument("-k", dest="keyword", help="only cases matching this pytest -k expression")
    p.add_argument("--req", action="append", default=[], metavar="ID_OR_CLAUSE",
                   help="only cases judging this requirement or clause; repeatable")  # fmt: skip
    p.add_argument("--profile", choices=tuple(PROFILES), help="a named selection (production)")
    p.add_argument("--format", choices=FORMATS, default="markdown", help="default: markdown")
    p.add_argument("-o", "--output", help="write the plan here (default: standard output)")
    # not an option of the plan: taken only to say so, since the main command's --port is
    # the first thing a user types (argparse's "unrecognized arguments" says nothing more)
    p.add_argument("--port", help=argparse.SUPPRESS)
    return p


def dry_port(role: str, declaration: str | None, version: str | None) -> str:
    """The simulated device the dry run uses."""
    if role == "recorder":
        return "sim" if version is None else f"sim://?version={format_version(version)}"
    query = []
    if declaration:
        query.append(f"declaration={quote(str(Path(declaration).resolve()))}")
    if version:
        query.append(f"version={format_version(version)}")
    return "sim://?" + "&".join(query) if query else "sim"


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(os.environ.get("SDI12_CACHE_DIR") or Path(base) / "sdi12-conform" / "plans")


def _code_digest() -> str:
    """The suite's own code (the package and its cases): a plan made by other code is not
    this code's plan, whatever the version number says."""
    h = hashlib.sha256()
    root = Path(__file__).resolve().parent
    for folder in (root, root.parent / "testcases"):
        for path in sorted(folder.rglob("*")):
            if path.suffix in (".py", ".json", ".ini") and "__pycache__" not in path.parts:
                h.update(str(path.relative_to(folder)).encode())
                h.update(path.read_bytes())
    return h.hexdigest()


def cached_plan(
    role: str,
    declaration: str | None = None,
    version: str | None = None,
    keyword: str | None = None,
    reqs: tuple[str, ...] = (),
    profile: str | None = None,
) -> dict[str, Any]:
    """:func:`make_plan`, kept on disk: the dry run is deterministic (virtual time), so the
    same code, declaration and selection give the same plan, and a bench that runs the
    same device again and again plans once (``SDI12_CACHE_DIR`` moves the cache)."""
    if declaration:
        load_declaration(declaration)  # a bad file is refused before the cache is read
    key = hashlib.sha256(
        json.dumps(
            [role, version, keyword, list(reqs), profile,
             declaration and str(Path(declaration).resolve()),
             declaration and hashlib.sha256(Path(declaration).read_bytes()).hexdigest(),
             _code_digest()]
        ).encode()
    ).hexdigest()  # fmt: skip
    path = _cache_dir() / f"{key}.json"
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        pass
    plan = make_plan(role, declaration, version, keyword, reqs, profile)
    from ..interrupts import GUARD

    if not GUARD.requested:  # a dry run cut short by Ctrl-C is kept nowhere
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(json.dumps(plan), encoding="utf-8")
            tmp.replace(path)
        except OSError:
            pass  # no cache where none can be written
    return plan


def make_plan(
    role: str,
    declaration: str | None = None,
    version: str | None = None,
    keyword: str | None = None,
    reqs: tuple[str, ...] = (),
    profile: str | None = None,
) -> dict[str, Any]:
    """Dry-run the suite and build its plan (:class:`DeclarationError` for a bad file)."""
    from ..conduct import NoVerdicts, run_into

    declared = load_declaration(declaration) if declaration else None
    digits = normalise_version(version) if version else None
    port = dry_port(role, declaration, digits)
    options = {
        # the recorder role reads its sdi12_version and [recorder] table
        "declaration": str(Path(declaration).resolve()) if declaration else None,
        "version": format_version(digits) if digits else None,
        "keyword": keyword or None,
        "requirements": tuple(reqs),
        "profile": profile,
    }
    with tempfile.TemporaryDirectory(prefix="sdi12-plan-") as tmp:
        try:
            dry = run_into(Path(tmp), port, role, **options)
        except NoVerdicts:  # pytest collected nothing: no verdicts
            raise PlanError("the selection (-k/--req) matches no case: nothing to plan") from None
    said = assumptions(declared) if declared is not None and role == "sensor" else []
    if role == "recorder":
        said = ["timed on the golden recorder: a logger under test paces its own jobs"]
        if declaration:
            said.append(
                "recorder declaration read: commands it declares it cannot send, where the "
                "standard lets it lack them, are not planned; every other job is"
            )
    elif declared is None:
        said = ["no declaration: timed on the reference sensor's profile"]
    selection = {"k": keyword, "req": list(reqs)} if keyword or reqs else None
    if profile:
        selection = (selection or {"k": None, "req": []}) | {"profile": profile}
    return build_plan(
        dry,
        role=role,
        dry_port=port,
        declaration=str(declaration) if declaration else None,
        assumptions=said,
        selection=selection,
    )


def plan_main(argv: list[str]) -> int:
    args = plan_parser().parse_args(argv)
    if args.port is not None:
        say_error(
            "error: plan does not touch the bus, so it takes no --port: its bus time comes "
            "from a dry run against a simulated sensor. Leave --port out; to run the suite "
            f"on {args.port}: sdi12-conform --port {args.port}"
        )
        return EXIT_USAGE
    try:
        plan = make_plan(args.role, args.declaration, args.sdi_version, args.keyword,
                         tuple(args.req), args.profile)  # fmt: skip
    except (DeclarationError, PlanError) as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    text = {
        "json": lambda: json.dumps(plan, indent=2, ensure_ascii=False) + "\n",
        "markdown": lambda: plan_markdown(plan),
        "html": lambda: plan_html(plan),
    }[args.format]()
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
    else:
        print(text, end="")
    return EXIT_OK
