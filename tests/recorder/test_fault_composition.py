"""Golden-recorder faults that compose (conformance.recorder.compose): a logger with several
deviations at once is one recorder with each fault's parts, and faults that change one thing
apart are refused with the reason, never drawn by the combination sampler."""

from __future__ import annotations

from types import SimpleNamespace

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
        # refused before (rt2): a logger may drop the sign and cut the field; keep ttt in 8
        # bits and read data after half of it; skip the break of a late retry and never
        # break after 87 ms of marking
        ("logs-without-sign", "truncates-values"),
        ("d0-before-ttt", "ttt-8-bit"),
        ("no-break-after-87ms", "retry-too-late"),
        ("late-d0-without-break", "no-break-after-87ms"),
        # refused before (rt3): the first retry after silence timed early or late, the retry
        # after a paused reply without the drain (R-7.2-02 at 12.00 / 95.00 ms and R-7.2-06
        # at -100.00 ms in one transcript); transparent mode without a break of its own
        # beside a logger that rewrites or adds commands ('0I!: sent without a break' beside
        # '$!', the CR LF preamble, XSN!) or interleaves aM!
        ("retry-too-early", "talks-over-reply"),
        ("retry-too-late", "talks-over-reply"),
        ("crlf-wake-up", "transparent-no-break"),
        ("polls-dollar", "transparent-no-break"),
        ("transparent-drops-address", "transparent-no-break"),
        ("interleaves-measurements", "transparent-no-break"),
        # refused before (rt3): the rewriting recorder split the job per command and lost
        # the interleaving (seed 27); it now passes the job on whole
        ("crlf-wake-up", "interleaves-measurements"),
        ("interleaves-measurements", "polls-dollar"),
        ("interleaves-measurements", "transparent-drops-address"),
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


#: Every pair that does not compose, with the part the composer names and why no logger can
#: have both deviations the way each fault states it (test_the_refusals_are_exactly_these).
REFUSED = [
    # one number each: how many sequences (1 and 3), the gap between command characters
    # (3 ms and 1.9 ms)
    (("no-retries", "retries-with-break"), "sequences (1 and 3)"),
    (("command-gap-in-tolerance", "gappy-commands"), "gap"),
    # the first retry after silence at 12 ms, 95 ms or after the 1.5 s poll timeout: one
    # retry, three times
    (("retry-too-early", "retry-too-late"), "silent_retry_time"),
    (("resends-after-timeout", "retry-too-early"), "silent_retry_time"),
    (("resends-after-timeout", "retry-too-late"), "silent_retry_time"),
    # every retry 1.5 s after the last attempt vs the retry into a paused reply: the
    # talking over would never reach the wire
    (("resends-after-timeout", "talks-over-reply"), "retry_time"),
    # aD0! after half of ttt vs a wait with no end for the service request, both for aM!
    (("d0-before-ttt", "waits-forever-for-service-request"), "wait_for_data"),
    # the marking after a break: 20 ms (past the sensor's characters still coming over the
    # break, breaks-over-long-reply) and 5 ms (short-marking)
    (("breaks-over-long-reply", "short-marking"), "post_break_marking"),
]


@pytest.mark.parametrize(("pair", "reason"), REFUSED)
def test_faults_that_change_one_thing_apart_are_refused_with_the_reason(pair, reason):
    assert reason in (composition_conflict(pair) or "")
    with pytest.raises(Refused, match="their own way|both set"):
        faulty_recorder(pair)
    with pytest.raises(PortError, match="do not compose"):
        recorder_faults({"recorder-faults": ",".join(pair)})


def test_the_refusals_are_exactly_these():
    """No pair is refused without its reason in :data:`REFUSED` (a new clash is looked at)."""
    names = sorted(RECORDER_FAULTS)
    refused = {
        (a, b)
        for i, a in enumerate(names)
        for b in names[i + 1 :]
        if composition_conflict((a, b)) is not None
    }
    assert refused == {tuple(sorted(pair)) for pair, _ in REFUSED}


