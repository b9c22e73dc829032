"""The cheap ways a run is judged and written (issue 22) give what the plain ways gave:
a :class:`~conformance.judges.timing.Measured` stands for its finding in every aggregate,
the gap observations are shared, not recomputed, transcript.jsonl keeps its bytes, and the
collector's pace is restored after a run."""

from __future__ import annotations

import gc
import json
import math
import random
from dataclasses import asdict
from math import copysign

import pytest

from conformance import gc_pace
from conformance.judges import wire
from conformance.judges.timing import (
    Measured,
    StampUncertainty,
    Window,
    combine,
    combine_local,
    judge_window,
    to_confirm,
)
from conformance.transcript import DUT, TOOL, Event, EventKind, Transcript, to_wire_7e1
from conformance.view.runs import Segment, Segments

WINDOWS = [
    Window("R-7.0-12", "gap", high=1.66e-3, tolerance=0.0),
    Window("R-7.0-09", "start", low=8.33e-3),
    Window("R-7.0-10", "start", low=7.93e-3, high=15.0e-3, decision="A1"),
    Window("R-4.4.5-09", "wait", high=1.0, should=True),  # a WARN, never a FAIL
    Window("R-4.1-01", "spacing", low=8.1e-3, high=8.5e-3, tolerance=0.0),
]


def _interval(rng: random.Random, window: Window) -> tuple[float, float]:
    edge = window.high if window.high is not None else window.low
    measured = edge * rng.choice([0.0, 0.5, 0.99, 1.0, 1.001, 1.2, 3.0, -0.0])
    uncertainty = rng.choice([0.0, 1e-5, 2e-4, edge * 0.05])
    return measured, uncertainty


def test_a_measured_interval_is_its_finding() -> None:
    rng = random.Random(7)
    for window in WINDOWS:
        for _ in range(200):
            measured, u = _interval(rng, window)
            evidence = rng.choice([None, [], ["reply to 0M!"]])
            m = Measured(window, measured, u, evidence)
            f = judge_window(
                window.requirement, window.what, measured, u, low=window.low,
                high=window.high, tolerance=window.tolerance, should=window.should,
                evidence=evidence, decision=window.decision,
            )  # fmt: skip
            assert asdict(m.finding) == asdict(f)
            for key in ("verdict", "measured_ms", "margin_ms", "uncertainty_ms", "limit_ms",
                        "detail", "evidence", "observed", "decision", "requirement"):  # fmt: skip
                assert getattr(m, key) == getattr(f, key), key


@pytest.mark.parametrize("real_time", [False, True])
def test_aggregates_of_measured_intervals_equal_those_of_findings(real_time: bool) -> None:
    """combine_local and to_confirm over Measured stand-ins give what they give over the
    findings: on a virtual clock and on a real-time link (set-aside, rare and recurring
    deviations, places)."""
    rng = random.Random(3)
    window = WINDOWS[0]
    for trial in range(150):
        observed_m, observed_f = [], []
        for _ in range(rng.choice([1, 3, 12, 40])):
            measured = rng.choice([0.0, 0.4e-3, 1.2e-3, 1.6e-3, 1.7e-3, 2.5e-3])
            if rng.random() < 0.9:
                measured = min(measured, 1.5e-3)  # mostly conforming: rare deviations
            u = rng.choice([0.0, 0.0, 0.05e-3, 0.3e-3])
            tainted = u > 0.1e-3
            place = (f"0D{rng.randrange(2)}!", "0+1.0<CR><LF>", rng.randrange(3))
            m = Measured(window, measured, u, ["in reply to 0D0!"])
            observed_m.append((m, tainted, place))
            observed_f.append(
                (
                    m.finding if trial % 2 else window.judge(measured, u, ["in reply to 0D0!"]),
                    tainted,
                    place,
                )
            )  # noqa: E501
        for smallest in (False, True):
            a = combine_local("R-7.0-12", observed_m, "character gap", smallest_is_worst=smallest,
                              real_time=real_time)  # fmt: skip
            b = combine_local("R-7.0-12", observed_f, "character gap", smallest_is_worst=smallest,
                              real_time=real_time)  # fmt: skip
            assert asdict(a) == asdict(b)
        assert to_confirm(observed_m, real_time=real_time) == to_confirm(
            observed_f, real_time=real_time
        )
        found = [o[0] for o in observed_m]
        assert asdict(combine("R-7.0-12", found, "gap")) == asdict(
            combine("R-7.0-12", [m.finding for m in found], "gap")
        )


