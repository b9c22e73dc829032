"""``sdi12-conform calibrate``: measure the bench before trusting it with verdicts.

A short probe of the link and the sensor on it: a few wake-ups and identifications, the same
probe every real-link run starts with (:meth:`SensorSession.probe_bench`). It says whether the
interface echoes, how breaks are made, what the receive path's latency and jitter are, how late
the reader woke, and for an FTDI adapter what its latency timer is set to (with the fix when it
is the slow default). It then prints the uncertainty a run would use and which section 7 rules
that uncertainty can decide, so a user can improve the bench before a long run.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .exits import EXIT_NO_DEVICE, EXIT_OK, EXIT_USAGE
from .judges.wire import reply_char_pairs
from .links.base import BusEnd
from .links.meter import TimingMeter
from .protocol.timing import (
    BREAK_ALWAYS,
    BREAK_NEVER,
    CHAR_TIME,
    INTER_CHAR_GAP_MAX,
    MARKING_AFTER_BREAK,
    RESPONSE_START_MAX,
    TOLERANCE,
)
from .view.runs import Segment, segments

SYSFS_SERIAL = Path("/sys/bus/usb-serial/devices")


@dataclass(frozen=True)
class Decidable:
    """A section 7 rule and the largest uncertainty (s) at which a compliant device's
    typical value is still decided."""

    rules: str
    what: str
    margin: float
    uart_timed: bool = False  # the margin is on a line state the UART times, if it can
    # what the probe itself measured of this kind: the spans (start, end, s) each such
    # measurement rests on, so the prediction uses the uncertainty the judges would give
    # each one (the run's regular figure, or more where the stamps were irregular near it)
    observed: Callable[[list[Segment]], list[tuple[float, float]]] | None = None


def _reply_starts(segs: list[Segment]) -> list[tuple[float, float]]:
    """The command's last character to the reply's first: what R-7.0-09/-10 rest on."""
    return [(s.command[-1].start, s.reply[0].end) for s in segs if s.reply and s.command]


def _reply_pairs(segs: list[Segment]) -> list[tuple[float, float]]:
    """Consecutive reply characters: what a gap or a character spacing rests on."""
    return [(a.start, b.end) for a, b in reply_char_pairs(segs)]


RULES = (
    Decidable(
        "R-7.0-09/-10",
        "response window, a reply in its middle",
        (RESPONSE_START_MAX - (CHAR_TIME - TOLERANCE)) / 2,
        observed=_reply_starts,
    ),
    Decidable(
        "R-7.0-12/-01",
        "character gap of a back-to-back reply",
        INTER_CHAR_GAP_MAX,
        observed=_reply_pairs,
    ),
    Decidable(
        "R-7.0-05", "8.33 ms marking after a break (probed at 9 ms)", 9e-3 - MARKING_AFTER_BREAK
    ),
    Decidable(
        "R-7.0-03", "5 ms pulse is not a break", BREAK_NEVER - TOLERANCE - 5e-3, uart_timed=True
    ),
    Decidable(
        "R-7.0-04", "12.6 ms break wakes", 12.6e-3 - BREAK_ALWAYS - TOLERANCE, uart_timed=True
    ),
    Decidable(
        "R-4.1-01", "1200 baud ±2 % from character spacing", 0.17e-3 / 2, observed=_reply_pairs
    ),
)


def latency_timer(port: str) -> int | None:
    """An FTDI-style adapter's latency timer (ms) from sysfs, or None where there is none."""
    path = SYSFS_SERIAL / Path(port).name / "latency_timer"
    try:
        return int(path.read_text().strip())
    except (OSError, ValueError):
        return None


def report(
    link: BusEnd, meter: TimingMeter, port: str, uart_timed: bool, length_error: float
) -> list[str]:
    """The lines ``calibrate`` prints (pure: reads what the probe left in the link)."""
    bench = link.describe()
    assert bench is not None, "a link that meters its stamps describes its bench"
    t = bench["timing"]
    lines = [
        f"port {port}: {'the interface echoes the tool' if bench['echo'] else 'no echo'} "
        f"(--echo {bench['echo_mode']}), breaks {bench['breaks']}, "
        f"transmit enable {bench['direction']}",
        f"receive stamps: {'kernel' if t['kernel_stamps'] else 'reader thread'}; reader "
        f"thread real-time: {'yes' if bench['realtime_reader'] else 'no'}; "
        f"worst reader lag {t['reader_lag']['worst_ms']:.2f} ms",
        f"round trip (write to echo): worst {t['round_trip']['worst_ms']:.2f} ms "
        f"({t['round_trip']['samples']} echoes)",
        f"jitter: regular {t['regular_ms']:.2f} ms, worst echo spread "
        f"{t['echo_spread']['worst_ms']:.2f} ms, batches {t['batches']['worst_ms']:.2f} ms, "
        f"artefacts {t['artefacts']['worst_ms']:.2f} ms "
        f"({t['local_irregularities']} local irregularities)",
    ]
    if bench["echo_collisions"] or bench["echo_missing"]:
        lines.append(
            f"echo problems: {bench['echo_collisions']} collisions, "
            f"{bench['echo_missing']} echoes not heard"
        )
    timer = latency_timer(port)
    if timer is not None:
        lines.append(f"USB adapter latency timer: {timer} ms")
        if timer > 1:
            name = Path(port).name
            lines.append(
                f"  fix: echo 1 | sudo tee {SYSFS_SERIAL}/{name}/latency_timer "
                "(bytes then reach the host within 1 ms instead of up to "
                f"{timer} ms)"
            )
    lines.append(f"a run here would use: {meter.summary()}")
    segs = segments(link.transcript.events)
    for rule in RULES:
        lines.append(_prediction(rule, meter, segs, uart_timed, length_error))
    return lines