def test_a_retry_after_silence_and_one_after_a_reply_are_timed_by_their_own_faults():
    """retry-too-early + talks-over-reply: the first retry after no reply 12 ms after the
    command (silent_retry_time), one after a paused reply at the engine's own time with no
    wait for a quiet line (EngineRetryHooks: usual() at once)."""
    from conformance.recorder.faults import EARLY_RETRY
    from conformance.tool_recorder.records import Attempt, Exchange

    recorder = faulty_recorder(("retry-too-early", "talks-over-reply"))
    hooks = recorder.master_factory(None, recorder.policy).hooks

    class _Link:
        def now(self) -> float:
            return 1.0

    class _Master:
        link = _Link()

    sent = [SimpleNamespace(end=1.0)]  # the command's last character ended at 1.0 s
    silent = Attempt(None, sent, [], "no reply", end=1.02)
    replied = Attempt(None, sent, [SimpleNamespace(end=1.01)], "no CR LF", end=1.02)
    for attempt, expected in ((silent, 1.0 + EARLY_RETRY), (replied, 7.0)):
        exchange = Exchange(None, "0M!", [attempt])
        assert hooks.retry_time(_Master(), exchange, 0, 2, lambda: 7.0) == expected


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


def test_mislogging_faults_compose_in_one_order():
    """logs-without-sign + truncates-values (refused before: both set the knob ``spoil``):
    the spoils unite and act as a logger writes, the sign dropped, then the field cut."""
    from conformance.protocol.commands import Command, Kind

    recorder = faulty_recorder(("truncates-values", "logs-without-sign"))
    assert len(recorder.spoils) == 2  # type: ignore[attr-defined]
    from conformance.recorder.faults import SPOIL_ORDER

    values = ["-1013.256", "+2.5"]
    for spoil in SPOIL_ORDER:
        if spoil in recorder.spoils:  # type: ignore[attr-defined]
            values = spoil(Command("0", Kind.MEASURE), values)
    assert values == ["1013.25", "+2.5"]


def test_a_skipped_break_passes_the_rest_on_to_the_other_break_rules():
    """retry-too-late + no-break-after-87ms (refused before: both change needs_break): the
    late retry's skipped break is skipped, and otherwise a break goes out only for a new
    address, never for 87 ms of marking."""
    recorder = faulty_recorder(("no-break-after-87ms", "retry-too-late"))
    master = recorder.master_factory(None, recorder.policy)
    hooks = master.hooks

    class _Master:
        last_address = "0"

    def usual() -> bool:
        return True  # the engine's rules: a break (87 ms of marking)

    assert hooks.needs_break(_Master(), "0", 1.0, usual) is False  # no break for marking
    assert hooks.needs_break(_Master(), "1", 1.0, usual) is True  # a new address: a break
    hooks.skip_break = True
    assert hooks.needs_break(_Master(), "1", 1.0, usual) is False  # the skipped one
    assert hooks.needs_break(_Master(), "1", 1.0, usual) is True


def test_all_pairs_are_every_composing_pair():
    pairs = recorder_combinations.all_pairs()
    names = sorted(RECORDER_FAULTS)
    assert len(pairs) == len(set(pairs)) == 658
    assert all(composition_conflict(p) is None and list(p) == sorted(p) for p in pairs)
    refused = [
        (a, b)
        for i, a in enumerate(names)
        for b in names[i + 1 :]
        if composition_conflict((a, b)) is not None
    ]
    assert len(pairs) + len(refused) == len(names) * (len(names) - 1) // 2 == 666


def test_an_unknown_fault_is_named_apart_from_the_known_ones():
    """'mislog-drops-sign,ttt-8-bit': the error says which of the two is not a fault, with a
    near name where one exists, before the list of every fault."""
    with pytest.raises(PortError) as err:
        recorder_faults({"recorder-faults": "mislog-drops-sign,ttt-8-bit"})
    assert str(err.value).startswith("recorder-faults: 'mislog-drops-sign' is not a recorder fault")
    with pytest.raises(PortError, match=r"'retry-to-early' is not .*did you mean retry-too-early"):
        recorder_faults({"recorder-faults": "retry-to-early"})


def _concurrent_waits(port: str) -> list[str]:
    data = run_recorder_suite(port, keyword="concurrent")
    (req,) = (r for r in data["requirements"] if r["id"] == "R-4.4.7-06")
    return [f["detail"] for f in req["findings"]]


@pytest.mark.parametrize("fault", ["crlf-wake-up", "polls-dollar", "transparent-drops-address"])
def test_a_rewriting_logger_measures_concurrent_sensors_together(fault):
    """R-4.4.7-06: the rewriting recorder passes a concurrent job on whole, so its two
    sensors' aC! are started together and the second waits its own ttt as the golden one's
    does (2005..2180 ms); split per command, each was started and collected alone
    (2005..2005 ms), a deviation no fault declares."""
    golden = _concurrent_waits("sim")
    assert any("2005.00..2180.00 ms" in d for d in golden), golden
    assert _concurrent_waits(f"sim://?recorder-faults={fault}") == golden
