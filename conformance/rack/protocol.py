"""What the rack and its workers say to each other over a worker's execnet channel: the rack
sends one job and, on Ctrl-C, :data:`STOP`; the worker sends one result, in which the DUT's
verdicts come as :func:`slim_document` cuts them. Imported on both sides (the worker's side
may be another host's Python): the standard library only."""

from __future__ import annotations

from typing import Any

#: the message the rack sends a worker to stop its run (its Ctrl-C)
STOP = "stop"


def slim_document(document: dict[str, Any] | None) -> dict[str, Any] | None:
    """What the rack's summary reads of a DUT's verdicts.json (its full file stays in its
    folder): the summary, the run's completeness, the DUT's identity and the requirements it
    FAILed (what a production line's operator needs to see in the rack's row)."""
    if document is None:
        return None
    run = document["run"]
    keep = ("started", "finished", "complete", "stop_reason", "partial", "selection", "port")
    return {
        "summary": document["summary"],
        "run": {key: run.get(key) for key in keep},
        "dut": document["dut"],
        "failed": [
            r["id"]
            for r in document.get("requirements", [])
            if r.get("verdict") == "FAIL" and r.get("selected", True)
        ],
    }
