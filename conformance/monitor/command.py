"""``sdi12-conform monitor --port X``: watch a live SDI-12 bus without touching it, then judge it.

Many deviations only show in the field, between a real recorder and real sensors, where no
test tool may take charge of the bus. The monitor is one more receiver on the wire: it opens
the port listen-only (:mod:`conformance.links.listen`: nothing is ever written, no break, no
modem line changed), shows each line of traffic as it is heard (direction inferred from the
protocol, time since the line before, any rule the line visibly breaks), and appends every
event to ``transcript.jsonl`` as it goes, so a crash keeps what was heard. ``--duration`` (or
SIGTERM) ends it; what was seen is then judged passively by ``judge`` on that transcript, and
the judge's exit code is the monitor's, except that rules the bus never exercised do not make
a watch that ended as asked "incomplete". Ctrl-C stops it at once, as it stops every
subcommand: the transcript kept whole, nothing judged, exit 2.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING

from .. import report_folder
from ..atomic import atomic_path
from ..exits import EXIT_INCOMPLETE, EXIT_OK, EXIT_USAGE
from ..exits import say_error as error
from ..interrupts import GUARD
from ..links.errors import LinkError, PortError
from ..options import UsageError
from ..report_folder import run_folder
from ..transcript import BUS, Event
from .lines import BusLine, LineTracker

if TYPE_CHECKING:
    from rich.console import Console

    from ..links.listen import ListenLink

POLL = 0.05  # s: how often new bytes are taken from the reader and lines shown
FLUSH_EVERY = 1.0  # s: the transcript on disk is at most this far behind the bus
LIVE_ROWS = 40  # lines the live view keeps on screen
ROLES = ("both", "sensor", "recorder")
LISTEN_ONLY = "listen-only: this tool never transmits"


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform monitor",
        description="Listen to a live SDI-12 bus (never transmits), show its traffic line by "
        "line with direction, timing and any rule a line breaks, write transcript.jsonl, "
        "and judge what was seen when it ends (--duration, or SIGTERM). Ctrl-C stops at "
        "once (exit 2) and keeps the transcript unjudged.",
        epilog="examples:\n"
        "  sdi12-conform monitor --port /dev/ttyUSB0\n"
        "  sdi12-conform monitor --port socket://127.0.0.1:4002 --duration 60 --role sensor\n"
        "  sdi12-conform emulate --listen 127.0.0.1:4001 --tap socket://127.0.0.1:4002\n"
        "                                          (an emulated bus with a tap to monitor)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--port",
        required=True,
        help="serial port or pyserial URL: /dev/ttyUSB0, COM3, rfc2217://HOST:PORT, "
        "socket://HOST:PORT, loop://",
    )
    p.add_argument(
        "--role",
        default="both",
        choices=ROLES,
        help="what to judge at the end: sensor rules on what sensors sent, recorder rules on "
        "what the recorder sent, or both (default)",
    )
    p.add_argument("--report-dir", help="where transcript.jsonl and the reports go")
    p.add_argument(
        "--duration",
        type=float,
        metavar="S",
        help="stop after S seconds and judge what was heard (exit 0 if no rule was broken; "
        "default: until SIGTERM)",
    )
    p.add_argument("--address", help="judge only the sensor at this address")
    return p


#: How the monitor has what it heard judged: ``judge(argv, console) -> exit code`` with the
#: ``judge`` subcommand's arguments (the CLI passes its own, so the layers run one way).
Judge = Callable[[list[str], "Console"], int]


def monitor_main(argv: list[str], console: Console, judge: Judge) -> int:
    """Parse ``argv`` (after ``monitor``), monitor until Ctrl-C / ``--duration``, judge."""
    args = build_parser().parse_args(argv)  # SystemExit: the CLI maps it to 0 / 4
    if args.duration is not None and not args.duration > 0:
        error(f"error: --duration must be more than 0 s, not {args.duration:g}")
        return EXIT_USAGE
    try:
        report_dir = run_folder(args.report_dir, "monitor")
        report_dir.mkdir(parents=True, exist_ok=True)
        report_folder.acquire(report_dir)  # no other run writes here while this one listens
    except (OSError, UsageError) as exc:
        error(f"error: cannot use --report-dir {args.report_dir or 'reports/'}: {exc}")
        return EXIT_USAGE
    try:
        return _monitor(args, report_dir, console, judge)
    finally:
        report_folder.release(report_dir)


def _monitor(args: argparse.Namespace, report_dir: Path, console: Console, judge: Judge) -> int:
    from ..links.listen import open_listen_link

    try:
        link = open_listen_link(args.port)
    except PortError as exc:
        error(f"error: {exc}")
        return EXIT_USAGE
    transcript = report_dir / "transcript.jsonl"
    say = _Printer(console)
    say(f"{LISTEN_ONLY} (monitoring {args.port} at 1200 baud 7E1)")
    say("a NUL byte (a framing error) is read as a break; directions are inferred")
    if args.duration:
        say(f"{args.duration:g} s end it and judge what was heard; Ctrl-C stops it at once")
    else:
        say("SIGTERM ends it and judges what was heard; Ctrl-C stops it at once")
    failure, heard, interrupted = _watch(link, transcript, console, args.duration)
    if interrupted:
        say(
            f"stopped: interrupted (Ctrl-C), not judged; transcript written to {transcript} "
            f"(judge it with: sdi12-conform judge {transcript} --role {args.role})"
        )
        return EXIT_INCOMPLETE
    if failure:
        error(f"error: {failure}; what was heard until then is kept")
    if not heard:
        say(
            f"nothing was heard on {args.port}: is it wired to the bus (RX on the data line, "
            "common ground) and is anything talking?"
        )
    say(f"transcript written to {transcript}; judging what was seen (--role {args.role})")
    GUARD.install()  # a Ctrl-C while judging: the judge's partial report and exit 2
    code = judge_recording(transcript, args.role, report_dir, args.address, console, judge)
    if code == EXIT_INCOMPLETE and not GUARD.requested and not failure:
        return heard_as_asked(report_dir, say)
    return code


def judge_recording(
    transcript: Path,
    role: str,
    report_dir: Path,
    address: str | None,
    console: Console,
    judge: Judge,
) -> int:
    """The judging step: ``judge`` on the monitor's transcript (exit code: the judge's)."""
    argv = [str(transcript), "--role", role, "--report-dir", str(report_dir)]
    if address:
        argv += ["--address", address]
    return judge(argv, console)


def heard_as_asked(report_dir: Path, say: Callable[[str], None]) -> int:
    """The exit code of a watch that ended as asked and whose judging left rules open.

    A bus shows only what its recorder and sensors happened to do: rules nothing exercised
    are INCONCLUSIVE, and the judge calls that INCOMPLETE (exit 2, as for an interrupted
    run). The monitoring itself was complete, so when every role's run completed with no
    FAIL and no ERROR the monitor says so and exits 0; the reports keep every INCONCLUSIVE."""
    found = [json.loads(p.read_text(encoding="utf-8")) for p in report_dir.rglob("verdicts.json")]
    if not found:
        return EXIT_INCOMPLETE
    for data in found:
        counts = data["summary"]["counts"]
        if not data["run"]["complete"] or counts.get("FAIL") or counts.get("ERROR"):
            return EXIT_INCOMPLETE
    open_ = sum(d["summary"]["counts"].get("INCONCLUSIVE", 0) for d in found)
    say(
        f"monitoring complete: no FAIL in what was heard; {open_} requirement(s) "
        "INCONCLUSIVE (not seen on this bus or not decidable from it), listed in the report"
    )
    return EXIT_OK


class _Printer:
    """One plain line on the console, flushed (a pipe reader sees it at once)."""

    def __init__(self, console: Console) -> None:
        self.console = console

    def __call__(self, text: str) -> None:
        self.console.print(text, markup=False, highlight=False)
        with contextlib.suppress(Exception):
            self.console.file.flush()


class _Stop:
    """SIGTERM ends the watch (the judging still runs); Ctrl-C ends it as interrupted (the
    transcript is kept whole, nothing is judged, exit 2: Ctrl-C means the same to every
    subcommand)."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.interrupted = False
        self._saved: list[tuple[int, object]] = []

    def __enter__(self) -> _Stop:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._saved.append((sig, signal.signal(sig, self._handle)))
        return self

    def _handle(self, sig: int, _frame: object) -> None:
        self.interrupted = self.interrupted or sig == signal.SIGINT
        self.event.set()

    def __exit__(self, *_exc: object) -> None:
        for sig, handler in self._saved:
            signal.signal(sig, handler)  # type: ignore[arg-type]


