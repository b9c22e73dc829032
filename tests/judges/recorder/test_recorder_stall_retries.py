"""The recorder judges truth32 and truth33 left stall-blind (truth34), over hand-built
transcripts with a NOTE of the tool's own host stalling: R-7.2-01, -04 and -05 (a reply a
stall made read invalid or missing, a paused in-process recorder past its window), R-7.2-03
where the stall's disorder outlived its noted span (a reply it held back met the next try, a
sensor asleep by its own clock), R-4.4.14-01 (transparent mode); and the served line's guard,
which now holds a case only where a note lies near what it judged. Each held deviation has
its control: the same with the stall 5 s away still FAILs (or WARNs), clean still PASSes.

A stall note at t covers ``t - ms - 50 ms .. t + 30 ms`` (``host_stall.Stall``)."""

from __future__ import annotations

from types import SimpleNamespace

from conformance.judges.recorder.capabilities import judge_transparent
from conformance.judges.recorder.retries import judge_retries
from conformance.links.host_stall import note_text, stalls
from conformance.transcript import TOOL, Event, EventKind
from conformance.verdicts import Finding, Verdict

from .test_recorder_host_stall import STALLED, Stalling, _far, _held
from .test_recorder_judges import by_id

RETRY_RULES = ("R-7.2-01", "R-7.2-04", "R-7.2-05")


def _retries(w: Stalling) -> dict[str, Finding]:
    return by_id(judge_retries(w.view(), 0.0))


# -- a reply a stall held back, then no retry: R-7.2-01, -04, -05 -----------------------------


def _unanswered(stalled: bool) -> Stalling:
    """truth32's paused runs: the played sensor's reply to 0D0! was held back by the stall
    (or the in-process recorder paused as it came), the recorder went on: "no reply ...,
    then no retry", "not sent again", "gave up after 1 sequence"."""
    w = Stalling().brk().rec("0D0!").idle(40)
    if stalled:
        w.stall(150)
    return w.idle(600) if stalled else _far(w.idle(600))


def test_no_retry_after_a_reply_a_stall_held_back_is_held_r_7_2_01_04_05():
    found = _retries(_unanswered(True))
    for rid in RETRY_RULES:
        _held(found[rid])
    far = _retries(_unanswered(False))
    assert far["R-7.2-01"].verdict is far["R-7.2-05"].verdict is Verdict.FAIL
    assert far["R-7.2-04"].verdict is Verdict.WARN


def _gap_then_new_sequence(stalled: bool) -> Stalling:
    """new1's 0XHELP!: the stall put 100 ms of marking inside the reply (the line's thread
    held its frames), the in-process recorder, paused too, read it whole and went on; 1.2 s
    later a new sequence (a break) of the same command."""
    w = Stalling().brk().rec("0D0!").sensor("0+1.5").idle(110)
    if stalled:
        w.stall(120)
    w.sensor("+2.5\r\n", delay_ms=0.0).idle(1200).brk().rec("0D0!").sensor("0+1.5+2.5\r\n")
    return w if stalled else _far(w)


def test_a_new_sequence_after_a_reply_a_stall_broke_up_is_held_r_7_2_01_05():
    found = _retries(_gap_then_new_sequence(True))
    _held(found["R-7.2-01"])
    _held(found["R-7.2-05"])
    far = _retries(_gap_then_new_sequence(False))
    assert far["R-7.2-01"].verdict is far["R-7.2-05"].verdict is Verdict.FAIL
    assert STALLED not in far["R-7.2-05"].detail


def test_one_unretried_reply_outside_every_stall_still_fails_beside_a_held_one():
    w = _unanswered(True).brk().rec("0!").sensor("0\r\n").idle(20)  # answered, after it
    w.brk().rec("0D1!").idle(600)  # 0D1! unanswered, no stall near
    found = _retries(w)
    for rid in RETRY_RULES:
        assert found[rid].verdict in (Verdict.FAIL, Verdict.WARN), (rid, found[rid].detail)
        assert "0D1!" in found[rid].detail


def test_a_clean_retry_under_a_stall_still_passes():
    w = Stalling().brk().rec("0D0!").idle(40).stall(30).rec("0D0!").sensor("0+1\r\n")
    found = _retries(w)
    assert found["R-7.2-01"].verdict is found["R-7.2-05"].verdict is Verdict.PASS


# -- a stall's disorder outliving its span: R-7.2-03, -05 -------------------------------------


def _asleep_after(stalled: bool) -> Stalling:
    """new1 at 127.5 s (clean, in-process): the reply to 0DB2! ended in a stall's late burst;
    0DB3! 23 ms after it (26 ms past the stall's reach) drew nothing, nor its retry: the
    played sensor, counting its marking from when it planned that reply, was asleep. Then a
    break and 0DB3! again, answered. Base: "0DB3! sequence 1: 1 retries, then no more"."""
    w = Stalling().brk().rec("0D1!").sensor("0+1.5+2.5\r\n")
    if stalled:
        w.stall(150, at=w.t - 35e-3)  # noted as the burst's last characters came in
    w.idle(23).rec("0D2!").idle(45).rec("0D2!").idle(35).brk().rec("0D2!").sensor("0+2\r\n")
    return w if stalled else _far(w)


