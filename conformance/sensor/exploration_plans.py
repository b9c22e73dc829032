"""The exploration's plans (the steps hypothesis draws), stored once per installation.

A derandomised exploration draws the same steps in every process (``exploration_machine.
plan_for``: nothing drawn depends on the sensor), yet each process imported hypothesis
(about 0.065 s of CPU) and drew them again (about 0.07 s): together some 15% of a whole
``sdi12-conform --port sim`` process (issue 22). As ``__pycache__`` keeps a module's
bytecode, the first process that draws a plan writes it beside the package's bytecode, and a
later one sends it (:mod:`.exploration_steps`) without loading hypothesis at all.

A stored plan stands only for the draws it was made from: its key is a digest of everything
those draws read (the interpreter's version, hypothesis's version file, the source of the
modules that make the rules, strategies, settings and the junk filter, and the run's
foreign addresses, examples and steps), so a change to any of them draws afresh. Only the
exploration's own junk strategy is stored (a caller's ``exploration.JUNK`` is drawn each
process), only a plan drawn by a hypothesis loaded without the environment's plugins is
written (``exploration._machine_module``), and nothing is written where bytecode may not be
(``PYTHONDONTWRITEBYTECODE``, ``-B``) or the folder cannot be written: then each process
draws, as before. ``tests/sensor/test_exploration_plans.py`` holds a stored plan to what
hypothesis sends.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import json
import sys
from pathlib import Path

from .exploration_steps import RULES, Plan

#: the package's own bytecode folder, where the plans' file goes
FOLDER = Path(__file__).resolve().parent.parent / "__pycache__"

#: the modules whose code decides what is drawn (relative to the package): the rules and
#: settings, the commands and the junk filter (and the command parser it asks), the draws'
#: guards (local constants, database key), and this key
SOURCES = (
    "sensor/exploration_machine.py",
    "sensor/exploration_record.py",
    "sensor/exploration.py",
    "sensor/exploration_plans.py",
    "protocol/commands.py",
)

#: the plans a file keeps at most (one per address set, examples and steps a process used)
LIMIT = 16

#: the file's format (a reader of another format draws afresh)
FORMAT = 1


class PlanStore:
    """The plans' file in ``folder``; ``reading`` False: no stored plan is sent (tests that
    want hypothesis to draw, ``exploration.forget_plans``)."""

    def __init__(self, folder: Path = FOLDER) -> None:
        self.folder = folder
        self.reading = True

    @property
    def path(self) -> Path:
        return self.folder / f"exploration_plans.{sys.implementation.cache_tag}.json"

    def load(self, key: str) -> Plan | None:
        """The plan stored under ``key``, or None (none, unreadable, or not a plan)."""
        if not self.reading:
            return None
        return as_plan(self._read().get(key))

    def store(self, key: str, plan: Plan) -> bool:
        """Write ``plan`` under ``key`` first, then the others the file held (up to
        :data:`LIMIT`); False where bytecode may not be written or the folder cannot be."""
        if sys.dont_write_bytecode:
            return False
        plans = {key: [[[name, args] for name, args in example] for example in plan]}
        for other, held in self._read().items():
            if len(plans) < LIMIT and other not in plans:
                plans[other] = held
        text = json.dumps({"format": FORMAT, "plans": plans})
        try:
            from ..atomic import atomic_path

            self.folder.mkdir(exist_ok=True)
            with atomic_path(self.path) as temp:
                temp.write_text(text, encoding="utf-8")
        except OSError:  # an install the user cannot write to: drawn again next time
            return False
        return True

    def _read(self) -> dict[str, object]:
        try:
            document = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {}
        if not isinstance(document, dict) or document.get("format") != FORMAT:
            return {}
        plans = document.get("plans")
        return plans if isinstance(plans, dict) else {}


#: the process's store
STORE = PlanStore()


def as_plan(held: object) -> Plan | None:
    """``held`` (a plan as its JSON reads back) as a plan, or None where any step is not a
    rule's name with its drawn arguments (a damaged or foreign file draws afresh)."""
    if not isinstance(held, list):
        return None
    plan = []
    for example in held:
        if not isinstance(example, list):
            return None
        steps = []
        for step in example:
            if not (isinstance(step, list) and len(step) == 2 and step[0] in RULES):
                return None
            name, args = step
            if not isinstance(args, dict) or not all(
                type(k) is str and type(v) in (str, float) for k, v in args.items()
            ):
                return None
            steps.append((name, args))
        plan.append(tuple(steps))
    return tuple(plan)


def plan_key(foreign: list[str], examples: int, steps: int) -> str | None:
    """The digest a plan is stored under (see the module's doc); None where hypothesis's
    version cannot be read (nothing is stored or sent then)."""
    digest = hashlib.sha256()
    spec = importlib.util.find_spec("hypothesis")  # found, not imported
    if spec is None or spec.origin is None:
        return None
    package = Path(__file__).resolve().parent.parent
    try:
        digest.update(Path(spec.origin).with_name("version.py").read_bytes())
        for source in SOURCES:
            digest.update(source.encode() + b"\0" + (package / source).read_bytes())
    except OSError:
        return None
    given = json.dumps([sys.version, sys.implementation.cache_tag, foreign, examples, steps])
    digest.update(given.encode())
    return digest.hexdigest()


def send_nothing_stored() -> None:
    """Send no stored plan in this process from now on (``exploration.forget_plans``)."""
    STORE.reading = False


def quietly_store(key: str, plan: Plan) -> None:
    """:meth:`PlanStore.store`, never a reason for a run to fail (a cache)."""
    with contextlib.suppress(Exception):
        STORE.store(key, plan)