def _watch(
    link: ListenLink, path: Path, console: Console, duration: float | None
) -> tuple[str, int, bool]:
    """Show and record the bus until stopped; returns why it failed ("" if it did not), how
    many breaks and characters were heard, and whether Ctrl-C stopped it."""
    tracker = LineTracker(between=link.uncertainty_between)  # the run's measured figure too
    view = _LiveView(console, link.name)
    failure = ""
    link.transcript.note(link.now(), f"monitor: {LISTEN_ONLY}; port {link.name}")
    taken = 0
    with _Stop() as stop, path.open("w", encoding="utf-8") as fh, view:
        started = time.monotonic()
        flushed = started
        while not stop.event.is_set():
            if duration is not None and time.monotonic() - started >= duration:
                break
            try:
                new = link.heard_since(taken)
            except LinkError as exc:
                failure = str(exc)
                break
            taken += len(new)
            _append(fh, new)
            tracker.add(new)
            view.show(tracker.poll(link.now()), tracker, link)
            if time.monotonic() - flushed >= FLUSH_EVERY:
                fh.flush()
                flushed = time.monotonic()
            stop.event.wait(POLL)
        link.close()
        with contextlib.suppress(LinkError):
            rest = link.heard_since(taken)
            _append(fh, rest)
            tracker.add(rest)
        view.show(tracker.poll(link.now(), final=True), tracker, link)
    with atomic_path(path) as whole:  # the whole, in order (the same lines as appended)
        link.transcript.write_jsonl(str(whole))
    return failure, tracker.chars + tracker.breaks, stop.interrupted