def test_a_sequence_a_stall_left_a_sleeping_sensor_is_held_r_7_2_03_05():
    found = _retries(_asleep_after(True))
    _held(found["R-7.2-03"])
    _held(found["R-7.2-05"])
    far = _retries(_asleep_after(False))
    assert far["R-7.2-03"].verdict is far["R-7.2-05"].verdict is Verdict.FAIL


def _held_back_met(stalled: bool) -> Stalling:
    """truth32's paused runs: a stall held back the rest of a long reply to 0D0!, and the
    recorder's 0D1!, 260 ms after the stall's reach, met its tail: no reply, and it went on
    without a retry. Base: "0D1! sequence 1: 0 retries, then no more"."""
    w = Stalling().brk().rec("0D0!").sensor("0+1000.000+1001.062")
    if stalled:
        w.stall(100)
    w.sensor("+1002.125+1003.188+1004.250+1005.312\r\n", delay_ms=0.0)
    w.t -= 30e-3  # 0D1! begins while the tail is still coming
    w.rec("0D1!").idle(600).brk().rec("0D2!").sensor("0+2\r\n")
    return w if stalled else _far(w)


def test_a_try_a_reply_held_back_by_a_stall_met_is_held_r_7_2_03_05():
    found = _retries(_held_back_met(True))
    _held(found["R-7.2-03"])
    _held(found["R-7.2-05"])
    far = _retries(_held_back_met(False))
    assert far["R-7.2-03"].verdict is far["R-7.2-05"].verdict is Verdict.FAIL


def _long_reply_broken_up(stalled: bool) -> Stalling:
    """newC at 103.4 s (clean, in-process): the stall put 107 ms of marking inside a long
    reply, 250 ms after the command ended (past the standby after it, where truth32's
    window for R-7.2-03 ended): "0D0! sequence 1: 0 retries, then no more"."""
    w = Stalling().brk().rec("0D0!").sensor("0+1000.000+1001.062+1002.125").idle(100)
    if stalled:
        w.stall(107)
    w.sensor("+1003.188\r\n", delay_ms=0.0).idle(500).brk().rec("0D0!").sensor("0+1\r\n")
    return w if stalled else _far(w)


def test_a_long_reply_a_stall_broke_up_late_is_held_r_7_2_03_05():
    found = _retries(_long_reply_broken_up(True))
    _held(found["R-7.2-03"])
    _held(found["R-7.2-05"])
    far = _retries(_long_reply_broken_up(False))
    assert far["R-7.2-03"].verdict is far["R-7.2-05"].verdict is Verdict.FAIL


def test_a_sequence_given_up_well_after_a_stall_still_fails_r_7_2_03():
    """The marking before a try, the sensor's standby and a reply still coming are all a
    stall's disorder reaches: a sequence after an answered exchange 300 ms after the stall,
    given up after one retry, still FAILs."""
    w = Stalling().brk().rec("0D1!").sensor("0+1\r\n").stall(150).idle(300)
    w.brk().rec("0D2!").sensor("0+2\r\n").idle(20)
    w.brk().rec("0D3!").idle(45).rec("0D3!").idle(400)
    found = _retries(w)
    assert found["R-7.2-03"].verdict is Verdict.FAIL and STALLED not in found["R-7.2-03"].detail


# -- transparent mode: R-4.4.14-01 -----------------------------------------------------------


def _relayed(stalled: bool, brk: bool = True) -> tuple[Stalling, dict[str, str]]:
    """A stall over the command's break (read with the command as one late burst) or over
    its reply (held back, the recorder relayed what it had)."""
    w = Stalling()
    if brk:
        w.brk()
    else:
        w.idle(200)
    if stalled:
        w.stall(120)
    w.rec("0I!").sensor("014CONFORM EMU001 1.0\r\n")
    return (w if stalled else _far(w)), {"0I!": "014CONFORM"}


def test_transparent_mode_across_a_stall_is_held_r_4_4_14_01():
    for brk in (True, False):  # the relay cut short, the command without its break
        w, relayed = _relayed(True, brk)
        found = by_id(judge_transparent(w.view(), ["0I!"], 0.0, relayed))
        _held(found["R-4.4.14-01"])
        w, relayed = _relayed(False, brk)
        far = by_id(judge_transparent(w.view(), ["0I!"], 0.0, relayed))
        assert far["R-4.4.14-01"].verdict is Verdict.FAIL, far["R-4.4.14-01"].detail
    w, _ = _relayed(True)
    whole = {"0I!": "014CONFORM EMU001 1.0\r\n"}
    assert by_id(judge_transparent(w.view(), ["0I!"], 0.0, whole))["R-4.4.14-01"].verdict is (
        Verdict.PASS
    )


# -- the served line's guard, per case ---------------------------------------------------------


def _note(t: float, ms: float = 120.0) -> Event:
    return Event(EventKind.NOTE, TOOL, t, t, text=note_text(ms / 1e3))