def test_what_combine_hands_on_is_not_the_shared_observation() -> None:
    """Observations are shared by a run's judges: extending a combined finding's evidence
    leaves the next combination as it was."""
    window = WINDOWS[0]
    observed = [(Measured(window, 2e-3, 0.0, ["in reply to 0M!"]), False, None)]
    first = combine_local("R-7.0-12", observed, "character gap", real_time=False)
    first.evidence.append("more")
    again = combine_local("R-7.0-12", observed, "character gap", real_time=False)
    assert again.evidence == ["in reply to 0M!"]


def _reply(t: float, text: str, gap: float) -> list[Event]:
    out = []
    for ch in text:
        out.append(Event(EventKind.CHAR, DUT, t, t + 8.33e-3, wire=to_wire_7e1(ord(ch))))
        t += 8.33e-3 + gap
    return out


def _command(t: float, text: str) -> list[Event]:
    return [
        Event(EventKind.CHAR, TOOL, t + i * 8.33e-3, t + (i + 1) * 8.33e-3,
              wire=to_wire_7e1(ord(c)))
        for i, c in enumerate(text)
    ]  # fmt: skip


def _run() -> list[Event]:
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013)]
    events += _command(0.03, "0D0!")
    events += _reply(0.03 + 4 * 8.33e-3 + 0.010, "0+1.5+22.25\r\n", 0.3e-3)
    events += _command(0.4, "0D1!")
    events += _reply(0.4 + 4 * 8.33e-3 + 0.010, "0+1.5+2.25\r\n", 1.9e-3)
    return events


def test_gap_judges_share_one_cut_and_judge_it_as_a_plain_list_would() -> None:
    segs = wire.segments(_run())
    assert isinstance(segs, Segments)
    stamps = StampUncertainty(0.1e-3, lambda a, b: 0.4e-3 if a < 0.4 else 0.0)
    cached = [asdict(f) for f in wire.judge_gaps(segs, stamps)]
    assert cached == [asdict(f) for f in wire.judge_gaps(list(segs), stamps)]
    assert wire._gaps(segs) is wire._gaps(segs)  # cut once per segments
    observed = wire._gap_observations(segs, stamps)
    assert wire._gap_observations(segs, stamps) is observed  # judged once per stamps
    assert wire._gap_observations(segs, StampUncertainty(0.1e-3)) is not observed
    assert wire.gaps_to_confirm(segs, stamps) == wire.gaps_to_confirm(list(segs), stamps)
    verdicts = {f["requirement"]: f["verdict"] for f in cached}
    assert verdicts["R-7.0-12"] == "FAIL"  # the 1.9 ms gaps of the second reply


def test_equal_gaps_share_a_judgement_but_not_a_signed_zero() -> None:
    segs = Segments(wire.segments(_run()))
    observed = wire._observe_gaps(segs, StampUncertainty(0.0))
    assert len({id(o[0]) for o in observed}) < len(observed)
    window = wire.GAP_WINDOW
    negative = Measured(window, -0.0, 0.0, ["x"])
    assert negative.detail != Measured(window, 0.0, 0.0, ["x"]).detail  # why it is apart


def _observation_figures(observed) -> list[tuple]:
    """Each observation's figures and which earlier one shares its Measured (by position)."""
    first: dict[int, int] = {}
    return [
        (
            m.measured, copysign(1.0, m.measured), m.uncertainty, m.verdict, m.margin_ms,
            m.evidence_lines, tainted, place, first.setdefault(id(m), i),
        )
        for i, (m, tainted, place) in enumerate(observed)
    ]  # fmt: skip


