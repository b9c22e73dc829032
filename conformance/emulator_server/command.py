"""``sdi12-conform emulate``: the reference sensor on a real port, in real time.

Serves the same emulator as ``--port sim`` (profile version, address, faults: the parameters
of a ``sim://`` URL) either as an RFC 2217 server on a TCP port, as raw bytes on a TCP port
(what ``socket://`` speaks; no breaks), or on a serial port. A recorder, or this tool with
``--port rfc2217://HOST:PORT``, then talks to it as to a sensor on a bus. With ``--sensors
0,1:FAULT,3`` (the ``sensors=`` of a ``sim://`` URL) several emulators share the one served line
(:mod:`.shared_line`), for ``--address all`` runs over a real-time link. With ``--harness
exec:PROGRAM`` the served sensor is an outside sensor harness instead (:mod:`.harness`): other
people's firmware reached through the bench models, as a bench reaches it.
"""

from __future__ import annotations

import argparse
import signal
import threading
from typing import TYPE_CHECKING

from ..exits import EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE
from ..links.priority import EMULATED_LINE, quick_gil_handover, realtime_priority
from ..ports import PortError, parse_sim, sim_profile
from .bench import BenchModel
from .harness import LineClock, ServedHarness, open_served_harness
from .realtime import RealTimeLine
from .servers import TcpEmulatorServer, serve_serial
from .shared_line import SharedLine
from .tap import TapServer, parse_tap

if TYPE_CHECKING:
    from ..emulator import SensorEmulator

PORT_MAX = 65535


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="sdi12-conform emulate",
        description="Serve the reference SDI-12 sensor emulator, or a sensor harness "
        "(--harness), in real time (1200 baud pacing, section 7 timing) on a TCP port or a "
        "serial port.",
        epilog="examples:\n"
        "  sdi12-conform emulate --listen 127.0.0.1:4001\n"
        "  sdi12-conform --port rfc2217://127.0.0.1:4001     (in another shell)\n"
        "  sdi12-conform emulate --listen 127.0.0.1:4001 --faults no-service-request\n"
        "  sdi12-conform emulate --serial /dev/ttyUSB1 --version 1.3 --address 5\n"
        "  sdi12-conform emulate --listen 127.0.0.1:4001 --sensors 0,1:answers-foreign-reply,3\n"
        "  sdi12-conform --port rfc2217://127.0.0.1:4001 --address all  (a bus of three)\n"
        "  sdi12-conform emulate --listen 127.0.0.1:4001 --harness 'exec:./sensor_harness' "
        "--echo --usb-latency 16",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--listen", metavar="HOST:PORT", help="serve on TCP (port 0: any free)")
    where.add_argument("--serial", metavar="PORT", help="serve on a serial port or pyserial URL")
    p.add_argument(
        "--raw",
        action="store_true",
        help="with --listen: plain bytes (socket://) instead of RFC 2217; carries no breaks",
    )
    p.add_argument(
        "--tap",
        metavar="socket://HOST:PORT",
        help="also serve a listen-only tap of the line (port 0: any free): its clients hear "
        "every character on it, the recorder's and the sensor's, a break as 0x00; what they "
        "send is dropped (for `sdi12-conform monitor`)",
    )
    p.add_argument("--version", dest="sdi_version", default="1.4", help="1.3 or 1.4 (default)")
    p.add_argument("--address", default=None, help="the sensor's address (default 0)")
    p.add_argument(
        "--sensors",
        metavar="A[:FAULT+FAULT],...",
        default=None,
        help="several sensors on the one line, as sim://?sensors= (e.g. 0,1:wrong-crc,3): "
        "each its address, serial number SN0001.. in order, and own faults; --faults and "
        "--version apply to every one (not with --address)",
    )
    p.add_argument("--faults", default="", help="comma-separated fault names (see `faults`)")
    p.add_argument(
        "--harness",
        metavar="exec:PROGRAM|unix:PATH",
        default=None,
        help="serve this sensor harness (docs/harness-protocol.md) instead of the reference "
        "sensor, in real time behind the bench models (not with --version, --address, ...)",
    )
    bench = p.add_argument_group(
        "bench models (what a real interface between recorder and line does; default: none)"
    )
    bench.add_argument(
        "--echo",
        action="store_true",
        help="the recorder hears its own characters at their stop bit, a break as 0x00",
    )
    bench.add_argument(
        "--usb-latency",
        type=float,
        default=0.0,
        metavar="MS",
        help="bytes reach the recorder in batches, at each tick of an MS latency timer (FTDI: 16)",
    )
    bench.add_argument(
        "--jitter",
        type=float,
        default=0.0,
        metavar="MS",
        help="each delivery is delayed a further random 0..MS ms (order kept)",
    )
    bench.add_argument(
        "--require-rts",
        action="store_true",
        help="the recorder's characters reach the line only while it raises RTS, and "
        "the sensor's reply is lost while RTS stays raised",
    )
    bench.add_argument("--seed", type=int, default=1, help="seed of the jitter (default 1)")
    return p


