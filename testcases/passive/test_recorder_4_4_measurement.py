"""Recorder rules over every recorded measurement and retry (sections 4.3-4.4, 7.1-7.2): the
waits for service requests and ttt, data collection, concurrent waits, high-volume data,
retries and the addresses polled."""

from __future__ import annotations

import pytest

from conformance.offline.recorder_windows import recorder_findings
from conformance.verdicts import Verdict

from ._helpers import judged, judged_only, unseen_rule

requirements = pytest.mark.requirements


@requirements("R-4.4.5-04", "R-4.4.5-05", "R-4.4.5-06", "R-4.4.5-07")
@pytest.mark.preconditions("heard")
def test_waiting_for_the_service_request(heard_recorder, case):
    """After 'atttn' the recorder leaves the line alone until the service request or ttt,
    then asks for aD0! at once, and talks to no other sensor until the data are in."""
    case.expect("aD0! not before the service request / ttt; within 0.5 s after it")
    judged(case, recorder_findings(heard_recorder.link).measure_waits)


@requirements("R-4.4.7-06")
@pytest.mark.preconditions("heard")
def test_concurrent_waits(heard_recorder, case):
    """After a concurrent reply, no data command to that sensor before ttt."""
    case.expect("first data command to each sensor at least ttt after its 'atttnn' reply")
    judged(case, recorder_findings(heard_recorder.link).concurrent_waits)


@requirements("R-4.4.8-05")
@pytest.mark.preconditions("heard")
def test_data_continuation(heard_recorder, case):
    """D0, D1, D2... until every announced value is in; the measurement again after an empty
    D reply."""
    case.expect("D indices in order until the count is reached; after 'a<CR><LF>', aM! again")
    judged(case, recorder_findings(heard_recorder.link).data_collection)


@requirements("R-5.1-04", "R-5.2-08")
@pytest.mark.preconditions("heard")
def test_high_volume(heard_recorder, case):
    """Recorded aHA! data are read past D9 without leading zeros; aHB! packets until every
    value (or the empty packet) is in. (Whether a v1.4 recorder issues both, R-5.4-01, is a
    question of what it can do, not of what one recording shows: not judged here.)"""
    case.expect("0D10!..0D14! (never 0D010!); DB0..DBn read, then stop")
    found = recorder_findings(heard_recorder.link).high_volume  # is_v14 reads only R-5.4-01
    judged_only(case, found, *case.requirements)


@requirements("R-7.2-01", "R-7.2-02", "R-7.2-03", "R-7.2-04", "R-7.2-05", "R-7.2-06")
@pytest.mark.preconditions("heard")
def test_retries(heard_recorder, case):
    """Recorded retries after no reply or an invalid one come inside the section 7.2 windows."""
    case.expect("retry 16.67-87 ms after an unanswered command; up to three sequences")
    judged(case, recorder_findings(heard_recorder.link).retries)


@requirements("R-4.3-03", "R-4.3-04")
@pytest.mark.preconditions("heard")
def test_addresses(heard_recorder, case):
    """Sensors at 0-9 polled (a PASS only when the recording shows all ten answering);
    anything addressed is an address."""
    case.expect("a valid exchange with each of the sensors at 0..9; only valid addresses")
    for f in recorder_findings(heard_recorder.link).addresses:
        if f.requirement == "R-4.3-03" and f.verdict is not Verdict.PASS:
            unseen_rule(case, "R-4.3-03", f"polls that answered at {f.detail.split(': ', 1)[-1]}")
        elif f.requirement == "R-4.3-04" and f.verdict is Verdict.NA:
            unseen_rule(case, "R-4.3-04", "no letter address used")
        else:
            judged(case, [f])
