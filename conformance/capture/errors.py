"""The one error every capture reader raises for input it cannot use.

A capture comes from outside the project (a logic analyzer, another tool, a user's disk), so a
bad one is a user error, not a bug: the CLI turns :class:`CaptureError` into a one-line message
and exit status 4, never a traceback. The message always names the file and what is wrong with
it, so the user can fix the file or the options without reading code.
"""

from __future__ import annotations


class CaptureError(Exception):
    """``path``: the capture; ``what``: what is wrong with it, in the user's terms."""

    def __init__(self, path: str, what: str) -> None:
        super().__init__(f"{path}: {what}")
        self.path = str(path)
        self.what = what