@pytest.mark.parametrize("base", [0.0, 1e-5, 0.4e-3])
def test_gaps_of_one_uncertainty_are_observed_as_the_general_path_does(base) -> None:
    """Without local irregularity (a virtual clock, a capture's grid) the gaps are observed
    by the short loop (_observe_gaps_alike): the same observations, shared alike, as the
    general loop gives when a local uncertainty that is never above the base is asked."""
    rng = random.Random(5)
    events = _run()
    t = 1.0
    for _ in range(40):  # replies with equal, signed-zero, overlapping and random gaps
        events += _command(t, "0D0!")
        t += 4 * 8.33e-3 + 0.010
        for c in "0+1.5+2\r\n":
            gap = rng.choice([0.0, -0.0, 0.3e-3, 1.9e-3, -1e-3, rng.random() * 2e-3])
            events.append(Event(EventKind.CHAR, DUT, t, t + 8.33e-3, wire=to_wire_7e1(ord(c))))
            t += 8.33e-3 + gap
        t += 0.2
    segs = wire.segments(events)
    alike = wire._observe_gaps(segs, StampUncertainty(base))
    general = wire._observe_gaps(segs, StampUncertainty(base, lambda a, b: base / 2))
    assert len(alike) > 300
    assert _observation_figures(alike) == _observation_figures(general)


def test_the_least_spacing_is_the_one_min_gives() -> None:
    """judge_reply_bit_rate keeps the least (spacing, command) as it goes: the pair ``min``
    over a list of them all gives, ties between commands broken by the text, a negative zero
    kept where it came first."""
    rng = random.Random(3)
    for _ in range(200):
        segs = []
        for _ in range(rng.randrange(1, 6)):
            t = rng.random()
            reply = []
            for _ in range(rng.randrange(0, 5)):
                reply.append(Event(EventKind.CHAR, DUT, t, t + 8.33e-3, wire=0x30))
                t += rng.choice([8.33e-3, 8.33e-3, 0.0, -0.0, 4e-3, 9e-3])
            segs.append(Segment(None, [], reply, text=rng.choice(["0D0!", "0D1!", "1D0!"])))
        pairs = [
            (b.start - a.start, seg.text)
            for seg in segs
            for a, b in zip(seg.reply, seg.reply[1:], strict=False)
        ]
        count, least, _fast = wire._spacings(segs, StampUncertainty(0.0))
        assert count == len(pairs)
        if pairs:
            assert least == min(pairs) and copysign(1.0, least[0]) == copysign(1.0, min(pairs)[0])
        else:
            assert least is None


def test_transcript_lines_are_what_the_json_module_writes(tmp_path) -> None:
    events = [
        *_run(),
        Event(EventKind.NOTE, TOOL, 0.0, 0.0, text='run-options {"port": "sim"} é\u2013\n'),
        Event(EventKind.CHAR, "sensor-1", 1.25, 1.26, wire=0x8D, uncertainty=2.5e-4),
        Event(EventKind.BREAK, TOOL, 3, 4),  # int stamps: the json module's way
        Event(EventKind.CHAR, DUT, 5.0, math.inf, wire=1),
        Event(EventKind.CHAR, DUT, 6.0, 6.1, wire=2, duration_uncertainty=1e-6),
        Event(EventKind.CHAR, DUT, 7.0, 7.1, wire=True),  # a bool is not an int to json
        Event(EventKind.CHAR, DUT, 1e-320, 123456789.123456789, text="\x00\t\\"),
    ]
    path = tmp_path / "t.jsonl"
    Transcript(list(events)).write_jsonl(str(path))
    expected = "".join(json.dumps(e.to_json()) + "\n" for e in events)
    assert path.read_text(encoding="utf-8") == expected


def test_a_start_written_as_the_end_before_it_is_what_the_json_module_writes(tmp_path) -> None:
    """The writer reuses the text of the line before's end for a start equal to it: back to
    back characters, equal times after a signed zero, a non-plain line between, and random
    times, some equal to the end before, are written as json.dumps writes each alone."""
    rng = random.Random(11)
    events = [
        Event(EventKind.CHAR, DUT, 0.0, -0.0, wire=65),
        Event(EventKind.CHAR, DUT, 0.0, 0.1 + 0.2, wire=66),  # -0.0 before: 0.0 apart
        Event(EventKind.CHAR, DUT, -0.0, 0.3, wire=67),
        Event(EventKind.CHAR, DUT, 0.30000000000000004, 0.4, wire=68),  # == 0.1 + 0.2
        Event(EventKind.BREAK, TOOL, 3, 4),  # not plain: json.dumps
        Event(EventKind.CHAR, DUT, 4.0, 5.0, wire=69),  # equal to the int 4 before
        Event(EventKind.CHAR, DUT, 5.0, math.inf, wire=70),  # not finite: json.dumps
        Event(EventKind.CHAR, DUT, 5.0, 6.0, wire=71),
    ]
    t = 0.0
    for _ in range(3000):
        start = t if rng.random() < 0.6 else t + rng.choice([1e-9, -1e-3, 0.0117, 1 / 3])
        t = start + rng.choice([8.33e-3, 1 / 120, 0.0, 1e-17, 7.123456789e-3])
        events.append(Event(EventKind.CHAR, DUT, start, t, wire=rng.randrange(256)))
    path = tmp_path / "t.jsonl"
    Transcript(list(events)).write_jsonl(str(path))
    expected = "".join(json.dumps(e.to_json()) + "\n" for e in events)
    assert path.read_text(encoding="utf-8") == expected


