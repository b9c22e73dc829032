"""What the sensor pass of a capture holds (issue 22: memory21's and memory22's method): the
first sensor's :func:`~conformance.offline.sensor_windows.sensor_records` under tracemalloc,
its peak and what it keeps (its records) over what was held before it, and the timing
folds' sizes when their findings are asked (observations, distinct objects, traced bytes).

    MALLOC_ARENA_MAX=1 python benchmarks/sensor_pass_memory.py CAPTURE.sr

Run it with ``PYTHONPATH`` a checkout to measure that checkout's pass (side by side: one
process each). The peak less what is kept is the pass's transient (its folds and one
window's view): memory24 made the folds' share of it flat in the capture's length.
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
from typing import Any


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("capture", help="a sigrok capture (.sr)")
    args = p.parse_args(argv)
    from conformance.judges import wire
    from conformance.offline import sensor_windows
    from conformance.offline.fixtures import recording_of
    from conformance.offline.heard import bus_of, bus_sensors

    link = recording_of(f"recording:{args.capture}?format=sr")
    bus = bus_of(link)
    address = bus_sensors(link)[0].address
    seen: dict[str, Any] = {}
    gaps_findings, starts_findings = wire.ReplyGaps.findings, wire.ResponseStarts.findings

    def gaps(self: wire.ReplyGaps) -> list:
        held = self._alike.observed if self._alike is not None else self._each
        seen["gaps"] = (len(held), len(getattr(held, "distinct", ())), traced() - seen["at"])
        return gaps_findings(self)

    def starts(self: wire.ResponseStarts) -> list:
        held = self.early.observed()
        seen["starts"] = (len(held), len(getattr(held, "distinct", ())), traced() - seen["at"])
        return starts_findings(self)

    def traced() -> int:
        return tracemalloc.get_traced_memory()[0]

    wire.ReplyGaps.findings, wire.ResponseStarts.findings = gaps, starts  # type: ignore[method-assign]
    tracemalloc.start()
    seen["at"] = before = traced()
    tracemalloc.reset_peak()
    cpu = time.process_time()
    records = sensor_windows.sensor_records(link, bus, address)
    cpu = time.process_time() - cpu
    now, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(
        f"sensor {address}: {len(records.exchanges)} exchanges, peak +{(peak - before) / 1e6:.3f}"
        f" MB, kept {(now - before) / 1e6:.3f} MB, transient {(peak - now) / 1e6:.3f} MB; "
        "(observations, distinct, traced bytes) at the findings: reply starts "
        f"{seen['starts']}, gaps {seen['gaps']}; {cpu:.2f} s CPU traced"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
