"""What the recorder pass of a capture holds (issue 22, memory26): the recorder's
:func:`~conformance.offline.recorder_windows.recorder_findings` under tracemalloc, the bus
pass made before it (the loaded state's), its peak, what it keeps (the findings) and what
the folds hold when their findings are first asked (after every window's ``add``), with
the lines holding most of that.

    MALLOC_ARENA_MAX=1 python benchmarks/recorder_pass_memory.py CAPTURE.sr [--top 5]

Run it with ``PYTHONPATH`` a checkout to measure that checkout's pass (side by side: one
process each), as ``sensor_pass_memory.py`` measures the sensor pass.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
import tracemalloc
from typing import Any


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("capture", help="a sigrok capture (.sr)")
    p.add_argument("--top", type=int, default=5, help="lines shown of the folds' holdings")
    args = p.parse_args(argv)
    from conformance.offline import recorder_windows
    from conformance.offline.fixtures import recording_of
    from conformance.offline.sensor_windows import bus_windows

    link = recording_of(f"recording:{args.capture}?format=sr")
    bus_windows(link)
    gc.collect()
    seen: dict[str, Any] = {}
    findings = recorder_windows.Breaks.findings

    def first_findings(self: recorder_windows.Breaks) -> list:
        # the first fold asked (judge_views asks Breaks first): every add is done
        seen["folded"] = tracemalloc.get_traced_memory()[0]
        seen["snapshot"] = tracemalloc.take_snapshot()
        return findings(self)

    recorder_windows.Breaks.findings = first_findings  # type: ignore[method-assign]
    tracemalloc.start()
    start = tracemalloc.take_snapshot()
    before = tracemalloc.get_traced_memory()[0]
    tracemalloc.reset_peak()
    cpu = time.process_time()
    found = recorder_windows.recorder_findings(link)
    cpu = time.process_time() - cpu
    now, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    # a checkout before memory27 keeps the measurements themselves, one after counts them
    measured = getattr(found, "measured", None)
    if measured is None:
        measured = len(found.measurements)
    print(
        f"recorder pass: {found.windows} windows, {measured} measurements, peak "
        f"+{(peak - before) / 1e6:.3f} MB, kept {(now - before) / 1e6:.3f} MB, folds at their "
        f"findings +{(seen['folded'] - before) / 1e6:.3f} MB; {cpu:.2f} s CPU traced"
    )
    for stat in seen["snapshot"].compare_to(start, "lineno")[: args.top]:
        print(f"  {stat}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
