"""The exit statuses of every ``sdi12-conform`` subcommand (a contract: CI scripts gate on
them), and the one way a subcommand tells the user about an error."""

from __future__ import annotations

import sys

EXIT_OK = EXIT_COMPLIANT = 0
EXIT_NON_COMPLIANT = 1  # matrix: a fault not caught exactly
EXIT_INCOMPLETE = EXIT_INTERRUPTED = 2  # interrupted, or verdicts left open
EXIT_INTERNAL = 3  # a bug in the tool, or the link failed mid-run
EXIT_USAGE = 4  # an ordinary mistake: bad option, file, port
EXIT_NO_DEVICE = 5  # nothing answered
PYTEST_NO_TESTS = 5  # pytest.ExitCode.NO_TESTS_COLLECTED (so the CLI need not import pytest)


def say_error(text: str) -> None:
    """One line for the user on stderr (never on stdout, where results and pipes go)."""
    from rich.console import Console

    Console(stderr=True, soft_wrap=not sys.stderr.isatty()).print(
        text, style="red", markup=False, highlight=False
    )


def exit_code(document: dict, pytest_code: int) -> int:
    """A run's exit status from its verdicts.json document and pytest's status: the one rule
    every command that runs the suite (the main command, ``judge``, passive judging) gives.

    A run cut short keeps the status that says why (nothing answered, a setup that cannot
    work, Ctrl-C, the link failed); a finished run's status is its verdict's."""
    stopped = (EXIT_NO_DEVICE, EXIT_USAGE, EXIT_INCOMPLETE, EXIT_INTERNAL)
    if pytest_code in stopped and not document["run"]["complete"]:
        return pytest_code
    verdict = document["summary"]["verdict"]
    if verdict == "NON-COMPLIANT":
        return EXIT_NON_COMPLIANT
    if verdict == "COMPLIANT":
        return EXIT_COMPLIANT
    if document["summary"]["counts"].get("ERROR"):
        return EXIT_INTERNAL
    return EXIT_INCOMPLETE
