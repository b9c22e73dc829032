"""The log file a ``--trigger`` recorder writes: what its logger logged in one scenario.

The trigger driver puts a fresh path in ``SDI12_LOG_FILE`` for each scenario; the logger (or
the trigger script, from the logger's own output) writes there one record per line, in
either of two formats, told apart by the first character of the first record:

- CSV: ``0M!,+22.15,+1013.2,+45.7`` (the command as sent, then the values as logged);
- JSON lines: ``{"command": "0M!", "values": ["+22.15", "+1013.2", 45.7]}`` (numbers are
  kept as written, ``45.70`` stays ``45.70``; other keys, a time stamp say, are ignored).

Blank lines and lines starting with ``#`` are skipped; several records for one command
append, in order. No file means the recorder reported nothing; an empty one, that it logged
nothing. A file that breaks these rules raises :class:`LogFileError` naming the line: the
logged-values judge then says the report could not be read (INCONCLUSIVE), nothing else.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

#: The environment variable naming the file (documented in docs/harness-protocol.md).
LOG_FILE_VARIABLE = "SDI12_LOG_FILE"
#: Largest log file read (one scenario logs a few hundred values at most).
MAX_SIZE = 1 << 20
#: Longest text quoted from a bad line.
QUOTED = 60


class LogFileError(ValueError):
    """The log file cannot be read as CSV or JSON lines; the message names the line."""


def _command(text: object, where: str) -> str:
    if not isinstance(text, str) or len(text) < 2 or not text.endswith("!") or "!" in text[:-1]:
        raise LogFileError(f"{where}: the command {str(text)[:QUOTED]!r} is not wire text like 0M!")
    return text


def _quote(line: str) -> str:
    return repr(line[:QUOTED] + ("..." if len(line) > QUOTED else ""))


def _json_record(line: str, where: str) -> tuple[str, list[str]]:
    try:
        record = json.loads(line, parse_float=str, parse_int=str)
    except ValueError as exc:
        raise LogFileError(f"{where}: not JSON ({exc.args[0]}): {_quote(line)}") from None
    if not isinstance(record, dict) or "command" not in record or "values" not in record:
        raise LogFileError(f"{where}: wants an object with 'command' and 'values': {_quote(line)}")
    values = record["values"]
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values):
        raise LogFileError(f"{where}: 'values' is not a list of numbers or strings: {_quote(line)}")
    return _command(record["command"], where), [v.strip() for v in values]


def _csv_record(line: str, where: str) -> tuple[str, list[str]]:
    try:
        fields = next(csv.reader([line], strict=True))
    except csv.Error as exc:
        raise LogFileError(f"{where}: not CSV ({exc}): {_quote(line)}") from None
    values = [f.strip() for f in fields[1:]]
    if "" in values:
        raise LogFileError(f"{where}: an empty value: {_quote(line)}")
    return _command(fields[0].strip(), where), values


def parse_log(text: str) -> dict[str, list[str]]:
    """The values logged per command in ``text`` (CSV or JSON lines, see the module)."""
    logged: dict[str, list[str]] = {}
    reader = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        where = f"line {number}"
        if reader is None:
            reader = _json_record if line.startswith("{") else _csv_record
        command, values = reader(line, where)
        logged.setdefault(command, []).extend(values)
    return logged


def read_log_file(path: Path) -> dict[str, list[str]] | None:
    """What the logger logged, from the file at ``path``; None if it wrote no file."""
    if not path.exists():
        return None
    if path.stat().st_size > MAX_SIZE:
        raise LogFileError(f"larger than {MAX_SIZE} bytes")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise LogFileError(f"cannot be read as UTF-8 text ({exc})") from None
    return parse_log(text)
