"""The data rules over the measurements other cases made again (truth35,
conformance.judges.other_waits.judge_other_data): a count short, a reply malformed or a CRC
wrong there FAILs beside the owners' findings, under the data judge's preconditions; what
those measurements cannot decide never outweighs an owner.

The sessions are the simulated sensor; the hand-typed records are those of the host-stall
tests (tests/judges/test_waits_host_stall.py)."""

from __future__ import annotations

from conformance.case import Case
from conformance.judges import measurements as judge
from conformance.judges.other_waits import DATA_IDS, judge_other_data
from conformance.preconditions import declared_on
from conformance.results import CaseRecord
from conformance.verdicts import Finding, Verdict, passed
from testcases.sensor.test_9_whole_run import test_data_of_every_measurement as every_data_case
from tests.judges.test_other_waits import _rule, _session
from tests.judges.test_waits_host_stall import Run

SHORT_AGAIN = "fewer-values-when-repeated"
CRC_IDS = ("R-4.4.12-02", "R-4.4.12-05", "R-4.4.12-06")


def _case(session) -> dict[str, Finding]:
    """The whole-run data case's findings over ``session``'s measurements made again (one
    per rule: no start here lacks a readable count)."""
    record = CaseRecord("every-data", "every-data", DATA_IDS)
    every_data_case(session, Case(record, preconditions=declared_on(every_data_case, DATA_IDS)))
    found = {f.requirement: f for f in record.findings}
    assert len(found) == len(record.findings)
    return found


def test_a_count_short_only_when_measured_again_fails_the_rule():
    """The cached aM! (the owner's) delivers its three values; measured again it delivers two
    for the three it announces: R-4.4.8-03 FAILs, where base-s69 judged only the first and
    PASSed; no other data rule FAILs."""
    session = _session(SHORT_AGAIN)
    owned = session.measurement("M")
    session.fresh_measurement("M")
    (own,) = judge.judge([owned], ["R-4.4.8-03"], session.version)
    assert own.verdict is Verdict.PASS, own.detail
    found = _case(session)
    short = found["R-4.4.8-03"]
    assert short.verdict is Verdict.FAIL, short.detail
    assert "made again" in short.detail and "2 values were returned for 3 announced" in short.detail
    assert _rule([own, short]) is Verdict.FAIL
    others = {f.verdict for r, f in found.items() if r != "R-4.4.8-03"}
    assert others <= {Verdict.PASS, Verdict.NA}, found


def test_the_clean_sensor_measured_again_passes_in_part():
    """PASS in part over a plain aM! made again; the CRC rules, with no CRC asked for
    again, N/A (no owner's verdict changes); aMC! made again brings them in, in part too."""
    session = _session()
    session.measurement("M")
    session.fresh_measurement("M")
    found = _case(session)
    assert found["R-4.4.8-03"].verdict is Verdict.PASS and found["R-4.4.8-03"].partial
    assert {found[rid].verdict for rid in CRC_IDS} == {Verdict.NA}
    session.fresh_measurement("MC")
    found = _case(session)
    assert {found[rid].verdict for rid in CRC_IDS} == {Verdict.PASS}
    assert all(f.partial for f in found.values()), found


def test_a_crc_wrong_when_measured_again_fails_its_rule():
    """wrong-crc's aMC! made again: R-4.4.12-05 FAILs there as the owner's does."""
    session = _session("wrong-crc")
    session.fresh_measurement("MC")
    found = _case(session)
    assert found["R-4.4.12-05"].verdict is Verdict.FAIL, found["R-4.4.12-05"].detail
    assert found["R-4.4.8-03"].verdict is Verdict.PASS


def test_a_partial_pass_alone_does_not_pass_the_rule():
    """Where no owner judged the rule (a partial run), these measurements' PASS is not the
    rule's; beside an owner's PASS it stands."""
    session = _session()
    session.fresh_measurement("M")
    found = _case(session)["R-4.4.8-03"]
    assert _rule([found]) is Verdict.INCONCLUSIVE
    owner = passed("R-4.4.8-03", "conforms", observed=5)
    assert _rule([owner, found]) is Verdict.PASS


def test_a_partial_run_that_measured_nothing_again_measures_once_itself():
    """-k or --req of the data rules alone: no case measured again, so the case makes one
    aM! of its own (as the wait case does) and judges it."""
    session = _session(SHORT_AGAIN)
    session.measurement("M")
    assert not session.remeasured
    found = _case(session)
    assert [m.command.text() for m in session.remeasured] == ["0M!"]
    assert found["R-4.4.8-03"].verdict is Verdict.FAIL


def test_no_measurement_made_again_is_no_verdict():
    found = judge_other_data([], ["R-4.4.8-03"], "14")
    assert [f.verdict for f in found] == [Verdict.NA]
    owner = passed("R-4.4.8-03", "conforms", observed=5)
    assert _rule([owner, *found]) is Verdict.PASS


def _short_read(stalled: bool) -> Run:
    """aM! announcing three values, its request, D0 answered with two (its read stalled
    over where asked), D1 empty."""
    run = Run()
    end = run.exchange("0M!", "00013\r\n")
    run.sensor("0\r\n", end + 0.5)
    run.exchange("0D0!", "0+22.15+1013.2\r\n", stalled=stalled)
    run.exchange("0D1!", "0\r\n")
    return run


def test_a_reply_read_across_a_stall_leaves_the_owner_s_pass():
    """A D reply the host stalled over may be cut: the short count there is undecided,
    observed 0, so the owner's PASS stands; the same reply outside any stall FAILs."""
    held = judge_other_data(_short_read(True).recorded().measurements, ["R-4.4.8-03"], "14")
    assert [f.verdict for f in held] == [Verdict.INCONCLUSIVE], held
    assert held[0].observed == 0 and "stalled" in held[0].detail
    owner = passed("R-4.4.8-03", "conforms", observed=5)
    assert _rule([owner, *held]) is Verdict.PASS
    late = judge_other_data(_short_read(False).recorded().measurements, ["R-4.4.8-03"], "14")
    assert [f.verdict for f in late] == [Verdict.FAIL]
    assert _rule([owner, *late]) is Verdict.FAIL


def test_a_start_with_no_count_leaves_its_data_undecided():
    """measure-ttt-two-digits' aM! made again gives no readable count, so no D command
    followed: every data rule undecided there, observed 0 (an owner's decision outweighs
    it), none N/A or PASS on values nobody read."""
    session = _session("measure-ttt-two-digits")
    session.fresh_measurement("M")
    m = session.remeasured[0]
    assert m.count is None and not m.data
    found = judge_other_data(session.remeasured, DATA_IDS, session.version)
    undecided = [f for f in found if f.verdict is Verdict.INCONCLUSIVE]
    assert {f.requirement for f in undecided} == set(DATA_IDS)
    assert all(f.observed == 0 for f in undecided)
    assert {f.verdict for f in found} <= {Verdict.INCONCLUSIVE, Verdict.NA}
