"""The suite's own abort cases, as they run, leave their waits for the aborted data counted
in the bus-time lower bound: the bound's rule (``links/bus_time.py``) must match what the
cases send, or a change to a case (a poke between the abort and ``aD0!``) would quietly make
their ttt the tool's overhead again."""

from __future__ import annotations

from pathlib import Path

from conformance.capture.transcript_io import read_transcript_jsonl
from conformance.conduct import run_into
from conformance.links.bus_time import bus_time, uncounted

ABORT_CASES = "test_own_command_aborts_concurrent or test_break_aborts_measurement"


def test_the_abort_cases_waits_for_the_aborted_data_are_bus_time(tmp_path: Path):
    data = run_into(tmp_path, "sim", keyword=ABORT_CASES)
    events = read_transcript_jsonl(str(tmp_path / "transcript.jsonl"))
    figures = bus_time(events)
    assert data["run"]["bus"]["bus_lower_bound_s"] == round(figures.lower_bound, 3)
    # both cases ran: an aI! abort and a break abort, each waited out before aD0!
    sent = {s["command"] for t in data["tests"] for s in t.get("sent", [])}
    assert {"0I!", "0D0!"} <= sent, sent
    # what stays uncounted is the tool's margin and grace past ttt, never a ttt itself
    longest = max(end - start for start, end in uncounted(events))
    assert longest < 0.6, longest  # the 0.5 s late-service-request grace after aM!'s abort
    assert figures.lower_bound > 0.9 * figures.span
