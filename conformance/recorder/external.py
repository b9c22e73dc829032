"""The golden recorder as a separate process, for ``--trigger`` over ``rfc2217-serve://``.

``sdi12-conform --port rfc2217-serve://127.0.0.1:0 --role recorder --trigger 'python -m
conformance.recorder.external'`` runs one such process per scenario: it reads the request
from the ``SDI12_*`` environment the trigger driver sets, connects to ``SDI12_PORT`` over
RFC 2217 as any external logger would, does the job with the golden recorder (or the faulty
twin named by ``SDI12_RECORDER_FAULT``), and writes what it logged to ``SDI12_LOG_FILE``
(JSON lines) and stdout. It proves the trigger path end to end with a recorder that lives
outside the judging process (its own GIL and clock), as the golden recorder of issue 6 is
meant to be run.
"""

from __future__ import annotations

import json
import os
import sys

from ..links.echo import EchoMode
from ..links.factory import open_real_link
from .faults import faulty_recorder
from .logfile import LOG_FILE_VARIABLE
from .scenarios import SCENARIOS


def main(environ: dict[str, str] | None = None) -> int:
    env = os.environ if environ is None else environ
    port, scenario = env.get("SDI12_PORT"), env.get("SDI12_SCENARIO")
    if not port or scenario not in SCENARIOS:
        print("needs SDI12_PORT and a known SDI12_SCENARIO (set by --trigger)", file=sys.stderr)
        return 2
    fault = env.get("SDI12_RECORDER_FAULT", "")
    program = faulty_recorder((fault,) if fault else ())
    link = open_real_link(port, echo=EchoMode.OFF)  # the served line of played sensors
    try:
        output = program(SCENARIOS[scenario].request, link)
    finally:
        link.close()
    log_file = env.get(LOG_FILE_VARIABLE)
    if log_file:  # what it logged, as JSON lines (docs/harness-protocol.md)
        with open(log_file, "w", encoding="utf-8") as f:
            for command, values in output.logged.items():
                f.write(json.dumps({"command": command, "values": values}) + "\n")
    for command, values in output.logged.items():
        print(f"logged {command} {' '.join(values)}")
    for command, reply in output.relayed.items():
        print(f"relayed {command} {reply!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
