"""Rules judged over every reply of the run: character framing and printability, CR LF
endings, the responding address, response start window, character gaps; and the
service-request and data rules over every measurement the run made again.

These cases are ``whole_run``: the plugin runs them after every other case, whatever order
or selection the run was given, so they judge everything the run sent. Each first asks for the
standard stimuli (cached: a full run has made them all already and sends nothing more), so a
partial run that selects them still judges every kind of reply a full run would.
"""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import other_waits, wire
from conformance.links import host_stall
from conformance.links.base import NO_BIT_TIMING
from conformance.tool_recorder.records import Measurement
from conformance.verdicts import inconclusive
from conformance.view.runs import Segments, transcript_segments

requirements = pytest.mark.requirements
pytestmark = pytest.mark.whole_run


def _segments(sensor):
    """The run's transcript cut into segments, once the standard stimuli are on it. On a
    bus shared with other sensors only the commands to the DUT and what followed them: the
    others' replies (the bus cases') are theirs, not evidence about this sensor."""
    sensor.standard_stimuli()
    segs = transcript_segments(sensor.link.transcript)  # cut once, shared with the report
    if not sensor.shared:
        return segs
    return Segments(s for s in segs if s.text[:1] == sensor.address)


def _answered_here(sensor):
    """The control that shows the sensor at its address: its ``a!``, else the last standard
    stimulus at that address it answered (all cached). A sensor that answers no ``a!`` but
    its measurements, as an ENG20009 Due sketch (docs/kit.md, thirty-fourth round), is there
    all the same: with ``a!`` alone as the control its replies' framing went unjudged, and
    R-4.3-01 PASSed on the exploration's checks while it sent 'FINAL DATA @2<CR><LF>'."""
    ack = sensor.exchange("")
    if ack.answered:
        return ack
    for made in reversed(sensor.standard_stimuli()):
        ex = made.start if isinstance(made, Measurement) else made  # its start reply
        if ex.answered and ex.text[:1] == sensor.address:
            return ex
    return ack


def _stalls(sensor):
    """The tool's own host stalls the link noted (:func:`~conformance.links.host_stall.
    stalls`); none on a virtual clock (its transcript is not read for them)."""
    if sensor.link.info.virtual_time:
        return []
    return host_stall.stalls(sensor.link.transcript.events)


def _confirmed(sensor, case, wanted):
    """The run's segments, after re-probing the commands ``wanted(segments, stamps,
    stalls)`` names: a rare deviation on a real-time link, or one read across a stall of
    the tool's host, is observed again with the same command before the judge decides it
    or sets it aside (issue 18, truth29); the repeats are the case's evidence."""
    segs = _segments(sensor)
    again = wanted(segs, sensor.stamp_uncertainty, _stalls(sensor))
    repeats = sensor.reprobe(again) if again else []
    if not repeats:
        return segs
    case.evidence(f"re-probed {', '.join(again)} to confirm a rare deviation", repeats)
    return _segments(sensor)


@requirements("R-7.0-09", "R-7.0-10")
@pytest.mark.preconditions("none")
def test_response_start_window(sensor, case):
    """Every reply's first start bit comes 7.93 to 15.40 ms after the command's last stop bit."""
    case.expect("8.33 ms (-0.40) <= delay <= 15.0 ms (+0.40), for every reply of the run")
    segs = _confirmed(sensor, case, wire.starts_to_confirm)
    stalls = _stalls(sensor)
    if wire.starts_after_a_retry(segs, sensor.stamp_uncertainty, stalls):
        # every reply began after a retry: one a! sent once, with no retry, times it alone
        probe = sensor.late_start_probe()
        case.evidence("every reply began after a retry: a! sent once, no retry, 1 s", [probe])
        segs, stalls = _segments(sensor), _stalls(sensor)
    case.extend(wire.judge_response_start(segs, sensor.stamp_uncertainty, stalls))


