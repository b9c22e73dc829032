"""The fault-detection matrix: the suite's own quality metric (design.md 5).

For every emulator fault, run the whole sensor suite against the faulty emulator and compare
the requirements that came out FAIL or WARN with the ones the fault declares it breaks. A fault
caught by exactly its requirements is a rule proven twice; anything else is a false verdict or
an untested rule.
"""

from __future__ import annotations

import multiprocessing
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

from .. import gc_pace
from ..conduct import NoVerdicts, conduct
from ..protocol.version import V14, format_version
from ..run import ConformanceRun, RunOptions

ItemT = TypeVar("ItemT")
RowT = TypeVar("RowT")

BAD = ("FAIL", "WARN")


@dataclass(frozen=True)
class MatrixRow:
    """One fault's run against what it declares.

    Exact means: every declared requirement flagged, nothing else flagged, and the
    INCONCLUSIVE requirements exactly the collateral the fault declares (usually none): a
    fault that silently leaves other rules undecided is a hole the matrix must show. An
    ERROR is never exact.
    """

    fault: str
    declared: tuple[str, ...]
    flagged: tuple[str, ...]  # FAIL or WARN requirements
    verdict: str  # the run's overall verdict
    other: tuple[str, ...]  # INCONCLUSIVE or ERROR requirements, for the reader
    failed: tuple[str, ...] = ()  # the FAIL ones among the flagged
    declared_inconclusive: tuple[str, ...] = ()  # collateral the fault says it leaves open
    #: verdicts judging the run through a capture of itself changed (None: not checked)
    capture: tuple[str, ...] | None = None

    @property
    def missed(self) -> tuple[str, ...]:
        return tuple(r for r in self.declared if r not in self.flagged)

    @property
    def extra(self) -> tuple[str, ...]:
        return tuple(r for r in self.flagged if r not in self.declared)

    @property
    def inconclusive(self) -> tuple[str, ...]:
        return tuple(o.split("=")[0] for o in self.other if o.endswith("=INCONCLUSIVE"))

    @property
    def errors(self) -> tuple[str, ...]:
        return tuple(o.split("=")[0] for o in self.other if o.endswith("=ERROR"))

    @property
    def stray_inconclusive(self) -> tuple[str, ...]:
        return tuple(r for r in self.inconclusive if r not in self.declared_inconclusive)

    @property
    def missing_inconclusive(self) -> tuple[str, ...]:
        return tuple(r for r in self.declared_inconclusive if r not in self.inconclusive)

    @property
    def exact(self) -> bool:
        return not (
            self.missed
            or self.extra
            or self.stray_inconclusive
            or self.missing_inconclusive
            or self.errors
            or self.capture
        )

    def explain(self) -> str:
        """One line naming every way the row is not exact."""
        parts = [
            f"{label} {list(ids)}"
            for label, ids in (
                ("missed", self.missed),
                ("also flagged", self.extra),
                ("undeclared INCONCLUSIVE", self.stray_inconclusive),
                ("declared INCONCLUSIVE but decided", self.missing_inconclusive),
                ("ERROR", self.errors),
                ("changed through a capture", self.capture or ()),
            )
            if ids
        ]
        return f"{self.fault}: " + ("; ".join(parts) or "exact")


def row_from(
    fault: str, declared: tuple[str, ...], data: dict, inconclusive: tuple[str, ...] = ()
) -> MatrixRow:
    """Compare one run's verdicts with what the fault declares (``inconclusive``: the
    collateral INCONCLUSIVEs it declares)."""
    reqs = data["requirements"]
    return MatrixRow(
        fault,
        declared,
        tuple(r["id"] for r in reqs if r["verdict"] in BAD),
        data["summary"]["verdict"],
        tuple(
            f"{r['id']}={r['verdict']}" for r in reqs if r["verdict"] in ("INCONCLUSIVE", "ERROR")
        ),
        tuple(r["id"] for r in reqs if r["verdict"] == "FAIL"),
        tuple(inconclusive),
    )


#: one matrix item: fault, the requirements it declares, its version ("14"), extra
#: RunOptions fields as (name, value) pairs
Item = tuple[str, tuple[str, ...], str, tuple[tuple[str, Any], ...]]


def fault_port(item: Item) -> str:
    fault, _, version, _ = item
    return f"sim://?faults={fault}&version={format_version(version)}"  # "13" is version=1.3


def fault_row(item: Item, data: dict) -> MatrixRow:
    from ..emulator import FAULTS

    fault, declared, _, _ = item
    return row_from(fault, declared, data, tuple(FAULTS[fault].inconclusive))


