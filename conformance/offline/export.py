"""``sdi12-conform export RUN --to vcd|sr|csv``: any saved run as a logic-analyzer capture.

So that a simulated run can be opened in PulseView or Logic 2 next to a real one, and so that a
capture of a known run exists to test the capture path with (export, then ``judge``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import atomic_path
from ..capture import (
    DEFAULT_SAMPLE_RATE,
    EXPORT_FORMATS,
    CaptureError,
    ExportInfo,
    export_events,
)
from ..exits import EXIT_OK, EXIT_USAGE, say_error
from ..replay.recording import RecordingError, read_recording, transcript_path
from ..transcript import EventKind


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="sdi12-conform export",
        description="Write a saved run's transcript as a logic-analyzer capture.",
        epilog="examples:\n"
        "  sdi12-conform export reports/20250101-120000-sensor --to sr\n"
        "                       capture.sr beside the run's transcript, for PulseView\n"
        "  sdi12-conform export reports/20250101-120000-sensor --to csv -o run.csv\n"
        "                       a Logic 2-style CSV\n"
        "  sdi12-conform export RUN --to vcd --line-polarity --tool-channel\n"
        "                       the wire's levels, and the tool's TX on its own channel\n"
        "  sdi12-conform judge reports/20250101-120000-sensor/capture.sr\n"
        "                       judge the capture: the run's verdicts again\n"
        "\nCtrl-C leaves no partial file: the capture is written under a temporary name "
        "and renamed when whole.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("run", help="a run folder or its transcript.jsonl")
    parser.add_argument("--to", choices=EXPORT_FORMATS, required=True, help="capture format")
    parser.add_argument(
        "-o", "--output", help="file to write (default: capture.<format> beside the transcript)"
    )
    parser.add_argument(
        "--sample-rate",
        type=float,
        default=DEFAULT_SAMPLE_RATE,
        help=f"samples per second (default {DEFAULT_SAMPLE_RATE:g}: 10 us, 1/40 of the "
        "0.40 ms tolerance of the section 7 limits)",
    )
    parser.add_argument(
        "--line-polarity",
        action="store_true",
        help="levels of the SDI-12 wire itself (marking low) instead of the UART side",
    )
    parser.add_argument(
        "--tool-channel",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="a second channel TOOL_TX holding only the tool's transmissions, like a TX "
        "probe beside the bus (default on: `judge` then knows who sent every character and "
        "gives the run's verdicts back; --no-tool-channel writes the bus alone)",
    )
    return parser


def export_main(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    try:
        recording = read_recording(args.run)
    except RecordingError as exc:
        say_error(f"error: {exc}")
        return EXIT_USAGE
    output = Path(args.output or transcript_path(Path(args.run)).with_name(f"capture.{args.to}"))
    try:
        with atomic_path(output) as partial:  # a Ctrl-C leaves no truncated capture
            info = export_events(
                recording.events,
                str(partial),
                args.to,
                sample_rate=args.sample_rate,
                line_polarity=args.line_polarity,
                tool_channel=args.tool_channel,
                notes=[e for e in recording.events if e.kind is EventKind.NOTE],
            )
    except (ValueError, CaptureError, OSError) as exc:
        say_error(f"error: {output}: {exc}")
        return EXIT_USAGE
    print(f"wrote {output} ({describe(info)})")
    return EXIT_OK


def describe(info: ExportInfo) -> str:
    """One line about what was written."""
    span = info.samples / info.sample_rate
    return (
        f"{info.fmt}, {len(info.channels)} channel(s) {', '.join(info.channels)}, "
        f"{info.sample_rate:g} samples/s, {span:.1f} s; "
        + ("line polarity" if info.line_polarity else "UART polarity (marking high)")
        + (f"; capture time 0 = transcript time {info.t0:.3f} s" if info.t0 else "")
    )
