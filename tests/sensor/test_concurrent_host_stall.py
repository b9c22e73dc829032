"""R-4.4.7-05 counts a concurrent measurement's values over its D reads together: one the
tool's own host stalled over may have been cut, so the count is no evidence of an abort
(truth30: a clean emulator behind RFC 2217, the tool paused 80-200 ms every 0.3-0.9 s,
FAILed "C delivered 18 values after a break and zI!, 20 undisturbed (aborted?)"). Here the
sim's sensor that a foreign command does abort, its disturbed D reads with the link's NOTE
of a stall (the sim never stalls): INCONCLUSIVE naming it; without the NOTE a FAIL."""

from __future__ import annotations

from conformance.links import host_stall
from conformance.protocol.commands import Kind
from conformance.verdicts import Verdict
from testcases.sensor.test_4_4_7_concurrent import (
    test_concurrent_survives_break_and_other_traffic as survives,
)
from tests.support.case_verdicts import case_verdict, sim_session

FAULT = "foreign-command-aborts-concurrent"


def _session(noted: bool):
    """The sim's session whose D reads after the foreign aI! get the NOTE of a stall just
    after their read, as the link writes it when its reader resumes."""
    session = sim_session(FAULT)
    watch, poked, notes = session.master.watch, [], []
    other = session.foreign_address()
    attempt = watch.attempt

    def noted_attempt(master, wire, address, command, proceed):
        made = attempt(master, wire, address, command, proceed)
        foreign = command is not None and command.kind is Kind.IDENTIFY
        poked.append(bool(poked and poked[-1]) or (foreign and address == other))
        if noted and poked[-1] and command is not None and command.kind is Kind.DATA:
            notes.append(command.text())
            session.link.transcript.note(session.link.now(), host_stall.note_text(0.15))
        return made

    watch.attempt = noted_attempt  # type: ignore[method-assign]
    return session, notes


def test_values_counted_over_stalled_reads_are_no_abort():
    session, notes = _session(True)
    assert case_verdict(session, survives, "R-4.4.7-05") is Verdict.INCONCLUSIVE
    assert notes  # the disturbed D reads were the stalled ones


def test_the_same_count_outside_any_stall_fails():
    session, _ = _session(False)
    assert case_verdict(session, survives, "R-4.4.7-05") is Verdict.FAIL