def _slice(start: float, end: float) -> list[Event]:
    return [
        Event(EventKind.BREAK, TOOL, start, start + 0.013),
        Event(EventKind.NOTE, TOOL, end, end),
    ]


def _guard(
    noted: list[Event], cases: list[list[tuple[str, list[Event]]]], in_process: bool = False
) -> list[list[Finding]]:
    """The guard over cases whose evidence is ``cases`` (each a FAIL of a stall-blind rule
    and one of a rule whose judge reads the notes), the line's notes ``noted``."""
    from conformance.run import ConformanceRun

    found = [
        [
            Finding("R-4.4-02", Verdict.FAIL, "logged 3 of 4 values", evidence=["l"], observed=1),
            Finding(
                "R-7.2-05", Verdict.FAIL, "no reply, then no retry", evidence=["r"], observed=1
            ),
        ]
        for _ in cases
    ]
    session = SimpleNamespace(
        worst_lateness=lambda: 0.150,
        unexplained_lateness=lambda: 0.0,
        noted_stalls=lambda: stalls(noted),
        recorder_in_process=lambda: in_process,
    )
    run = SimpleNamespace(
        session=session,
        cases=[SimpleNamespace(findings=f, evidence=e) for f, e in zip(found, cases, strict=True)],
    )
    ConformanceRun._guard_served_line(run)  # type: ignore[arg-type]
    return found


def test_the_guard_holds_a_case_only_where_a_note_lies_near_its_scenarios():
    near = [("scenario a: x", _slice(10.0, 12.0))]
    after = [("scenario b: y", _slice(11.4, 14.0))]  # within REACTION after the stall's span
    far = [("scenario c: z", _slice(20.0, 22.0))]
    whole = [("transcript", _slice(0.0, 30.0))]  # no scenario slice: judged the run whole
    held_near, held_after, kept, held_whole = _guard([_note(11.0)], [near, after, far, whole])
    for findings in (held_near, held_after, held_whole):
        assert findings[0].verdict is Verdict.INCONCLUSIVE
        assert "fell 150.0 ms behind" in findings[0].detail
    assert kept[0].verdict is Verdict.FAIL  # a faulty recorder's FAIL far from any late frame
    for findings in (held_near, held_after, kept, held_whole):
        assert findings[1].verdict is Verdict.FAIL  # its judge read the notes


def test_the_guard_holds_an_in_process_recorders_deviations_near_a_note():
    """An in-process recorder's threads are held up with the tool's around a stall, where
    nothing notes it (base-s69's paused clean run: a 1.15 ms break 184 ms after a note,
    R-7.0-02): in a case near a note, a rule whose judge reads the notes stands only where
    what it names lies over a second from every note (truth34's burners run: the fault's
    R-7.0-17 at 43.5 s, the run's one 6 ms note at 4.9 s, in one whole-run case); the
    rest of the case is held; a case far from every note stands whole."""
    near = [("scenario a: x", _slice(10.0, 12.0)), ("scenario b: y", _slice(40.0, 44.0))]
    far = [("scenario c: z", _slice(20.0, 22.0))]
    held, kept = _guard([_note(11.0)], [near, far], in_process=True)
    assert held[0].verdict is Verdict.INCONCLUSIVE  # a stall-blind rule near a note
    assert held[1].verdict is Verdict.INCONCLUSIVE  # names no place: held
    assert {f.verdict for f in kept} == {Verdict.FAIL}
    from conformance.run import ConformanceRun

    def one(detail: str) -> Finding:
        f = Finding("R-7.0-17", Verdict.FAIL, detail, evidence=["e"], observed=1)
        session = SimpleNamespace(
            worst_lateness=lambda: 0.150,
            unexplained_lateness=lambda: 0.0,
            noted_stalls=lambda: stalls([_note(11.0)]),
            recorder_in_process=lambda: True,
        )
        case = SimpleNamespace(findings=[f], evidence=near)
        ConformanceRun._guard_served_line(SimpleNamespace(session=session, cases=[case]))
        return f

    assert one("2005.70 ms [before 0D0! at t=43.521 s]").verdict is Verdict.FAIL
    assert one("1.15 ms [break at t=11.300 s]").verdict is Verdict.INCONCLUSIVE


def test_no_retry_then_a_poll_timeout_with_a_stall_in_it_still_fails_r_7_2_01_05():
    """no-retries under the pauses (truth34's newR): the recorder waits out a 1 s poll
    timeout, then a new sequence; a stall 500 ms into that wait came after the retry it owed
    (the standby after the unanswered try), so "not retried" stands. (R-7.2-04's "gave up
    after 2 sequences" rests on the group's whole span, the stall inside it: held.)"""
    w = Stalling().brk().rec("0D0!").idle(500).stall(120).idle(500).brk().rec("0D0!")
    found = _retries(w.idle(600))
    _held(found["R-7.2-04"])
    for rid in ("R-7.2-01", "R-7.2-05"):
        assert found[rid].verdict is Verdict.FAIL, (rid, found[rid].detail)
        assert STALLED not in found[rid].detail