def test_the_writer_says_whether_every_event_was_plain(tmp_path) -> None:
    """What write_recording keeps as a transcript's own reading rests on this answer."""
    plain = [Event(EventKind.CHAR, DUT, 1.0, 2.0, wire=65)]
    assert Transcript(plain).write_jsonl(str(tmp_path / "a.jsonl")) is True
    int_times = [*plain, Event(EventKind.BREAK, TOOL, 3, 4)]
    assert Transcript(int_times).write_jsonl(str(tmp_path / "b.jsonl")) is False


def _random_window(rng: random.Random) -> list[Event]:
    """Tool and DUT events of every kind, close together, some overlapping, some stamps
    uncertain: what a collision scan is asked about."""
    events, t = [], 0.0
    for _ in range(rng.randrange(30)):
        t += rng.choice([0.0, 0.001, 0.004, 8.33e-3, 0.02, 0.1, -0.005])
        events.append(
            Event(
                rng.choice([EventKind.CHAR] * 5 + [EventKind.BREAK, EventKind.NOTE]),
                rng.choice([TOOL, DUT, "bus", "sensor-1"]),
                t,
                t + rng.choice([0.0, 1e-4, 8.33e-3, 0.012]),
                wire=65,
                uncertainty=rng.choice([0.0, 0.0, 0.002, 0.006]),
            )
        )
    return events


def test_collisions_are_found_exactly_where_a_tool_event_and_a_dut_character_overlap() -> None:
    """The scan returns early when nothing meets: it may never skip a real overlap."""
    from conformance.tool_recorder.contention import _overlap, collisions

    rng = random.Random(22)
    for _ in range(3000):
        window = _random_window(rng)
        tool = [e for e in window if e.kind is not EventKind.NOTE and e.origin == TOOL]
        dut = [e for e in window if e.kind is EventKind.CHAR and e.origin != TOOL]
        found = collisions(window)
        assert bool(found) == any(_overlap(d, t) for d in dut for t in tool)
        for c in found:
            assert all(any(_overlap(d, t) for t in c.tool) for d in c.dut)


def test_a_one_line_replys_stop_rule_is_the_general_one() -> None:
    """Framing.stop's shortcut for a one-line 7E1 reply, and a packet's size read from its
    first bytes, against the rules they stand for."""
    from conformance.tool_recorder.reply_end import Framing, _head
    from conformance.transcript import decode_8n1

    rng = random.Random(12)
    framings = [Framing(idle=0.01, max_chars=n) for n in (1, 3, 80)]
    for _ in range(2000):
        chars = [
            Event(rng.choice([EventKind.CHAR] * 6 + [EventKind.BREAK]), DUT, 0.0, 1.0,
                  wire=rng.choice([0x0D, 0x8D, 0x0A, 0x8A, 0x02, 0x03, 0x31, 0xB1]))
            for _ in range(rng.randrange(6))
        ]  # fmt: skip
        assert _head(chars) == decode_8n1(chars)[:3]
        for f in framings:
            general = len(chars) >= f.limit(chars) or f.finished(chars) or f.at_line_end(chars)
            assert f.stop(chars) == general


def test_the_collector_is_paced_for_a_run_and_restored_after() -> None:
    before = gc.get_threshold()
    pace = gc_pace.slow_down()
    try:
        assert gc.get_threshold() == gc_pace.RUN_THRESHOLDS
        assert gc.get_freeze_count() > 0
    finally:
        gc_pace.restore(pace)
    assert gc.get_threshold() == before
    assert gc.get_freeze_count() == 0


