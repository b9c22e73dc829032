"""A command the break rules would send without a break goes after one where the link noted
a stall of the tool's own host after the line's last activity (truth30): that activity's
stamp may be the late burst's, so "within 87 ms" of it is not known. The case that asked for
it: a service request the stall held back reads as just ended, ``aD0!`` went at once
without a break, the sensor had been marking for over 100 ms already and slept, and its
silence was taken for its own. Outside any stall the engine sends D0 as before."""

from __future__ import annotations

from conformance.links import host_stall
from conformance.protocol import commands as cmds
from conformance.transcript import TOOL, Event, EventKind
from tests.tool_recorder.test_scripted_sensor import ScriptedSensor, rig, then_sr

SCRIPT = {"0M!": [then_sr("00052\r\n", after=2.0)], "0D0!": ["0+1.5-2.25\r\n"]}


def _measured(noted: bool):
    """0M! whose service request came 2 s after its reply; ``noted``: the link's NOTE of a
    stall right after the wait that read it (where the reader writes it, after the burst)."""
    master, _ = rig(ScriptedSensor(SCRIPT))
    usual_wait = master.hooks.wait_for_data

    def wait(engine, m, service_request, usual):
        usual_wait(engine, m, service_request, usual)
        if noted:
            master.link.transcript.note(master.link.now(), host_stall.note_text(0.15))

    master.hooks.wait_for_data = wait  # type: ignore[method-assign]
    return master.measure(cmds.measure("0"))


def test_d0_after_a_request_a_stall_may_have_misdated_goes_after_a_break():
    m = _measured(True)
    assert m.service_request_end is not None  # the request was read
    assert m.data[0].attempts[0].break_event is not None
    assert m.values == ["+1.5", "-2.25"]


def test_d0_after_a_request_outside_any_stall_goes_at_once():
    m = _measured(False)
    assert m.data[0].attempts[0].break_event is None  # R-4.4.5-05, R-7.1-01, as ever


def test_only_the_notes_after_the_last_activity_count():
    events = _measured(True).data[0].attempts[0].reply_events
    note = host_stall.note_text(0.15)
    at = events[-1].end
    noted = Event(EventKind.NOTE, TOOL, at, at, text=note)
    other = Event(EventKind.NOTE, TOOL, at, at, text="maybe collided")
    assert host_stall.noted_since_activity([*events, noted, other])
    assert not host_stall.noted_since_activity([noted, *events, other])
    assert not host_stall.noted_since_activity([])


def _sent_after_note(noted: bool) -> float:
    """How long after the last reply the tool's next command began (its break, if any),
    ``noted``: the link's NOTE of a stall right after that reply (the reader's first turn
    after the pause, the reply's rest maybe still on its way)."""
    master, _ = rig(ScriptedSensor({"0!": ["0\r\n"], "0I!": ["013CONFORM EMULATOR1.0\r\n"]}))
    first = master.transact("0!")
    end = first.judged.reply_events[-1].end
    if noted:
        master.link.transcript.note(master.link.now(), host_stall.note_text(0.15))
    nxt = master.transact("0I!").attempts[0]
    return (nxt.break_event or nxt.command_events[0]).start - end


def test_the_next_transmission_waits_for_what_a_stall_held_back():
    """A retry sent 0.4 ms after the NOTE met the rest of the reply the stall had cut
    (R-4.3-01 FAILed a clean emulator, base-s67): it now waits AFTER past the NOTE."""
    assert _sent_after_note(True) >= host_stall.AFTER
    assert _sent_after_note(False) < host_stall.AFTER  # outside any stall, as soon as ever
