"""``sdi12-conform judge FILE``: verdicts for a recording.

Two ways, chosen by what the file is:

- a ``transcript.jsonl`` (or run folder) of a virtual-time run (sim, harness) is judged by
  **replay**: the same cases run again and the recording answers them, so the verdicts are the
  run's own (``--port replay:FILE``);
- anything else (a logic-analyzer capture, a monitor's transcript, a run over a real link) is
  judged **passively**: what is on the wire is segmented, its direction inferred where the
  recording does not say, and every rule that traffic can show is judged.

This module only decides and prepares; the CLI runs the suite (it owns the console and the
report writing), so the layers keep running one way.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field, replace
from functools import cache
from pathlib import Path

from ..capture import (
    CaptureDecode,
    CaptureError,
    CaptureMeta,
    decode_capture,
    embedded_meta,
    read_edges,
    sniff,
)
from ..capture.export import TOOL_CHANNEL
from ..preflight import UsageError, check_report_dir
from ..replay.link import VIRTUAL_KINDS
from ..replay.recording import (
    Recording,
    RecordingError,
    hold_capture,
    hold_recording,
    options_in,
    read_recording,
    transcript_path,
    write_recording,
)
from ..report_folder import held, run_folder
from ..run import RunOptions
from ..transcript import BUS, DUT, TOOL, Event, EventKind, plain_fields
from ..view.direction import infer_directions
from ..view.sides import RECORDER, SENSOR
from .job import PassiveJob

ROLES = ("sensor", "recorder", "both")

JUDGE_EXAMPLES = """\
examples:
  sdi12-conform judge reports/20250101-120000-sensor      a saved sim run, by replay
  sdi12-conform export reports/20250101-120000-sensor --to sr
  sdi12-conform judge reports/20250101-120000-sensor/capture.sr
                                                          its capture: the run's verdicts
  sdi12-conform judge field.sr --channel D0 --role sensor  a field capture, passively
  sdi12-conform judge logic2.csv --channel SDI12 --tx-channel RTX
                                                          a Logic 2 export with the
                                                          recorder's TX on its own probe
  sdi12-conform judge reports/20250101-120000-monitor/transcript.jsonl
                                                          what a monitor heard

exit codes: 0 compliant, 1 non-compliant, 2 interrupted or incomplete (rules the recording
  cannot show), 4 a recording or option that cannot be used.
