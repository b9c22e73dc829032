"""Golden-recorder faults that compose (conformance.recorder.compose): a logger with several
deviations at once is one recorder with each fault's parts, and faults that change one thing
apart are refused with the reason, never drawn by the combination sampler."""

from __future__ import annotations

import pytest

from conformance.links.errors import PortError
from conformance.matrices import recorder_combinations
from conformance.matrices.recorder_matrix import run_recorder_suite
from conformance.recorder.compose import Refused
from conformance.recorder.faults import (
    RECORDER_FAULTS,
    composition_conflict,
    faulty_recorder,
)
from conformance.recorder.golden import GoldenRecorder, GoldenToolRecorder
from conformance.recorder.openers import recorder_faults


def _flagged(port: str) -> set[str]:
    data = run_recorder_suite(port)
    return {r["id"] for r in data["requirements"] if r["verdict"] in ("FAIL", "WARN")}


def test_one_fault_builds_the_recorder_it_always_was():
    """No generated class for a single fault: its runs stay byte-identical."""
    assert type(faulty_recorder(("no-retries",))) is GoldenRecorder
    assert faulty_recorder(("short-break",)).master_factory is GoldenToolRecorder
    assert faulty_recorder(()) == GoldenRecorder(faulty_recorder(()).policy)


@pytest.mark.parametrize(
    "pair",
    [
        # a policy value and an engine subclass (R-7.0-02 and R-4.4.8-05 each)
        ("short-break", "stops-after-d0"),
        # two engine subclasses that both pass collect on (no break before D0 after ttt,
        # and D0 only): both deviations reach the wire through one chained collect
        ("no-break-after-87ms", "stops-after-d0"),
        # engine hooks and a recorder subclass with its knob
        ("ignores-bad-crc", "no-concurrent"),
    ],
)
def test_a_pair_puts_both_deviations_on_the_wire(pair):
    flagged = _flagged(recorder_combinations.combo_port(pair))
    for fault in pair:
        assert set(RECORDER_FAULTS[fault].violates) <= flagged, (fault, flagged)


def test_the_report_names_every_fault_of_a_pair():
    """The assumptions named only the first fault of ``short-break,no-retries``."""
    data = run_recorder_suite("sim://?recorder-faults=short-break,no-retries", keyword="breaks")
    said = " ".join(data["dut"]["assumptions"])
    assert "golden recorder with faults short-break, no-retries" in said, said


def test_two_attempt_hooks_chain():
    """retries-with-break waits a poll timeout before each repeat and ignores-bad-crc takes a
    bad CRC as valid: both hooks' ``attempt`` run, one through the other's super()."""
    master = faulty_recorder(("ignores-bad-crc", "retries-with-break")).master_factory(
        None, faulty_recorder(("retries-with-break",)).policy
    )
    names = [c.__name__ for c in type(master.hooks).__mro__]
    assert names.index("BreakEveryTryHooks") < names.index("GoldenHooks")
    assert names.index("IgnoresCrcHooks") < names.index("GoldenHooks")


@pytest.mark.parametrize(
    ("pair", "reason"),
    [
        (("retry-too-early", "retry-too-late"), "retry_time"),
        (("no-retries", "retries-with-break"), "sequences (1 and 3)"),
        (("command-gap-in-tolerance", "gappy-commands"), "gap"),
        (("logs-without-sign", "truncates-values"), "spoil (_unsigned and _cut)"),
        (("polls-dollar", "transparent-no-break"), "__call__"),
        # the rewriting recorder splits the job per command: the interleaving would be lost
        (("crlf-wake-up", "interleaves-measurements"), "__call__"),
    ],
)
def test_faults_that_change_one_thing_apart_are_refused_with_the_reason(pair, reason):
    assert reason in (composition_conflict(pair) or "")
    with pytest.raises(Refused, match="their own way|both set"):
        faulty_recorder(pair)
    with pytest.raises(PortError, match="do not compose"):
        recorder_faults({"recorder-faults": ",".join(pair)})


def test_same_kind_knobs_unite():
    """no-concurrent and drops-metadata: one logger lacking both sets of commands."""
    lacks = faulty_recorder(("drops-metadata", "no-concurrent")).lacks  # type: ignore[attr-defined]
    assert (
        lacks
        == RECORDER_FAULTS["no-concurrent"].parts.knobs["lacks"]
        | (RECORDER_FAULTS["drops-metadata"].parts.knobs["lacks"])
    )


@pytest.mark.parametrize("size", [2, 3])
def test_the_sampler_never_draws_a_refused_combination(size):
    drawn = recorder_combinations.sample(60, size, seed=7)
    assert len(drawn) == 60 and len(set(drawn)) == 60
    assert all(composition_conflict(c) is None for c in drawn)
    assert drawn == recorder_combinations.sample(60, size, seed=7)