def test_a_run_paces_the_collector_and_leaves_it_as_found(tmp_path) -> None:
    from conformance.conduct import conduct
    from conformance.run import RunOptions

    seen = []

    class Probe:
        def pytest_runtest_call(self, item):
            seen.append(gc.get_threshold())

    before = gc.get_threshold()
    options = RunOptions(report_dir=str(tmp_path), keyword="test_query_address")
    result = conduct(options, html=False, rootdir=tmp_path, plugins=[Probe()])
    assert result.document is not None
    assert seen and set(seen) == {gc_pace.RUN_THRESHOLDS}
    assert gc.get_threshold() == before
    assert gc.get_freeze_count() == 0


def test_a_run_collects_even_when_its_caller_turned_the_collector_off(tmp_path) -> None:
    """A whole ``sdi12-conform`` process turns the collector off outside its run: the run
    itself still collects, at its pace, and the collector is off again after it."""
    from conformance.conduct import conduct
    from conformance.run import RunOptions

    seen = []

    class Probe:
        def pytest_runtest_call(self, item):
            seen.append((gc.isenabled(), gc.get_threshold()))

    options = RunOptions(report_dir=str(tmp_path), keyword="test_query_address")
    gc.disable()
    try:
        result = conduct(options, html=False, rootdir=tmp_path, plugins=[Probe()])
        assert not gc.isenabled()
    finally:
        gc.enable()
    assert result.document is not None
    assert seen and set(seen) == {(True, gc_pace.RUN_THRESHOLDS)}


_PROBE = (
    "import gc, json, sys\n"
    "from conformance import cli, conduct\n"
    "seen = {}\n"
    "real = conduct.conduct\n"
    "class Probe:\n"
    "    def pytest_runtest_call(self, item):\n"
    "        seen['run'] = gc.isenabled()\n"
    "def probed(options, **kw):\n"
    "    seen['before'] = gc.isenabled()\n"
    "    kw['plugins'] = [*kw.get('plugins', ()), Probe()]\n"
    "    result = real(options, **kw)\n"
    "    seen['after'] = gc.isenabled()\n"
    "    return result\n"
    "conduct.conduct = probed\n"
    "import atexit\n"
    "atexit.register(lambda: print('SEEN ' + json.dumps(seen)))\n"
    "sys.argv = ['sdi12-conform', *sys.argv[1:]]\n"
    "cli.main()\n"
)


