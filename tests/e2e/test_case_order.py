"""Verdicts do not depend on the order the cases run in, nor on which cases a run selects.

The suite runs on the built-in sim (clean and with faults of both kinds a whole-run case
judges: a reply-timing fault and a reply-format fault) in its default order, reversed, in
seeded random orders (a tiny plugin reorders the collected items, as ``pytest -p randomly``
would), and with ``-k`` subsets. Every case's verdict, and every requirement's verdict, must
match the default run. A subset is compared on the requirements all of whose default-run
cases it selected (a requirement it judges with fewer cases is a different question).
"""

from __future__ import annotations

import random
import tempfile

import pytest

from conformance.conduct import conduct
from conformance.run import RunOptions


class Reorder:
    """A pytest plugin object that reorders the collected conformance cases."""

    def __init__(self, how: str, seed: int = 0) -> None:
        self.how = how
        self.seed = seed

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, items: list[pytest.Item]) -> None:
        if self.how == "reversed":
            items.reverse()
        elif self.how == "random":
            random.Random(self.seed).shuffle(items)


def run_suite(role: str, port: str, how: str = "default", seed: int = 0, k: str = "") -> dict:
    """Run the ``role`` suite in this process in the given order; return verdicts.json
    with the order the cases ran in."""
    with tempfile.TemporaryDirectory(prefix="sdi12-order-") as tmp:
        options = RunOptions(port=port, role=role, report_dir=tmp, keyword=k or None)
        result = conduct(options, html=False, rootdir=tmp, plugins=[Reorder(how, seed)])
        assert result.document is not None
        return result.document


def case_verdicts(data: dict) -> dict[str, str]:
    return {t["id"]: t["verdict"] for t in data["tests"]}


def differences(default: dict, other: dict) -> list[str]:
    """Where ``other`` judged something differently from ``default``: any case it ran, and
    any requirement whose default-run cases it all ran."""
    cases = case_verdicts(default)
    ran = case_verdicts(other)
    found = [f"{t}: {cases.get(t)} -> {v}" for t, v in ran.items() if cases.get(t) != v]
    wanted = {r["id"]: r for r in default["requirements"]}
    for r in other["requirements"]:
        base = wanted[r["id"]]
        if base["tests"] and set(base["tests"]) <= set(ran) and base["verdict"] != r["verdict"]:
            found.append(f"{r['id']}: {base['verdict']} -> {r['verdict']}")
    return found


ORDERS = [("reversed", 0), ("random", 1), ("random", 2)]
#: the clean sim, a reply-timing fault and a reply-format fault (both judged by whole-run cases)
SENSOR_PORTS = ["sim", "sim://?faults=response-too-late", "sim://?faults=extended-no-crlf"]
#: faults whose verdicts once hung on what an earlier case left in the sensor: the aRn! a
#: sensor answers only after aR0! (the R/RC pairs are one unit now), and the data an aborted
#: measurement keeps (the abort cases fill the buffer first)
STATEFUL_PORTS = [
    "sim://?faults=continuous-needs-r0-first",
    "sim://?faults=abort-keeps-old-data",
]
_runs: dict[tuple[str, str, str, int], dict] = {}


def ordered_run(role: str, port: str, how: str = "default", seed: int = 0) -> dict:
    """:func:`run_suite` of the whole suite, made once in this process: the sim runs in
    virtual time, so a run depends on nothing but these, and several tests read the same one
    (the default runs; the clean sim reversed, for its order and for its verdicts)."""
    if (role, port, how, seed) not in _runs:
        _runs[role, port, how, seed] = run_suite(role, port, how, seed)
    return _runs[role, port, how, seed]


def default_run(role: str, port: str) -> dict:
    return ordered_run(role, port)


@pytest.mark.slow
def test_whole_run_cases_run_last_whatever_the_order():
    data = ordered_run("sensor", "sim", "reversed")
    order = [t["id"] for t in data["tests"]]
    whole = [i for i, t in enumerate(order) if "test_9_whole_run" in t]
    assert whole and whole == list(range(len(order) - len(whole), len(order))), order
    assert data["run"]["partial"] is False


@pytest.mark.parametrize(
    ("port", "how", "seed"),
    [(p, how, seed) for p in SENSOR_PORTS for how, seed in ORDERS]
    + [(p, how, seed) for p in STATEFUL_PORTS for how, seed in ORDERS[:2]],
)
@pytest.mark.slow
def test_sensor_verdicts_do_not_depend_on_order(port, how, seed):
    default = default_run("sensor", port)
    other = ordered_run("sensor", port, how, seed)
    assert [t["id"] for t in other["tests"]] != [t["id"] for t in default["tests"]]
    assert differences(default, other) == []
    assert other["summary"] == default["summary"]


@pytest.mark.slow
@pytest.mark.parametrize("port", SENSOR_PORTS)
@pytest.mark.parametrize("k", ["test_9_whole_run", "test_4_4_8_data", "test_4_4_8_data or test_9"])
def test_sensor_subsets_judge_like_the_full_run(port, k):
    default = default_run("sensor", port)
    subset = run_suite("sensor", port, k=k)
    assert subset["run"]["partial"] is True
    assert subset["tests"], "the subset selected no case"
    assert differences(default, subset) == []


@pytest.mark.slow
def test_a_whole_run_case_alone_still_sees_the_faulty_replies():
    """-k test_9 on a sensor whose extended reply lacks CR LF: the whole-run case asks for
    the declared extended commands itself, so the FAIL does not depend on test_4_4_13."""
    subset = run_suite("sensor", "sim://?faults=extended-no-crlf", k="test_reply_framing")
    verdicts = {r["id"]: r["verdict"] for r in subset["requirements"]}
    assert verdicts["R-4.2-03"] == "FAIL"


@pytest.mark.slow
@pytest.mark.parametrize(("how", "seed"), [*ORDERS, ("default", 0)])
def test_recorder_verdicts_do_not_depend_on_order(how, seed):
    default = default_run("recorder", "sim")
    if how == "default":  # the whole-run case alone
        other = run_suite("recorder", "sim", k="test_9_whole_run")
    else:
        other = run_suite("recorder", "sim", how, seed)
        assert other["summary"] == default["summary"]
    assert differences(default, other) == []


def test_the_session_knows_when_the_data_buffer_holds_values():
    """A D read with values fills the buffer; any later command to the sensor makes it
    unknown again, and then fill_data_buffer measures anew (and only then)."""
    from conformance.emulator import sim_sensor
    from conformance.sensor.session import SensorSession

    _, link, _ = sim_sensor()
    sensor = SensorSession(link, address="0")
    assert not sensor.master.buffer_holds_values("0")
    sensor.measurement("M")  # aM!, service request, aD0! with values
    assert sensor.master.buffer_holds_values("0")
    sent = len(link.transcript.events)
    sensor.fill_data_buffer("M")
    assert len(link.transcript.events) == sent  # already filled: nothing sent
    sensor.fresh_exchange("I")
    assert not sensor.master.buffer_holds_values("0")
    sensor.fill_data_buffer("M")
    assert sensor.master.buffer_holds_values("0")
    assert len(link.transcript.events) > sent
