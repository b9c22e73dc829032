#!/usr/bin/env python3
"""A recorder harness in Python: recorder logic written against a Link, run by the tool.

    sdi12-conform --role recorder --port 'exec:python examples/python/recorder_harness.py'
    sdi12-conform --role recorder \
        --port 'exec:python examples/python/recorder_harness.py no-retries'

The logic here is sdi12-conform's golden recorder (or, with an argument, one of its faulty
twins); put your own `(request, link) -> RecorderOutput` callable in its place.
`serve_recorder` speaks the protocol of docs/harness-protocol.md on stdin/stdout.
"""

import sys

from conformance.harness.client import serve_recorder
from conformance.recorder.faults import faulty_recorder

if __name__ == "__main__":
    sys.exit(serve_recorder(faulty_recorder(tuple(sys.argv[1:])), name="python-golden-recorder"))
