#!/usr/bin/env python3
"""A recorder harness in Python: recorder logic written against a Link, run by the tool.

    sdi12-conform --role recorder --port 'exec:python examples/python/recorder_harness.py'
    sdi12-conform --role recorder \
        --port 'exec:python examples/python/recorder_harness.py no-retries'
    sdi12-conform --role recorder \
        --port 'exec:python examples/python/recorder_harness.py --cannot addresses,families'

The logic here is sdi12-conform's golden recorder (or, with an argument, one of its faulty
twins); put your own `(request, link) -> RecorderOutput` callable in its place.
`--cannot JOB,...` makes it answer those jobs (scenario names, SDI12_SCENARIO) with
`cannot` instead of doing them, as a logger that lacks what they need would.
`serve_recorder` speaks the protocol of docs/harness-protocol.md on stdin/stdout.
"""

import os
import sys

from conformance.harness.client import serve_recorder
from conformance.recorder.faults import faulty_recorder
from conformance.recorder_jobs import RecorderOutput


def main(args: list[str]) -> int:
    refused: set[str] = set()
    if args[:1] == ["--cannot"]:
        refused = set(args[1].split(",")) if len(args) > 1 else set()
        args = args[2:]
    recorder = faulty_recorder(tuple(args))

    def program(request, link):
        job = os.environ.get("SDI12_SCENARIO", "")
        if job in refused:
            return RecorderOutput(cannot=f"this logger cannot do {job}")
        return recorder(request, link)

    return serve_recorder(program, name="python-golden-recorder")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
