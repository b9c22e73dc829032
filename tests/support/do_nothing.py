"""Devices that do nothing, for the "no PASS without evidence" tests (issue 10).

Not test modules themselves: ``test_nothing_to_judge.py`` puts them on the line.
"""

from __future__ import annotations

from conformance.links.base import Link
from conformance.recorder_jobs import RecorderOutput, Request


def idle_recorder() -> object:
    """A recorder program that, whatever it is asked, sends nothing and logs nothing."""

    def program(request: Request, link: Link) -> RecorderOutput:
        return RecorderOutput()

    return program
