"""Issue 22, matrix16: on a link that ``reads_line_at_once`` (the sim bus's) the tool recorder
reads the rest of a one-line reply in one receive, the idle counted from the reply's last
character so far, instead of one receive per idle window. A character is taken exactly when
it starts within the idle of the one before and before the reply's deadline however the reads
are cut, so every exchange comes out as the window-by-window reads gave it: the same events,
stamps, reasons and clock, with every emulator fault (late, slow, gapped, paused, babbling,
cut-off replies) and on the clean emulator."""

from __future__ import annotations

import pytest

from conformance.emulator import FAULTS, default_profile
from conformance.emulator.replies import Reply, ReplyKind
from conformance.emulator.sim import sim_sensor
from conformance.links.base import LineEnd
from conformance.protocol import commands as cmds
from conformance.recorder.job_time import JobBudget, JobLink
from conformance.sim.bus import SimBus, SimLink
from conformance.tool_recorder import ToolRecorder
from conformance.tool_recorder.policy import Policy
from tests.support.transmitter_device import TransmitterDevice

#: the one-line replies a run reads most, a multi-line and a binary one beside them
SCRIPT = ("0!", "0I!", "0IM_001!", "0IMC_002!", "0R0!", "0RC0!", "0XHELP!", "?!", "0V!")


def _script(name: str | None, at_once: bool, monkeypatch: pytest.MonkeyPatch) -> tuple:
    """What the script leaves (transcript, each attempt's reason and reply, the clock) and
    how many receives were given a line's characters to go on from."""
    monkeypatch.setattr(SimLink, "reads_line_at_once", at_once)
    version = FAULTS[name].version if name else FAULTS["wrong-crc"].version
    _, link, _ = sim_sensor(default_profile(version), (name,) if name else ())
    reads = []
    receive = link.receive

    def counted(deadline, until=None, idle=None):  # noqa: ANN001, ANN202 - as SimLink.receive
        if type(until) is LineEnd and until.before:
            reads.append(len(until.before))
        return receive(deadline, until, idle)

    link.receive = counted  # type: ignore[method-assign]
    master = ToolRecorder(link)
    done = []
    for text in SCRIPT:
        ex = master.transact(text)
        done.append([(a.reason, [(e.start, e.wire) for e in a.reply_events]) for a in ex.attempts])
    for command in (cmds.measure("0"), cmds.measure("0", crc=True), cmds.high_volume_binary("0")):
        m = master.measure(command)
        done.append([[a.reason for a in x.attempts] for x in (m.start, *m.data)])
    monkeypatch.undo()
    return list(link.transcript.events), done, link.now(), reads


@pytest.mark.parametrize("name", [None, *sorted(FAULTS)])
def test_a_line_read_at_once_is_what_window_by_window_gives(name, monkeypatch) -> None:
    events, done, now, reads = _script(name, True, monkeypatch)
    events_w, done_w, now_w, reads_w = _script(name, False, monkeypatch)
    assert (events, done, now) == (events_w, done_w, now_w)
    if name is None:  # the read went otherwise, so the comparison compared something
        assert 0 < len(reads) < len(reads_w)


def test_a_link_that_does_not_say_so_is_read_window_by_window() -> None:
    """The recorder jobs' timed link forwards attributes to the sim link it wraps, and its
    receive cuts every read at the job's end: it does not pass the sim link's word on (the
    class is asked, not the object), and the engine reads through it as before."""
    _, link, _ = sim_sensor()
    timed = JobLink(link, JobBudget(60.0, "a test's"))
    assert type(link).reads_line_at_once and timed.reads_line_at_once
    assert not getattr(type(timed), "reads_line_at_once", False)
    assert ToolRecorder(timed).transact("0I!").ok  # type: ignore[arg-type]


class _Pausing(TransmitterDevice):
    """A device that answers every command ending in '!' with ``text`` 10 ms after it, with
    ``pauses`` ((index, s) each: marking added before that character)."""

    def __init__(self, text: str, pauses: tuple[tuple[int, float], ...]) -> None:
        super().__init__()
        self.text, self.pauses = text, pauses

    def on_char(self, wire: int, start: float, end: float) -> None:
        if wire & 0x7F == ord("!"):
            reply = Reply(ReplyKind.DATA, self.text)
            self.tx.schedule(reply, end + 0.010, gap=0.0, pauses=self.pauses)


IDLE = Policy().reply_idle  # the marking after which a one-line reply's read stops
PAUSES = [  # around the read's idle, inside and across the windows of ~6 characters
    ((1, IDLE - 1e-4),), ((1, IDLE),), ((1, IDLE + 1e-9),), ((2, IDLE - 1e-9),),
    ((6, IDLE * 0.98),), ((7, IDLE * 0.99),), ((7, IDLE * 1.01),), ((12, IDLE),),
    ((3, IDLE * 0.6), (8, IDLE * 0.9)), ((5, IDLE * 0.7), (6, IDLE * 0.7), (11, IDLE * 1.2)),
    ((4, 0.3),), ((14, IDLE * 0.999),),
]  # fmt: skip


@pytest.mark.parametrize("pauses", PAUSES, ids=str)
@pytest.mark.parametrize("text", ["0+1.5+2.25+7.125\r\n", "0+1.5+2.25+7.125+8+9+10+11+12"])
def test_pauses_around_the_idle_are_read_as_window_by_window(text, pauses, monkeypatch) -> None:
    """Replies paused just inside, at and just past the idle, at the first character, at
    the windows' edges and across them, complete and never ending: the same both ways."""

    def read(at_once: bool) -> tuple:
        monkeypatch.setattr(SimLink, "reads_line_at_once", at_once)
        link = SimLink(SimBus([_Pausing(text, pauses)]))
        master = ToolRecorder(link)
        done = [master.transact(t) for t in ("0D0!", "0D1!", "0!")]
        got = [[(a.reason, len(a.reply_events)) for a in ex.attempts] for ex in done]
        return list(link.transcript.events), got, link.now()

    at_once = read(True)
    assert at_once == read(False)