def bench_model(args: argparse.Namespace) -> BenchModel:
    """The bench model the options ask for (raises :class:`PortError` on bad figures)."""
    for name in ("usb_latency", "jitter"):
        value = getattr(args, name)
        if not 0 <= value <= 1000:
            flag = "--" + name.replace("_", "-")
            raise PortError(f"{flag} must be 0..1000 ms, not {value:g}")
    return BenchModel(
        echo=args.echo,
        usb_latency=args.usb_latency / 1e3,
        jitter=args.jitter / 1e3,
        require_rts=args.require_rts,
        seed=args.seed,
    )


def make_device(version: str, address: str, faults: str) -> object:
    """The emulator a ``sim://?version=..&address=..&faults=..`` URL would put on the bus,
    validated the same way (raises :class:`PortError` with the reason)."""
    from urllib.parse import urlencode

    from ..emulator import SensorEmulator

    query = {"version": version, "address": address, "faults": faults}
    spec = parse_sim("sim://?" + urlencode(query))
    return _without_own_breaks([SensorEmulator(sim_profile(spec), spec.faults)])[0]


def make_bus(version: str, sensors: str, faults: str) -> SharedLine:
    """The emulators a ``sim://?sensors=..`` URL would put on the simulated bus, as one device
    of the served line (raises :class:`PortError` with the reason)."""
    from urllib.parse import urlencode

    from ..ports import bus_emulators

    query = {"version": version, "sensors": sensors, "faults": faults}
    return SharedLine(_without_own_breaks(bus_emulators(parse_sim("sim://?" + urlencode(query)))))


def _without_own_breaks(devices: list[SensorEmulator]) -> list[SensorEmulator]:
    """``devices``, or :class:`PortError` naming a fault that breaks before its reply
    (``break-before-reply``): the real-time line sends a device's frames as bytes, and a
    sensor's break (a ``BreakFrame``) would go out as a NUL character; only ``sim`` puts it on
    the line as spacing."""
    from ..emulator import FAULTS

    for device in devices:
        if device.behaviour.break_before_reply:
            named = ", ".join(
                f for f in device.faults.names if FAULTS[f].settings.get("break_before_reply")
            )
            raise PortError(
                f"fault {named}: a sensor's own break is not served on a real-time line "
                "(it would go out as a NUL character); run it on --port sim"
            )
    return devices


def serving_what(
    args: argparse.Namespace, bench: BenchModel, clock: LineClock | None = None
) -> tuple[object, str]:
    """The device the options ask for (one sensor, a :class:`SharedLine` of several, or a
    :class:`ServedHarness` on ``clock``) and the words the server's first line says it with
    (raises :class:`PortError`)."""
    if args.harness is not None:
        return _served_harness(args, bench, clock or LineClock())
    faults = args.faults or "none"
    if args.sensors is not None:
        if args.address is not None:
            raise PortError("--sensors gives every sensor its address: no --address with it")
        bus = make_bus(args.sdi_version, args.sensors, args.faults)
        return bus, (
            f"bus of {len(bus.devices)} reference sensors v{args.sdi_version} "
            f"({args.sensors}), faults on every one: {faults}, bench: {bench.describe()}"
        )
    address = args.address or "0"
    device = make_device(args.sdi_version, address, args.faults)
    return device, (
        f"reference sensor v{args.sdi_version}, address {address}, faults: {faults}, "
        f"bench: {bench.describe()}"
    )


def _served_harness(
    args: argparse.Namespace, bench: BenchModel, clock: LineClock
) -> tuple[ServedHarness, str]:
    """The sensor harness ``--harness`` names, started and greeted (options that shape the
    reference sensor do not apply to it: a usage error, not ignored)."""
    given = [
        flag
        for flag, value in (
            ("--sensors", args.sensors),
            ("--address", args.address),
            ("--faults", args.faults or None),
            ("--version", None if args.sdi_version == "1.4" else args.sdi_version),
        )
        if value is not None
    ]
    if given:
        raise PortError(f"{', '.join(given)} shape the reference sensor: not with --harness")
    device = open_served_harness(args.harness, clock)
    return device, (
        f"sensor harness {device.harness_name!r} ({args.harness}, real-time priority "
        f"{'on' if device.realtime_priority else 'off'}), bench: {bench.describe()}"
    )


def _host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit():
        raise PortError(f"--listen wants HOST:PORT (for example 127.0.0.1:4001), not {text!r}")
    if int(port) > PORT_MAX:
        raise PortError(f"--listen port must be 0..{PORT_MAX} (0: any free), not {port}")
    return host.strip("[]") or "127.0.0.1", int(port)


def _say(message: str) -> None:
    print(message, flush=True)  # a supervising process reads the URL line at once