def test_the_main_commands_sim_process_never_collects(tmp_path) -> None:
    """``sdi12-conform --port sim`` as a process: a bounded run in virtual time, so the
    collector is off before, during and after the run (gc_pace.never_in_this_process)."""
    import subprocess
    import sys

    probe = tmp_path / "probe.py"
    probe.write_text(_PROBE, encoding="utf-8")
    done = subprocess.run(
        [sys.executable, str(probe), "--port", "sim", "-k", "test_query_address",
         "--report-dir", str(tmp_path / "r")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stdout.splitlines() if x.startswith("SEEN "))
    assert json.loads(line[5:]) == {"before": False, "run": False, "after": False}


def test_a_process_that_never_collects_is_not_paced(monkeypatch) -> None:
    monkeypatch.setattr(gc_pace, "_NEVER", True)
    before = gc.get_threshold()
    gc.disable()
    try:
        pace = gc_pace.slow_down()
        assert not gc.isenabled() and gc.get_threshold() == before
        assert gc.get_freeze_count() > 0  # an explicit gc.collect() skips what was loaded
        gc_pace.restore(pace)
        assert not gc.isenabled() and gc.get_threshold() == before
        assert gc.get_freeze_count() == 0
    finally:
        gc.enable()


def in_collectors_sight(thing: object) -> bool:
    """``thing`` is among the objects the collector walks: tracked and not frozen."""
    return any(o is thing for o in gc.get_objects())


def test_before_a_library_collects_what_exists_is_frozen_only_where_nothing_collects(
    monkeypatch,
) -> None:
    """gc_pace.freeze_for_libraries (before hypothesis, whose register_random collects once a
    process): in a process that never collects, what the run made so far is frozen with what
    was loaded; anywhere else (a paced run, a caller's process) nothing changes.

    Whether the run's objects were frozen is asked of the objects themselves (the collector's
    view, ``gc.get_objects``, leaves frozen ones out), not of the frozen count: that count also
    falls whenever a frozen object is freed, on any thread (an xdist worker's own, or one an
    earlier test of the worker left), and "count unchanged" failed so (118007 == 118009) in
    5 of 5 runs of tests/kit, test_cli, test_conduct... with this file under ``-n 2``."""
    pace = gc_pace.slow_down()  # a paced run: collecting, so nothing more is frozen
    try:
        made_paced = [[n] for n in range(1000)]  # objects the run made
        gc_pace.freeze_for_libraries()
        assert in_collectors_sight(made_paced) and in_collectors_sight(made_paced[-1])
    finally:
        gc_pace.restore(pace)
    monkeypatch.setattr(gc_pace, "_NEVER", True)
    gc.disable()
    try:
        pace = gc_pace.slow_down()
        made_never = [[n] for n in range(1000)]
        gc_pace.freeze_for_libraries()
        assert not in_collectors_sight(made_never) and not in_collectors_sight(made_never[-1])
        gc_pace.restore(pace)
        assert gc.get_freeze_count() == 0
    finally:
        gc.enable()
    assert len(made_paced) == len(made_never)  # both kept alive to the end


def test_the_main_command_called_in_a_process_keeps_collecting(tmp_path) -> None:
    """main(argv) in someone else's process (a test, a rack worker's caller) leaves the
    collector to that process: on after the run, and runs after it still paced."""
    from conformance import cli

    assert gc.isenabled()
    code = cli.main(["--port", "sim", "-k", "test_query_address",
                     "--report-dir", str(tmp_path / "r"), "--plan", "never"])  # fmt: skip
    assert code == 0
    assert gc.isenabled() and not gc_pace._NEVER


#: What a sensor run on the simulated bus needs none of (issue 22: the start-up cost of a
#: run): the recorder role, the emulator servers, the passive and capture code, the rack and
#: the subcommands, pyserial's siblings that only real benches use, and off a terminal rich
#: (its bar, tables and console: the lines are plain); and hypothesis, which only the
#: exploration case loads (the ``-k`` run below selects another). Each entry is a package
#: or a module.
NOT_ON_A_SENSOR_RUN = (
    "hypothesis",
    "conformance.sensor.exploration_machine",
    "conformance.recorder.scenario_runner",
    "conformance.recorder.openers",
    "conformance.recorder.drivers",
    "conformance.recorder.job_time",
    "conformance.emulator_server",
    "conformance.offline.heard",
    "conformance.offline.judge",
    "conformance.capture.sigrok",
    "conformance.capture.decode",
    "conformance.rack.pool",
    "conformance.monitor",
    "conformance.matrices",
    "conformance.commands",
    "conformance.kit",
    "conformance.calibrate",
    "conformance.suggest",
    "conformance.reports.diff",  # --baseline only
    "execnet",
    "numpy",
    "asyncio",
    "unittest",  # pytest's unittest plugin is blocked (conformance.suite.UNUSED_PYTEST_PLUGINS)
    "serial",  # pyserial, the serial, RFC 2217, adapter and harness links and the capture
    "conformance.links.factory",  # link: kinds a sim port never looks up (links.registry.defer)
    "conformance.links.serial_link",
    "conformance.links.adapter_link",
    "conformance.harness.device",
    "conformance.replay.recording_link",
    "pdb",  # so is its debugging plugin, which imported pdb (and readline, cmd, code) to wrap it
    "rich",  # off a terminal the main command's lines are plain (reports.plain_console)
    "readline",  # pytest's capture plugin imported it early; the judged run blocks it
    "tomllib",  # a declaration file's reader: a run given none parses no TOML
    "jinja2",  # report.html's template: read by the forked child that renders the page
    "markupsafe",  # (reports.page_template), which is not this process
)

#: the CLI as ``sdi12-conform`` runs it (the whole process: ``main()`` with no argv), with
#: the module table written out when the process ends (its exit runs the atexit handlers)
MODULES_AT_EXIT = """
import atexit, json, sys
out = sys.argv.pop(1)
atexit.register(lambda: open(out, "w").write(json.dumps(sorted(sys.modules))))
from conformance.cli import main
main()
"""


def _no_terminal_env() -> dict[str, str]:
    """This environment without what would make rich treat a pipe as a terminal."""
    import os

    from conformance.reports.plain_console import TERMINAL_ENV

    return {k: v for k, v in os.environ.items() if k not in TERMINAL_ENV}


def test_a_sensor_run_on_the_simulated_bus_loads_only_what_it_needs(tmp_path) -> None:
    """The whole ``sdi12-conform --port sim`` process, off a terminal, imports none of
    :data:`NOT_ON_A_SENSOR_RUN`: a module-level import that pulls one back in (and its
    start-up cost into every run, every matrix row and every CI job) fails here. It runs in
    a folder of its own, as a user's does: in a checkout, pytest would also load the tool's
    own ``tests/conftest.py`` (pytest reads ``test*/conftest.py`` under where it starts)."""
    import subprocess
    import sys

    listed = tmp_path / "modules.json"
    done = subprocess.run(
        [sys.executable, "-c", MODULES_AT_EXIT, str(listed), "--port", "sim",
         "-k", "test_query_address", "--report-dir", str(tmp_path / "run"), "--plan", "never"],
        capture_output=True, text=True, timeout=120, cwd=tmp_path, env=_no_terminal_env(),
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    loaded = set(json.loads(listed.read_text()))
    assert "conformance.sensor.session" in loaded  # the run did run
    # what ``import pytest`` alone loads is not the tool's to choose: pytest 9.0's own
    # ``pytest/__init__`` imports its debugging plugin and with it unittest; 9.2's does not
    alone = subprocess.run(
        [sys.executable, "-c", "import json, sys, pytest; print(json.dumps(list(sys.modules)))"],
        capture_output=True, text=True, timeout=60, cwd=tmp_path, check=True,
    )  # fmt: skip
    loaded -= set(json.loads(alone.stdout))
    found = sorted(
        m for m in loaded for unwanted in NOT_ON_A_SENSOR_RUN
        if m == unwanted or m.startswith(unwanted + ".")
    )  # fmt: skip
    assert not found, f"a sensor run on the sim bus imported {found}"


def test_the_run_needs_no_assertion_rewriting() -> None:
    """The judged run has no assertion rewriting (pytest's ``assertion`` plugin blocked,
    which also leaves ``--assert`` at plain; a run that cannot cache it spent ~0.1 s
    rewriting): right only while no conformance case and not the plugin uses a bare
    ``assert``, whose failure message rewriting would have explained (a case records
    findings through ``case``)."""
    import ast
    from pathlib import Path

    from conformance import plugin
    from conformance.suite import SUITE_ROOT, suite_args

    args = suite_args("testcases.sensor", "out")
    assert "no:assertion" in args and not any(a.startswith("--assert") for a in args)
    sources = [*sorted((SUITE_ROOT / "testcases").rglob("*.py")), Path(plugin.__file__)]
    asserting = [
        f"{path}:{node.lineno}"
        for path in sources
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Assert)
    ]
    assert len(sources) > 10 and not asserting, asserting


def test_stop_after_a_read_is_stop_of_the_reply_so_far() -> None:
    """Framing.stop_after(have, more), asked after every character without making
    ``have + more``, against Framing.stop of that list, for every kind of framing."""
    from conformance.tool_recorder.reply_end import Framing

    rng = random.Random(21)
    framings = [Framing(idle=0.01, max_chars=n) for n in (1, 3, 80)] + [
        Framing(idle=0.01, max_chars=80, binary=True),
        Framing(idle=0.01, max_chars=80, multiline=True, max_text_chars=200),
    ]
    codes = [0x0D, 0x8D, 0x0A, 0x8A, 0x02, 0x03, 0x31, 0xB1]
    for _ in range(2000):
        chars = [
            Event(rng.choice([EventKind.CHAR] * 6 + [EventKind.BREAK]), DUT, 0.0, 1.0,
                  wire=rng.choice(codes))
            for _ in range(rng.randrange(1, 8))
        ]  # fmt: skip
        cut = rng.randrange(len(chars))  # ``more`` holds at least one character
        for f in framings:
            assert f.stop_after(chars[:cut], chars[cut:]) == f.stop(chars)


def test_a_command_parsed_again_is_what_a_first_parse_gives() -> None:
    """parse_command's memo: every text, valid or not, wildcard or not, str or bytes, gives
    what the grammar gives it (the same command, or an error with the same reason), the first
    time and every time after, also once the memo was cleared for growing."""
    from conformance.protocol import commands
    from conformance.protocol.commands import CommandError, _parse_text, parse_command

    rng = random.Random(5)
    texts = ["0!", "?!", "0I!", "0M!", "0MC3!", "0D0!", "0DB12!", "0D01!", "0IM1_002!", "0XYZ!",
             "0A1!", "0AA1!", "0", "", "0\x01!", "0!!", "?M!", "!", "0R9!", "0RC3!", "0IR0!",
             "0HB!", "0I_001!", "0IM_01!", "0XWT!", "$M!"]  # fmt: skip
    texts += ["".join(rng.choice("0?!MDCIRVHAB_1239x") for _ in range(rng.randrange(7)))
              for _ in range(400)]  # fmt: skip

    def fresh(text: str, wildcard: bool) -> tuple[str, object]:
        try:
            return "ok", _parse_text(text, wildcard)
        except CommandError as exc:
            return "error", (exc.text, exc.reason, str(exc))

    def memo(text: str | bytes, wildcard: bool) -> tuple[str, object]:
        try:
            return "ok", parse_command(text, allow_wildcard=wildcard)
        except CommandError as exc:
            return "error", (exc.text, exc.reason, str(exc))

    commands._PARSED.clear()
    for _round in range(3):
        for text in texts:
            for wildcard in (False, True):
                expected = fresh(text, wildcard)
                assert memo(text, wildcard) == expected
                assert memo(text.encode("ascii"), wildcard) == expected
        commands._PARSED_MAX, saved = 7, commands._PARSED_MAX
        commands._PARSED.clear()
        try:
            for text in texts:
                assert memo(text, False) == fresh(text, False)
                assert len(commands._PARSED) <= 7
        finally:
            commands._PARSED_MAX = saved


def test_events_in_order_and_apart_are_what_the_sorted_pass_finds_apart() -> None:
    """contention's in-order shortcut says 'apart' only where the sorted pass finds no
    tool event meeting a DUT character; windows in start order (as a sim bus appends them),
    shuffled, and with equal starts."""
    from conformance.tool_recorder.contention import _apart_in_order, collisions

    rng = random.Random(23)
    shortcut = 0
    for n in range(3000):
        window = _random_window(rng)
        if n % 3:
            window.sort(key=lambda e: e.start)  # stable: notes and ties keep their order
        sorted_wire = sorted((e for e in window if e.kind is not EventKind.NOTE),
                             key=lambda e: e.start)  # fmt: skip
        apart = _apart_in_order(window)
        if apart:
            shortcut += 1
            assert [e for e in window if e.kind is not EventKind.NOTE] == sorted_wire
            assert collisions(list(reversed(window))) == []  # the full pass agrees
        assert (collisions(window) == []) >= apart
    assert shortcut > 300  # the shortcut was taken, so the comparison compared something


def test_apart_so_far_says_apart_only_where_the_window_is_apart() -> None:
    """contention.ApartSoFar, read on as a transcript grows (events appended in bursts, in
    order or not, the window's start moving on, the list replaced now and then), says
    'apart' only where _apart_in_order of the window asked about does; and it says so
    often for a transcript that is in order."""
    from conformance.tool_recorder.contention import ApartSoFar, _apart_in_order

    rng = random.Random(31)
    held = 0
    for trial in range(300):
        apart, events, t, scanned = ApartSoFar(), [], 0.0, 0
        ordered = trial % 3 != 0
        for _step in range(40):
            for _ in range(rng.randrange(6)):
                t += rng.choice([0.009, 0.02, 0.1, 0.0] + ([] if ordered else [-0.005]))
                kind = rng.choice([EventKind.CHAR] * 5 + [EventKind.NOTE])
                origin = TOOL if rng.random() < 0.5 else DUT
                events.append(Event(kind, origin, t, t + 8.33e-3 * rng.random()))
            if rng.random() < 0.03:
                events = list(events)  # a new list: its identity says nothing
            first = max(0, scanned - rng.choice([0, 3, 64]))
            if apart.holds(events, first):
                held += 1
                assert _apart_in_order(events[first:])
            scanned = len(events)
    assert held > 3000