@requirements("R-7.0-12", "R-7.0-01")
@pytest.mark.preconditions("none")
def test_character_gaps(sensor, case):
    """No more than 1.66 ms of marking between the characters of a reply (no tolerance)."""
    case.expect("every inter-character gap of every reply <= 1.66 ms")
    segs = _confirmed(sensor, case, wire.gaps_to_confirm)
    case.extend(wire.judge_gaps(segs, sensor.stamp_uncertainty, _stalls(sensor)))


@requirements("R-4.1-01", "R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01")
@pytest.mark.preconditions(
    address=("R-4.3-01",), none=("R-4.1-01", "R-4.1-02", "R-4.2-02", "R-4.2-03")
)
def test_reply_framing(sensor, case):
    """Every reply is 1200 baud 7E1 (except aDBn! packets), printable, at least 3 characters
    ending in CR LF, and starts with the address of the sensor that answers."""
    case.expect(
        "even parity and printable characters in every ASCII reply; CR LF at the end; "
        "the address first"
    )
    segs = _segments(sensor)
    if sensor.link.info.frame_lengths:  # a firmware kit: each frame its own ten bits
        case.add(wire.judge_reply_frame_lengths(segs, sensor.stamp_uncertainty))
    elif sensor.link.info.bit_timing:
        case.add(wire.judge_reply_bit_rate(segs, sensor.stamp_uncertainty))
    else:
        case.add(inconclusive("R-4.1-01", NO_BIT_TIMING))
    stalled = host_stall.stalls(sensor.link.transcript.events)  # the link's notes
    case.extend(
        wire.judge_framing(segs, sensor.stamp_uncertainty, own=sensor.address, stalls=stalled)
    )
    # replies are judged against the address the sensor answered at (cached: no new traffic)
    case.requires(
        "address",
        precondition.answers_at(
            _answered_here(sensor), sensor.address, "no standard stimulus at it was answered"
        ),
    )


@pytest.mark.needs("unsolicited")
@requirements(*other_waits.WAIT_IDS)
@pytest.mark.preconditions("none")
def test_service_requests_of_every_measurement(sensor, case):
    """The service-request rules over every measurement a case made again (outside the
    cached ones their own cases judge): a late, malformed or missing request there, or talk
    before it, is the sensor's as much; none after a concurrent one (truth31). One case for
    both kinds: the rules of the kind no case made again are N/A, which changes no verdict
    of their own cases (a case of the concurrent rules alone was N/A in every clean run)."""
    case.expect(
        "exactly 'a<CR><LF>', complete within ttt s of the reply, nothing before it, after "
        "every M-type measurement with ttt > 0 the run made; none after a concurrent one"
    )
    ms = _remeasured(sensor) + sensor.disturbed
    case.evidence("measurements made again by other cases", ms)
    case.extend(other_waits.judge_other_waits(ms, case.requirements, sensor.version))


@requirements(*other_waits.DATA_IDS)
@pytest.mark.preconditions("none")
def test_data_of_every_measurement(sensor, case):
    """The data rules over every measurement a case made again (outside the cached ones
    their own cases judge): a D reply malformed, a count short or a CRC wrong there is the
    sensor's as much (truth35: one value fewer than announced only when measured again
    PASSed R-4.4.8-03). A rule no such measurement bears on (no CRC asked for again) is N/A,
    which changes no verdict of its own cases."""
    case.expect(
        "'a<values>[<CRC>]<CR><LF>' to every D command of every measurement the run made, "
        "the values adding up to the count announced, D0 not empty, the CRC where asked for"
    )
    ms = _remeasured(sensor)
    case.evidence("measurements made again by other cases", ms)
    case.extend(other_waits.judge_other_data(ms, case.requirements, sensor.version))


def _remeasured(sensor):
    """The measurements the run's cases made again; in a partial run (-k, --req) that left
    out every case measuring again, one aM! of the whole-run cases' own, so they judge what
    a full run gives them (CI: alone the wait case was N/A, PASS in full)."""
    if not sensor.remeasured and sensor.defined(("M",)):
        sensor.fresh_measurement("M")
    return sensor.remeasured
