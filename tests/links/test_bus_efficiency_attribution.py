"""``benchmarks/bus_efficiency.py --attribute``: where a kept run's wall beyond its bus-time
lower bound went, by cause, from its transcript alone."""

from __future__ import annotations

import re

from conformance.links.bus_time import bus_time, uncounted
from conformance.protocol.timing import RELEASE_LINE, RETRY_MIN
from conformance.transcript import DUT, TOOL
from tests.links.test_bus_time import Wire
from tests.support.paths import benchmark


def bench_module():
    return benchmark("bus_efficiency")


def test_each_uncounted_stretch_goes_to_the_cause_the_wire_shows():
    w = Wire().brk().pause(9e-3).send(TOOL, "9I!").pause(0.2)  # silence probe: no answer
    w.brk().pause(9e-3).send(TOOL, "0!").pause(9e-3).send(DUT, "0\r\n").pause(14e-3)
    w.send(TOOL, "0I!").pause(9e-3).send(DUT, "013X\r\n").pause(0.3)  # idle marking
    w.brk().pause(9e-3).send(TOOL, "0!")
    table = bench_module().attribution(w.events)
    lines = table.splitlines()
    figures = bus_time(w.events)
    assert lines[0].startswith(f"lower bound {figures.lower_bound:.1f} s")
    rows = {m[3]: (float(m[1]), int(m[2]), m[4]) for m in map(ROW.match, lines[2:]) if m}
    assert len(rows) == len(lines) - 2
    seconds, count, longest = rows["listening after an unanswered command (probes for silence)"]
    assert (round(seconds, 2), count) == (round(0.2 - RETRY_MIN, 2), 1)
    assert longest == "9I! 183 ms"
    seconds, count, longest = rows["listening after the DUT's last character (waits, idle marking)"]
    assert (round(seconds, 2), count) == (round(0.3 - RELEASE_LINE, 2), 1)
    assert longest.startswith("0I! 29")
    seconds, count, longest = rows["turnaround and look before transmitting after the DUT"]
    assert count == 1 and seconds == round(14e-3 - RELEASE_LINE, 2)
    # every uncounted stretch is in exactly one row
    assert sum(count for _, count, _ in rows.values()) == len(uncounted(w.events))


ROW = re.compile(r"^\s*([\d.]+)\s+(\d+)  (.*) \((.*)\)$")


def _link(reference: str) -> dict:
    part = {"worst_ms": 0.0, "samples": 0, "where": ""}
    return {
        "timing_uncertainty_ms": 5.0,
        "bench": {
            "timing": {
                "reference": reference,
                "regular_ms": 0.25 if reference == "echo" else 0.0,
                "batches": {**part, "worst_ms": 8.22, "samples": 8},
                "artefacts": {**part, "worst_ms": 10.481, "samples": 14301},
                "local_irregularities": 717,
            }
        },
    }


def test_the_look_is_shown_beside_the_lateness_the_run_saw():
    """The look before transmitting is the declared figure; the run's own lower bounds of
    its characters' lateness stand beside it (issue 22, sixth round: a local RFC 2217
    emulator on a loaded machine showed an 8.2 ms batch and 10.5 ms of overlap)."""
    text = bench_module().look_figures(_link("write"))
    assert text.startswith("look before transmitting: 5.0 ms declared")
    assert "write time (no echo)" in text
    assert "batches worst 8.22 ms (8), overlapping frames worst 10.481 ms" in text
    assert text.endswith("717 local irregularities")
    assert "echo of its commands, regular figure 0.25 ms" in bench_module().look_figures(
        _link("echo")
    )
    assert bench_module().look_figures({"timing_uncertainty_ms": 1.0}) == (
        "look before transmitting: 1.0 ms declared (no bench figures)"
    )