def _append(fh: IO[str], events: list[Event]) -> None:
    for e in events:
        fh.write(json.dumps(e.to_json()) + "\n")


class _LiveView:
    """A rich ``Live`` table on a terminal; plain lines anywhere else (CI, a pipe)."""

    def __init__(self, console: Console, port: str) -> None:
        self.console = console
        self.port = port
        self.live_on = console.is_terminal
        self.rows: deque[BusLine] = deque(maxlen=LIVE_ROWS)
        self._live = None
        self._print = _Printer(console)

    def __enter__(self) -> _LiveView:
        if self.live_on:
            from rich.live import Live

            self._live = Live(self._render(None, None), console=self.console, refresh_per_second=8)
            self._live.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._live is not None:
            self._live.__exit__(None, None, None)

    def show(self, lines: list[BusLine], tracker: LineTracker, link: ListenLink) -> None:
        if not self.live_on:
            for line in lines:
                self._print(line.plain())
            return
        self.rows.extend(lines)
        if self._live is not None:
            self._live.update(self._render(tracker, link))

    def _render(self, tracker: LineTracker | None, link: ListenLink | None):
        from rich.table import Table

        table = Table(
            title=f"{LISTEN_ONLY} \u2014 {self.port}, 1200 baud 7E1 (Ctrl-C stops)",
            expand=True,
        )
        for col, kw in (
            ("t (s)", {"justify": "right", "no_wrap": True}),
            ("+ms", {"justify": "right", "no_wrap": True}),
            ("from", {"no_wrap": True}),
            ("traffic", {"overflow": "fold"}),
            ("rules broken", {"overflow": "fold", "style": "red"}),
        ):
            table.add_column(col, **kw)
        for line in self.rows:
            gap = "" if line.gap is None else f"{line.gap * 1e3:.1f}"
            what = "BREAK" if line.kind == "break" else line.text
            flags = "\n".join(str(f) for f in line.flags)
            table.add_row(f"{line.start:.4f}", gap, line.who, what, flags)
        if tracker is not None and link is not None:
            table.caption = (
                f"{link.now():.1f} s: {tracker.chars} characters, {tracker.breaks} breaks, "
                f"{tracker.flagged} lines "
                f"breaking a rule; stamps \u00b1{link.timing_uncertainty() * 1e3:.1f} ms "
                f"(origin {BUS}: direction inferred)"
            )
        return table
