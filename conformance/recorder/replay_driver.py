"""A recorded recorder: the device under test of a saved recorder-role run, played back.

In the recorder role the tool plays the sensors and the recorder under test acts. Judging a
saved recorder-role run again replays, scenario by scenario, what the recorder sent (each
scenario's slice is found by name, so the order the cases ask in does not matter) while the
tool plays its sensors live, as it did. The recorder's own account of a scenario (values it
logged, replies it relayed, or the driver's failure) is read from the note the session wrote
after the scenario (:data:`OUTPUT_NOTE`).
"""

from __future__ import annotations

import bisect
import json
from typing import Any

from ..links.base import Link
from ..recorder_jobs import RecorderOutput, Request
from ..replay.sensor import ReplayDiverged
from ..sim.bus import SimLink
from ..transcript import TOOL, Event, EventKind
from .errors import RecorderDriverError
from .job_time import JobBudget, JobTimeout

#: Prefix of the scenario-start note (written by the recorder session).
SCENARIO_NOTE = "scenario "
#: Prefix of the note holding the recorder's account of a scenario (JSON).
OUTPUT_NOTE = "recorder-output "


def output_note(
    name: str, output: RecorderOutput, error: str | None, cut: JobTimeout | None = None
) -> str:
    """The note text a recorder session writes after scenario ``name`` (``cut``: the job
    ran out of its budget, :mod:`conformance.recorder.job_time`)."""
    found: dict[str, Any] = {
        "scenario": name,
        "logged": output.logged,
        "relayed": output.relayed,
        "notes": output.notes,
        "error": error,
    }
    if cut is not None:
        found["timed_out"] = {"seconds": cut.budget, "reason": cut.reason}
    if output.stderr:
        found["stderr"] = output.stderr
    if output.cannot is not None:
        found["cannot"] = output.cannot
    if output.log_source is not None or output.log_problem is not None:
        found["log_source"] = output.log_source
        found["log_problem"] = output.log_problem
    return OUTPUT_NOTE + json.dumps(found)


class RecordedRecorder:
    """A recorder driver that acts by replaying a recording's recorder transmissions."""

    kind = "recording"
    needs_real_time = False

    def __init__(self, events: list[Event]) -> None:
        # per scenario: when it began, what the recorder sent, its account, when it was done
        self.slices: dict[str, tuple[float, list[Event], dict[str, Any] | None]] = {}
        self.done: dict[str, float] = {}
        begins: list[tuple[float, str]] = []
        for e in events:
            if e.kind is not EventKind.NOTE:
                continue
            if e.text.startswith(SCENARIO_NOTE) and ":" in e.text:
                # "scenario NAME: ..." starts one ("scenario NAME done; ..." ends it)
                name = e.text[len(SCENARIO_NOTE) :].split(":", 1)[0].split(" ", 1)[0]
                begins.append((e.start, name))
                self.slices[name] = (e.start, [], None)
            elif e.text.startswith(OUTPUT_NOTE):
                found = json.loads(e.text[len(OUTPUT_NOTE) :])
                name = found.get("scenario")
                if name in self.slices:
                    begun, sent, _ = self.slices[name]
                    self.slices[name] = (begun, sent, found)
                    self.done[name] = e.start
        # a decoded capture stamps a scenario's first break within a sample of its note, on
        # either side: an event belongs to the scenario begun by then, give or take that
        slack = 2 * max((e.uncertainty for e in events), default=0.0) + 1e-6
        starts = [t for t, _ in begins]
        for e in events:
            if e.kind is EventKind.NOTE or e.origin != TOOL:
                continue
            i = bisect.bisect_right(starts, e.start + slack) - 1
            if i >= 0:
                self.slices[begins[i][1]][1].append(e)

    def act(
        self, scenario: str, request: Request, link: Link, budget: JobBudget | None = None
    ) -> RecorderOutput:
        if scenario not in self.slices:
            raise ReplayDiverged(
                f"the recording has no scenario {scenario!r} (it has: "
                f"{', '.join(self.slices) or 'none'})"
            )
        if not isinstance(link, SimLink):
            raise ReplayDiverged("a recorded recorder replays on the simulated bus only")
        begun, sent, account = self.slices[scenario]
        offset = link.now() - begun
        for e in sent:
            link.wait_until(e.start + offset)
            if e.kind is EventKind.BREAK:
                # where it was sent, even over a sensor's character still coming
                link.bus.tool_break(e.end - e.start, e.start + offset)
            else:
                link.bus.tool_char(e.wire, e.start + offset, e.end - e.start)
        if scenario in self.done:  # the recorder was busy (listening) until then
            link.wait_until(self.done[scenario] + offset)
        if account is None:
            return RecorderOutput()
        if account.get("timed_out"):
            cut = account["timed_out"]
            raise JobTimeout(float(cut["seconds"]), str(cut["reason"]))
        if account.get("error"):
            raise RecorderDriverError(str(account["error"]))
        return RecorderOutput(
            logged={k: list(v) for k, v in (account.get("logged") or {}).items()},
            relayed=dict(account.get("relayed") or {}),
            notes=list(account.get("notes") or []),
            log_source=account.get("log_source"),
            cannot=account.get("cannot"),
            log_problem=account.get("log_problem"),
            stderr=account.get("stderr"),
        )
