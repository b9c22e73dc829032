"""One conformance case run alone against the simulated sensor, its verdict for one rule
combined as a run combines its findings: for tests that pin what a case decides on a given
fault (the combination false-pass rows, the standby idles) without a whole run."""

from __future__ import annotations

from conformance.case import Case
from conformance.ports import open_sim, parse_sim
from conformance.preconditions import declared_on
from conformance.results import CaseRecord, counted
from conformance.sensor.session import SensorSession
from conformance.verdicts import Verdict, worst


def sim_session(faults: str = "") -> SensorSession:
    """The reference sensor with ``faults`` (comma-separated; "" for none), discovered."""
    opened = open_sim(parse_sim(f"sim://?faults={faults}" if faults else "sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    return session


def case_rules(case_fn) -> tuple[str, ...]:
    """The requirement IDs a case's ``requirements`` mark names."""
    marks = [m for m in case_fn.pytestmark if m.name == "requirements"]
    return tuple(marks[0].args)


def case_verdict(session: SensorSession, case_fn, rule: str) -> Verdict:
    """``rule``'s verdict from ``case_fn`` alone, its findings combined as the run does."""
    rules = case_rules(case_fn)
    record = CaseRecord(case_fn.__name__, case_fn.__name__, rules)
    case_fn(session, Case(record, preconditions=declared_on(case_fn, rules)))
    findings = [f for f in record.findings if f.requirement == rule]
    return worst(f.verdict for f in counted(findings))