def _prediction(
    rule: Decidable, meter: TimingMeter, segs: list[Segment], uart_timed: bool, length: float
) -> str:
    """One rule's line: decided, partly decided or INCONCLUSIVE, and the uncertainty it has.

    Where the probe measured this kind of interval, each measurement gets the uncertainty the
    judges would give it (:meth:`TimingMeter.between`): a link that batches bytes shows a
    small regular figure between its batches and a large one inside them, and only the
    probe's own measurements tell how often a run would meet which."""
    head = f"  {rule.rules:<13} "
    needs = f"{rule.what}: needs < ±{rule.margin * 1e3:.2f} ms"
    if rule.uart_timed and uart_timed:
        verdict = "decided" if length < rule.margin else "INCONCLUSIVE"
        return f"{head}{verdict:<12} {needs}, has ±{length * 1e3:.2f} ms (UART-timed)"
    spans = rule.observed(segs) if rule.observed else []
    if not spans:
        u = meter.uncertainty()
        verdict = "decided" if u < rule.margin else "INCONCLUSIVE"
        return f"{head}{verdict:<12} {needs}, has ±{u * 1e3:.2f} ms"
    errors = sorted(meter.between(start, end) for start, end in spans)
    decided = sum(1 for e in errors if e < rule.margin)
    if decided == len(errors):
        verdict = "decided"
    elif decided:
        verdict = "partly"
    else:
        verdict = "INCONCLUSIVE"
    typical, worst = errors[len(errors) // 2], errors[-1]
    return (
        f"{head}{verdict:<12} {needs}, has ±{typical * 1e3:.2f} ms typically, "
        f"±{worst * 1e3:.2f} ms at worst ({decided} of {len(errors)} measured in the probe "
        "decidable)"
    )


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform calibrate",
        description="Probe the bench (interface, link, sensor) and print the timing uncertainty "
        "a run would use and which section 7 rules it can decide.",
    )
    p.add_argument("--port", required=True, help="serial port or pyserial URL (not sim)")
    p.add_argument("--address", help="the sensor's address (default: ask with ?!)")
    from .options import add_cli_options

    add_cli_options(p, ("echo", "direction"))  # the main command's, help text and all
    p.add_argument("--rounds", type=int, default=10, help="wake-ups to time (default 10)")
    return p


def calibrate_main(argv: list[str], say: Callable[[str], None] = print) -> int:
    from .ports import PortError, is_sim, open_port
    from .protocol.commands import ADDRESS_CHARS
    from .sensor.session import NoDeviceAnswered, SensorSession

    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        return EXIT_OK if exc.code == 0 else EXIT_USAGE
    if is_sim(args.port):
        say("error: the simulated bus has a virtual clock: its timing is exact, nothing to measure")
        return EXIT_USAGE
    if args.address is not None and (len(args.address) != 1 or args.address not in ADDRESS_CHARS):
        say(f"error: --address must be one of 0-9, A-Z, a-z, not {args.address!r}")
        return EXIT_USAGE
    if not 1 <= args.rounds <= 1000:
        say(f"error: --rounds must be 1..1000, not {args.rounds}")
        return EXIT_USAGE
    try:
        opened = open_port(args.port, echo=args.echo, direction=args.direction)
    except PortError as exc:
        say(f"error: {exc}")
        return EXIT_USAGE
    link = opened.link
    try:
        session = SensorSession(link, address=args.address)
        session.discover()  # a real link: this already runs the start-of-run probe
        session.probe_bench(args.rounds)
        for _ in range(3):
            session.fresh_exchange("I")
        # a break as the timing cases make it (UART-timed where the link can), then a!
        session.probe(f"{session.address}!", break_s=13e-3, marking_s=9e-3, idle_before=0.15)
        meter = link.meter
        if meter is None:
            say(f"port {args.port}: a {link.info.kind} link measures nothing of its own timing")
            return EXIT_OK
        breaks = [e for e in link.transcript.events if e.kind == "break"]
        uart = [e for e in breaks if e.duration_uncertainty is not None]
        length_error = max((e.length_uncertainty for e in uart), default=meter.uncertainty())
        say(f"sensor at address {session.address!r} answered; {len(breaks)} breaks sent")
        for line in report(link, meter, args.port, bool(uart), length_error):
            say(line)
        return EXIT_OK
    except NoDeviceAnswered as exc:
        say(f"error: {exc}")
        return EXIT_NO_DEVICE
    finally:
        link.close()