def matrix_run(
    report_dir: Path, port: str, role: str = "sensor", **options: Any
) -> tuple[ConformanceRun, dict]:
    """The run :func:`conformance.conduct.run_into` makes, writing no report file, and its
    verdict lines: a matrix row reads its verdicts from memory
    (:meth:`ConformanceRun.verdict_lines`, what a row reads of verdicts.json; the report
    files cost about a seventh of a row's CPU)."""
    report_dir.mkdir(parents=True, exist_ok=True)
    given = RunOptions(port=port, role=role, report_dir=str(report_dir), **options)
    result = conduct(given, html=False, rootdir=report_dir, files=())
    lines = result.run.verdict_lines() if result.run is not None else None
    if result.run is None or lines is None:
        raise NoVerdicts(
            f"the {role} suite against {port} gave no verdicts (pytest exit {result.pytest_code})"
        )
    return result.run, lines


def matrix_verdicts(port: str, role: str = "sensor", **options: Any) -> dict:
    """:func:`matrix_run`'s verdict lines, in a folder of its own removed after."""
    with tempfile.TemporaryDirectory(prefix=f"sdi12-{role}-") as tmp:
        return matrix_run(Path(tmp), port, role, **options)[1]


def _row(item: Item) -> MatrixRow:
    return fault_row(item, matrix_verdicts(fault_port(item), **dict(item[3])))


def fault_matrix(
    faults: list[str] | None = None,
    processes: int = 2,
    progress: Callable[[int, int, MatrixRow], None] | None = None,
    row: Callable[[Item], MatrixRow] = _row,
) -> list[MatrixRow]:
    """One row per fault (all of them by default), run ``processes`` at a time;
    ``progress(done, total, row)`` hears of each row as it arrives (the whole matrix takes
    minutes). ``row`` makes one row from an item in a worker process (a module-level
    function: :func:`conformance.matrices.roundtrip.row_through_capture` adds the capture check)."""
    from ..emulator import FAULTS

    # a bus fault shows only beside other sensors: the bus cases' matrix proves it
    names = faults or sorted(n for n, f in FAULTS.items() if not f.bus)
    items = [
        (n, tuple(FAULTS[n].violates), getattr(FAULTS[n], "version", None) or V14, ())
        for n in names
    ]
    return run_rows(items, row, processes, progress, role="sensor")


#: rows a worker makes in one pytest session at most (fewer when the rows are few: every
#: worker should get about three batches, so none is left alone with a long last one)
BATCH = 8


def run_rows(
    items: Sequence[ItemT],
    make: Callable[[ItemT], RowT],
    processes: int,
    progress: Callable[[int, int, RowT], None] | None = None,
    role: str | None = None,
) -> list[RowT]:
    """``make(item)`` for each item, ``processes`` at a time in spawned workers (a fresh
    process keeps runs apart), in the items' order; ``progress(done, total, row)`` hears of
    each row as it arrives. ``role``: the rows' ``role`` runs are judged a batch of rows at
    a time in one pytest session (:func:`conformance.many_runs.judged_in_one_session`:
    collected once, not once a run); None: each run a session of its own."""
    rows: list[RowT] = []

    def keep(made: RowT) -> None:
        rows.append(made)
        if progress is not None:
            progress(len(rows), len(items), made)

    processes = min(processes, len(items))  # a worker for no row costs a whole start-up
    make = partial(paced_row, make)  # the collector once a row (gc_pace.one_row)
    if processes <= 1:
        if role is None:
            for item in items:
                keep(make(item))
        else:
            from ..many_runs import judged_in_one_session

            judged_in_one_session(lambda: [keep(make(item)) for item in items], role)
        return rows
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(processes) as pool:
        if role is None:
            for made in pool.imap(make, items, chunksize=1):
                keep(made)
            return rows
        size = max(1, min(BATCH, len(items) // (3 * processes)))
        batches = [list(items[i : i + size]) for i in range(0, len(items), size)]
        for batch in pool.imap(partial(rows_in_one_session, make, role), batches, chunksize=1):
            for made in batch:
                keep(made)
    return rows


def paced_row(make: Callable[[ItemT], RowT], item: ItemT) -> RowT:
    """``make(item)`` with the collector paused, the row's cyclic garbage collected at its
    end (:func:`conformance.gc_pace.one_row`): what :func:`run_rows` makes each row with."""
    with gc_pace.one_row():
        return make(item)


def rows_in_one_session(
    make: Callable[[ItemT], RowT], role: str, items: Sequence[ItemT]
) -> list[RowT]:
    """``make(item)`` for each item, their ``role`` runs judged in one pytest session (a
    worker's batch in :func:`run_rows`)."""
    from ..many_runs import judged_in_one_session

    return judged_in_one_session(lambda: [make(item) for item in items], role)
