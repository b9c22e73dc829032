#!/usr/bin/env python3
"""A sensor harness in Python: a sensor state machine behind the harness line protocol.

    sdi12-conform --port 'exec:python examples/python/sensor_harness.py'
    sdi12-conform --port 'exec:python examples/python/sensor_harness.py no-service-request'

The state machine here is sdi12-conform's own reference sensor (any object with the same four
methods will do: your firmware's logic, ported or wrapped). Everything else is the protocol of
docs/harness-protocol.md, spelled out without helpers so it can be copied to another language:
read a line, tell the sensor what happened on the line, answer with what it will send next.
Optional arguments name faults of the reference sensor, to see the tool catch them.
"""

import sys

from conformance.emulator import SensorEmulator, default_profile


def plan(sensor: SensorEmulator) -> str:
    """The answer to every message: the next character the sensor will send, or idle. A
    start already past (the sensor was interrupted mid-reply) means: as soon as possible."""
    frame = sensor.next_frame()
    if frame is None:
        return "idle"
    return f"tx {round(frame.start * 1e6)} {frame.wire:02x}"


def main() -> int:
    sensor = SensorEmulator(default_profile(), faults=sys.argv[1:])
    for line in sys.stdin:
        word, *fields = line.split()
        if word == "hello":
            answer = "hello 1 python-example-sensor"
        elif word == "bye":
            return 0
        else:
            times = [int(f) for f in fields[:2]]
            if word == "break":
                sensor.on_break(times[0] / 1e6, times[1] / 1e6)
            elif word == "char":
                sensor.on_char(int(fields[2], 16), times[0] / 1e6, times[1] / 1e6)
            elif word == "sent":
                sensor.pop_frame()  # our character is on the wire; plan the next one
            answer = plan(sensor)
        print(answer, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