"""


class JudgeError(ValueError):
    """A recording or option ``judge`` cannot use (exit 4, one line, no traceback)."""


@dataclass
class JudgePlan:
    """What ``judge`` will do: replay a run (``replay``: the main command's options for it)
    or judge a recording passively (``passive``: the passive cases' job)."""

    path: Path
    kind: str  # "jsonl", "sr", "vcd", "csv"
    replay: RunOptions | None = None
    passive: PassiveJob | None = None
    notes: list[str] = field(default_factory=list)
    #: the role this tool's run judged, when the recording is of one: judged passively, only
    #: that role's rules by default (the other side is the tool's own, partly deliberately
    #: out-of-spec, stimuli; ``--role both`` judges it too)
    run_role: str | None = None


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="sdi12-conform judge",
        description=(
            "Judge a recording: a run's transcript.jsonl (or its folder), a sigrok .sr session, "
            "a Saleae Logic 2 CSV export or a VCD. A virtual-time run is replayed through the "
            "same cases (the same verdicts); anything else is judged passively."
        ),
        epilog=JUDGE_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", help="the recording")
    parser.add_argument(
        "--role",
        choices=ROLES,
        help="whose rules: sensor rules on what the sensors sent, recorder rules on what the "
        "recorder sent (default: the role a run of this tool judged; otherwise both)",
    )
    parser.add_argument("--address", help="judge only this sensor address")
    parser.add_argument("--channel", help="capture channel carrying the SDI-12 line")
    parser.add_argument(
        "--tx-channel", help="capture channel carrying only the recorder's TX (optional)"
    )
    polarity = parser.add_mutually_exclusive_group()
    polarity.add_argument(
        "--invert",
        dest="invert",
        action="store_true",
        default=None,
        help="the capture has the SDI-12 line's levels (marking low); default: detected",
    )
    polarity.add_argument(
        "--no-invert",
        dest="invert",
        action="store_false",
        help="the capture has UART levels (marking high); default: detected",
    )
    parser.add_argument("--baud", type=int, default=1200, help="bit rate (default 1200)")
    parser.add_argument(
        "--glitch-filter-us",
        type=float,
        default=None,
        metavar="US",
        help="a capture's pulses shorter than this are removed before decoding, counted in "
        "the notes (default: 1/16 of a bit, 52 us at 1200 baud; 0: off)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="judge a capture whose decode is mostly errors (a wrong bit rate, framing or "
        "channel, it seems) instead of refusing it; the notes keep why it was refused",
    )
    parser.add_argument("--report-dir", help="output folder (default: reports/<date>-judge)")
    parser.add_argument("--strict", action="store_true", help="WARN (SHOULD violations) fails")
    parser.add_argument(
        "--sdi-version", help="the rule set, 1.3 or 1.4 (default: from the recording)"
    )
    parser.add_argument(
        "--run",
        help="a capture of a run of this tool: that run's folder (or transcript.jsonl), whose "
        "cases are repeated against the capture (default: the options an export left in it)",
    )
    parser.add_argument(
        "--passive",
        action="store_true",
        help="judge a replayable run passively too (what the wire shows, no replay)",
    )
    return parser


@cache
def _parser() -> argparse.ArgumentParser:
    """:func:`build_parser`'s parser, built once a process: parsing leaves a parser as it
    was, and building its 16 options was ~1 ms of each fault-matrix row's round trip, whose
    :func:`plan` parses a judge command line per row (issue 22, replay27)."""
    return build_parser()


#: the files a run folder holds beside its recording, which ``judge`` is sometimes given
RUN_REPORTS = frozenset({"verdicts.json", "junit.xml", "report.html"})


def plan(argv: list[str], *, in_memory: bool = False) -> JudgePlan:
    """Parse ``judge``'s arguments and decide how to judge the file (JudgeError if not).
    ``in_memory``: a capture's decoding is not written to capture.jsonl but held for its
    replay (:func:`~conformance.replay.recording.hold_recording`; the caller lets it go with
    :func:`~conformance.replay.recording.held_recordings`): the fault matrix's round trip."""
    args = _parser().parse_args(argv)
    path = Path(args.file)
    if path.is_dir():
        path = transcript_path(path)
    elif path.name in RUN_REPORTS and (path.parent / "transcript.jsonl").is_file():
        # A run's report beside its recording: the parse error it drew ("line 1: not a
        # transcript event (Expecting property name ...)") did not say what to pass instead.
        raise JudgeError(
            f"{path}: a report of a run, not a recording; judge the run's folder "
            f"({path.parent}) or its transcript ({path.parent / 'transcript.jsonl'})"
        )
    try:
        kind = sniff(str(path))
    except CaptureError as exc:
        raise JudgeError(str(exc)) from None
    found = JudgePlan(path, kind)
    if kind == "jsonl":
        try:
            recording = read_recording(path)
        except RecordingError as exc:
            raise JudgeError(str(exc)) from None
        why_not = replay_refused(recording, args)
        if why_not is None:
            found.replay = replay_options(recording, args)
            return found
        found.notes.append(f"judged passively: {why_not}")
        if recording.options:
            found.run_role = recording.role
    else:
        capture_replay(found, args, in_memory)
        if found.replay is not None:
            return found
    if args.role is None and found.run_role is not None:
        other = "recorder" if found.run_role == "sensor" else "sensor"
        found.notes.append(
            f"{found.run_role} rules only: the recording is of this tool's {found.run_role} "
            f"run, whose {other} side is the tool's own stimuli (--role both judges them too)"
        )
    found.passive = passive_job(path, kind, args, found.run_role)
    return found


def capture_replay(found: JudgePlan, args: argparse.Namespace, in_memory: bool = False) -> None:
    """Set ``found.replay`` when the capture is of a run of this tool whose cases can be
    repeated against it: its options come from ``--run`` or from the notes an export kept in
    it, and every character's direction is known (else a note says why it is judged
    passively). The capture is decoded first in any case: a broken one is refused here."""
    meta = embedded_meta(str(found.path))
    if args.run:
        try:
            notes = [e for e in read_recording(args.run).events if e.kind is EventKind.NOTE]
        except RecordingError as exc:
            raise JudgeError(f"--run: {exc}") from None
    else:
        notes = meta.notes
    options = options_in(notes)
    tool_tx = tool_channel(meta, args, found.path) if options else None
    # held in memory, the decode's characters stay columns: the replay reads those alone
    # judged passively (no run's options), its events compact: the loader takes this decode
    columns = in_memory and bool(options)
    decoded = decode(found.path, args, tool_tx, columns=columns, compact=not options)
    found.notes.extend(describe_decode(decoded))
    if not options:
        found.notes.append("judged passively: the capture does not say which run it is of")
        return
    found.run_role = str(options.get("role", "sensor"))
    if tool_tx and found.run_role == "sensor":
        args.tx_channel = tool_tx  # the tool was the recorder: its TX is the recorder's
    columns = decoded.columns
    if columns is not None and BUS in columns.origin:  # directions to infer: events needed
        decoded.events, decoded.columns, columns = columns.events(), None, None
    events, unsettled = directed(decoded.events) if columns is None else ([], 0)
    if unsettled:
        found.notes.append(
            f"judged passively: the protocol does not settle who sent {unsettled} of the "
            "capture's characters, and a replay needs every one (a --tx-channel settles it)"
        )
        return
    report_dir = run_folder(args.report_dir, str(options.get("role", "sensor")))
    decoded_path = report_dir / "capture.jsonl"
    try:  # nothing is written into a folder another live run holds (issue 19)
        check_report_dir(report_dir)
        # columns are held as they are where they stand for the events exactly, else made
        kept = columns is not None and hold_capture(decoded_path, notes, columns)
        if not kept:
            if columns is not None:
                events = columns.events()
            decoded_events = sorted([*notes, *events], key=lambda e: e.start)
            # held only where the events are what the file would read back as
            # (write_recording's rule)
            kept = in_memory and all(map(plain_fields, decoded_events))
            if kept:
                hold_recording(decoded_path, decoded_events)
            else:
                with held(report_dir):
                    write_recording(decoded_path, decoded_events)
    except UsageError as exc:
        raise JudgeError(str(exc)) from None
    recording = read_recording(decoded_path)
    why_not = replay_refused(recording, args)
    if why_not is not None:
        found.notes.append(f"judged passively: {why_not}")
        return
    args.report_dir = str(report_dir)
    found.replay = replay_options(recording, args)
    found.notes.append(
        f"decoded capture {'held in memory as' if kept else 'written to'} {decoded_path}"
    )


def directed(events: list[Event]) -> tuple[list[Event], int]:
    """``events`` with the direction the protocol implies where the capture does not give it
    (origin ``tool`` for the recorder's side, ``dut`` for the sensors'), and how many the
    protocol did not settle for sure. Those are not guessed: a replay needs every direction
    (a recorder replayed from a wrong one would act as the real one never did), so a capture
    with any left open is judged passively instead."""
    if not any(e.origin == BUS for e in events):
        return events, 0
    origin = {RECORDER: TOOL, SENSOR: DUT}
    out: list[Event] = []
    open_ = 0
    for e, d in infer_directions(events):
        if e.origin != BUS:
            out.append(e)
        elif d.side is None or not d.sure:
            open_ += 1
            out.append(e)
        else:
            out.append(replace(e, origin=origin[d.side]))
    return out, open_


def tool_channel(meta: CaptureMeta, args: argparse.Namespace, path: Path) -> str | None:
    """The channel holding only the tool's own transmissions in a capture of a run of this
    tool: ``--tx-channel``, else the one the export named (no option to repeat), else one
    named as the export names it. None when the bus channel asked for is that one."""
    if args.tx_channel:
        return args.tx_channel
    tool = meta.tool_channel or TOOL_CHANNEL
    if args.channel == tool or (meta.tool_channel is None and not has_channel(path, tool)):
        return None
    return tool


def has_channel(path: Path, name: str) -> bool:
    """Whether the capture at ``path`` has a channel ``name``."""
    try:
        return name in read_edges(str(path), None).channels
    except CaptureError:
        return False


def decode(
    path: Path,
    args: argparse.Namespace,
    tx_channel: str | None = None,
    columns: bool = False,
    compact: bool = False,
) -> CaptureDecode:
    """``path`` decoded; ``tx_channel``: the tool's own TX (default ``--tx-channel``), whose
    characters are the tool's (origin ``tool``, whatever side it played); ``columns``: its
    events kept as columns (:attr:`CaptureDecode.columns`), none made; ``compact``: kept in
    a :class:`~conformance.event_store.CompactEvents` (the passive judgement's loader takes
    this decode over: issue 22)."""
    try:
        return decode_capture(
            str(path),
            channel=args.channel,
            tx_channel=tx_channel or args.tx_channel,
            invert=args.invert,
            baud=args.baud,
            glitch_filter=glitch_filter(args.glitch_filter_us),
            force=args.force,
            columns=columns,
            compact=compact,
        )
    except CaptureError as exc:
        raise JudgeError(str(exc)) from None


def glitch_filter(us: float | None) -> float | None:
    """``--glitch-filter-us`` in seconds (None: the decoder's default)."""
    if us is not None and us < 0:
        raise JudgeError(f"--glitch-filter-us {us:g}: a width, 0 or more")
    return None if us is None else us * 1e-6


def describe_decode(decoded: CaptureDecode) -> list[str]:
    """What the reader must know about the decoding before trusting verdicts from it."""
    how = "detected" if decoded.polarity_detected else "forced"
    said = [
        f"capture {decoded.format}, channel {decoded.channel!r} at {decoded.sample_rate:g} "
        f"samples/s: {decoded.chars} characters, {decoded.breaks} breaks, "
        f"{decoded.pulses} spacing pulses; {decoded.polarity} polarity ({how}); stamps "
        f"\u00b1{decoded.uncertainty_s * 1e3:.3f} ms",
    ]
    problems = decoded.framing_errors + decoded.parity_errors + decoded.glitches
    if problems:
        said.append(
            f"{decoded.framing_errors} framing error(s), {decoded.parity_errors} parity "
            f"error(s), {decoded.glitches} glitch(es) in the capture"
        )
    if decoded.filtered:
        said.append(
            f"glitch filter {decoded.glitch_filter_s * 1e6:.0f} us: {decoded.filtered} "
            "pulse(s) shorter than that removed before decoding (spikes, chattering edges)"
            + (
                f"; {decoded.filtered_beside_edges} beside an edge that stayed, whose "
                f"position is known to the filter's width: stamps widened by it"
                if decoded.filtered_beside_edges
                else ""
            )
        )
    if decoded.forced_past:
        said.append(f"judged although the decode looks wrong (--force): {decoded.forced_past}")
    if decoded.partial_frames:
        said.append(
            f"{decoded.partial_frames} frame(s) the capture cut dropped, not judged (it began "
            "inside traffic, before a start bit could be told from a data bit, or ended inside "
            "a character)"
        )
    said.extend(decoded.notes)
    return said


def replay_refused(recording: Recording, args: argparse.Namespace) -> str | None:
    """Why this recording is not replayed (None: it is)."""
    if args.passive:
        return "--passive asked for it"
    link = recording.options.get("link") or {}
    kind = str(link.get("kind", "")).removeprefix("replay of ")
    if not recording.options:
        return "the transcript does not say how its run was made (no run-options note)"
    if not link.get("virtual_time") or kind not in VIRTUAL_KINDS:
        return (
            f"its run was over a {kind or 'real'} link in real time "
            "(only sim and harness runs replay)"
        )
    if args.role and args.role != recording.role:
        return f"--role {args.role} asked for, the run judged the {recording.role}"
    if args.address and args.address != recording.options.get("address"):
        return "--address differs from the run's"
    return None


def replay_options(recording: Recording, args: argparse.Namespace) -> RunOptions:
    """The main command's options that repeat the recorded run against its recording: the
    options its run-options note saved, with what ``judge`` was told on top."""
    saved = recording.options
    kept = {
        key: saved[key]
        for key in (
            "address", "version", "declaration", "timing_uncertainty_ms", "keyword",
            "sweep",  # a swept run's steps are in its recording: replayed too
            "profile",  # a production run's selection and the groups it tried
            "job_timeout",  # the budgets its scenario notes state
        )
        if saved.get(key) is not None
    }  # fmt: skip
    if saved.get("bus"):  # one sensor of a shared line (commands/bus.py): its bus, again
        kept["bus"] = tuple((str(a), None if i is None else str(i)) for a, i in saved["bus"])
    return RunOptions(
        port=f"replay:{recording.path}",
        role=str(saved.get("role", "sensor")),
        requirements=tuple(str(r) for r in saved.get("requirements") or ()),
        strict=bool(saved.get("strict") or args.strict),
        report_dir=args.report_dir,
        **(kept | ({"version": args.sdi_version} if args.sdi_version else {})),
    )


def passive_job(
    path: Path, kind: str, args: argparse.Namespace, run_role: str | None = None
) -> PassiveJob:
    """The passive judging's job (see :mod:`conformance.commands.passive`); ``run_role``: the
    default role when the recording is of a run of this tool (else both)."""
    return PassiveJob(
        recording=str(path),
        format=kind,
        role=args.role or run_role or "both",
        address=args.address,
        channel=args.channel,
        tx_channel=args.tx_channel,
        sdi_version=args.sdi_version,
        report_dir=args.report_dir,
        invert=args.invert,
        baud=args.baud,
        strict=args.strict,
        glitch_filter_us=args.glitch_filter_us,
        force=args.force,
    )


def capture_replay_stopped(plan_: JudgePlan, document: dict | None) -> str | None:
    """Why a capture's replay stopped because the capture, not the tool, went astray (None:
    it did not). A capture comes from outside: damaged, cut, or decoded on a wrong channel or
    polarity, it stops following its run; that leaves the run incomplete (exit 2), where a
    run's own transcript.jsonl diverging is the tool's failure (exit 3)."""
    from ..replay.sensor import DIVERGED

    if plan_.kind == "jsonl" or document is None:
        return None
    reason = document["run"].get("stop_reason") or ""
    if DIVERGED not in reason:
        return None
    return (
        f"{plan_.path} stops following the run it is of ({reason.split(': ', 1)[-1]}): "
        "is it damaged, or decoded on the wrong --channel or polarity? The verdicts up to "
        "there stand; the rest is not judged"
    )