def emulate_main(argv: list[str], print_line=_say) -> int:
    """Parse ``argv`` (after ``emulate``), serve until Ctrl-C or SIGTERM; exit code."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        return EXIT_OK if exc.code == 0 else EXIT_USAGE
    clock = LineClock()
    try:
        bench = bench_model(args)
        if args.raw and not args.listen:
            raise PortError("--raw applies to --listen only")
        tap_at = parse_tap(args.tap) if args.tap else None
        if args.listen:
            _host_port(args.listen)  # a port out of range is a usage error, before serving
        device, what = serving_what(args, bench, clock)  # last: it may start a harness
    except PortError as exc:
        print_line(f"error: {exc}")
        return EXIT_USAGE
    try:
        return _serve(device, args, what, print_line, bench, tap_at, clock)
    finally:
        if isinstance(device, ServedHarness):
            device.close()


def _serve(
    device: object,
    args: argparse.Namespace,
    what: str,
    print_line,
    bench: BenchModel,
    tap_at: tuple[str, int] | None,
    clock: LineClock,
) -> int:
    """Serve ``device`` as the options ask until stopped; the exit code."""
    # the line's thread must get the interpreter back at once when a frame is due, and no
    # thread of the server may be preempted while it holds the lock the line needs
    quick_gil_handover()  # for the life of the process
    realtime_priority(EMULATED_LINE)
    tap = None
    if tap_at is not None:
        try:
            tap = TapServer(*tap_at, log=print_line).start()
        except OSError as exc:
            print_line(f"error: cannot listen on {args.tap}: {exc}")
            return EXIT_USAGE
    try:
        if args.listen:
            return _serve_tcp(device, args, what, print_line, bench, tap, clock)
        return _serve_port(device, args.serial, what, print_line, tap, clock)
    finally:
        if tap is not None:
            tap.stop()


def _serve_tcp(
    device: object,
    args: argparse.Namespace,
    what: str,
    print_line,
    bench: BenchModel,
    tap: TapServer | None = None,
    clock: LineClock | None = None,
) -> int:
    try:
        host, port = _host_port(args.listen)
        line = RealTimeLine(
            device,  # type: ignore[arg-type]
            lambda _data: None,
            bench=bench,
            clock=clock or LineClock(),
            on_failure=lambda _exc: server.stop(),  # a failed device stops the server
        )
        if tap is not None:
            line.add_tap(tap.send)
        server = TcpEmulatorServer(line, host, port, rfc2217_protocol=not args.raw, log=print_line)
        line.start()
    except (PortError, OSError) as exc:
        print_line(f"error: cannot listen on {args.listen}: {exc}")
        return EXIT_USAGE
    print_line(f"serving the {what} on {server.url} (Ctrl-C stops){_tapped(tap)}")
    _stop_on_sigterm(server.stop)
    code = EXIT_OK
    try:
        server.serve()
    except KeyboardInterrupt:  # Ctrl-C: exit 2, as every subcommand (SIGTERM: 0)
        print_line("stopped: interrupted")
        code = EXIT_INTERRUPTED
    finally:
        line.stop()
    return _failed(line, print_line) or code


def _failed(line: RealTimeLine, print_line) -> int:
    """EXIT_INTERNAL, said, if the line's device failed (a served harness broke the
    protocol, crashed or hung: the server stopped for it); else 0."""
    if not line.errors:
        return 0
    print_line(f"error: the served device failed, the server stopped: {line.errors[0]}")
    return EXIT_INTERNAL


def _serve_port(
    device: object,
    port_name: str,
    what: str,
    print_line,
    tap: TapServer | None = None,
    clock: LineClock | None = None,
) -> int:
    import serial

    try:
        port = serial.serial_for_url(port_name, baudrate=1200, timeout=0.1)
    except (serial.SerialException, OSError, ValueError) as exc:
        print_line(f"error: cannot open {port_name}: {exc}")
        return EXIT_USAGE
    stopped = threading.Event()
    line = RealTimeLine(
        device,  # type: ignore[arg-type]
        port.write,
        deliver_at_end=False,
        clock=clock or LineClock(),
        on_failure=lambda _exc: stopped.set(),
    )
    if tap is not None:
        line.add_tap(tap.send)
    line.start()
    _stop_on_sigterm(stopped.set)
    print_line(f"serving the {what} on {port_name} at 1200 baud (Ctrl-C stops){_tapped(tap)}")
    code = EXIT_OK
    try:
        serve_serial(line, port, stopped)
    except KeyboardInterrupt:  # Ctrl-C: exit 2, as every subcommand (SIGTERM: 0)
        print_line("stopped: interrupted")
        code = EXIT_INTERRUPTED
    except serial.SerialException as exc:
        print_line(f"error: the port failed: {exc}")
    finally:
        line.stop()
        port.close()
    return _failed(line, print_line) or code


def _tapped(tap: TapServer | None) -> str:
    return f"; listen-only tap on {tap.url}" if tap is not None else ""


def _stop_on_sigterm(stop) -> None:
    """A service manager's SIGTERM ends the server like Ctrl-C (main thread only)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, lambda _sig, _frame: stop())
