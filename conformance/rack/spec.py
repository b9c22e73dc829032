"""What a rack holds: its DUTs, from repeated ``--port`` or from a TOML rack file.

A rack file names each DUT's port and, where they differ from the command line's, its role,
address and declaration, a name for its report folder, and the worker it runs on::

    tx = ["popen"]                 # optional: the workers' execnet specs, round robin

    [[dut]]
    name = "bay1"                  # optional: its report folder's name (default 1-<port>)
    port = "rfc2217://127.0.0.1:4001"
    role = "sensor"                # optional: sensor | recorder (default: --role)
    address = "0"                  # optional (default: --address)
    declaration = "bay1.toml"      # optional, relative to the rack file (default: --declaration)
    tx = "ssh=pi@bench2//python=/opt/sdi12/bin/python"   # optional: this DUT's worker

Every mistake in the file (TOML syntax, an unknown key, a wrong type, a missing port, two
DUTs of one name) is one line naming the file and what to fix: a usage error, exit 4, before
any worker starts. A typo silently ignored would change what is judged.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..options import ROLES, UsageError

#: the worker spec used when none is given: a local process (execnet's ``popen``)
LOCAL_TX = "popen"
_DUT_KEYS = {"name", "port", "role", "address", "declaration", "tx"}
_TOP_KEYS = {"dut", "tx"}
#: names inside a rack's folder that are the rack's own files, never a DUT's folder
RESERVED = frozenset({"index.html", "rack.json", "junit.xml", ".sdi12-conform.lock"})
_NAME_OK = re.compile(r"[A-Za-z0-9._-]+")


class RackError(UsageError):
    """A rack that cannot be run as given; the message says what to fix."""


@dataclass(frozen=True)
class Dut:
    """One device under test of a rack and the worker that runs it."""

    name: str  # its report folder's name inside the rack's folder
    port: str
    role: str | None = None  # None: the command line's --role
    address: str | None = None  # None: the command line's --address
    declaration: str | None = None  # None: the command line's --declaration
    tx: str = LOCAL_TX  # the execnet spec of its worker


def expand_tx(specs: Sequence[str]) -> list[str]:
    """``--tx`` as pytest-xdist reads it: ``3*popen`` is three ``popen`` specs."""
    expanded: list[str] = []
    for spec in specs:
        count, star, rest = spec.partition("*")
        if star and count.isdigit():
            expanded.extend([rest] * int(count))
        else:
            expanded.append(spec)
    return expanded


def _check_tx(spec: str, where: str) -> str:
    """A worker spec execnet can parse (``popen``, ``ssh=HOST``, ``socket=HOST:PORT`` with
    ``//key=value`` parts); refused here rather than when its gateway would be made."""
    import execnet

    try:
        parsed = execnet.XSpec(spec)
    except (ValueError, AttributeError, IndexError) as exc:
        raise RackError(f"{where}: {spec!r} is not an execnet spec ({exc})") from None
    if not (parsed.popen or parsed.ssh or parsed.socket or parsed.vagrant_ssh):
        raise RackError(
            f"{where}: {spec!r} names no worker (popen, ssh=HOST, socket=HOST:PORT; "
            "e.g. ssh=pi@bench2//python=/opt/sdi12/bin/python)"
        )
    return spec


def default_name(index: int, port: str) -> str:
    """A DUT's folder name from its place in the rack and its port: ``2-rfc2217-host-4001``."""
    safe = re.sub(r"[^A-Za-z0-9.]+", "-", port.split("?", 1)[0]).strip("-.")
    return f"{index}-{safe[:40] or 'port'}"


def _assign_tx(duts: list[Dut], tx: Sequence[str]) -> list[Dut]:
    """Each DUT without its own ``tx`` gets the next of ``tx`` (round robin), else popen."""
    specs = expand_tx(tx)
    for spec in specs:
        _check_tx(spec, "--tx")
    if not specs:
        return duts
    out = []
    for i, dut in enumerate(duts):
        own = dut.tx if dut.tx != LOCAL_TX else specs[i % len(specs)]
        out.append(Dut(dut.name, dut.port, dut.role, dut.address, dut.declaration, own))
    return out


def _check_names(duts: list[Dut], where: str) -> list[Dut]:
    if not duts:
        raise RackError(f"{where}: no DUT to run")
    seen: set[str] = set()
    for dut in duts:
        if dut.name in RESERVED:
            raise RackError(f"{where}: a DUT may not be named {dut.name!r} (the rack's own file)")
        if dut.name in seen:
            raise RackError(f"{where}: two DUTs are named {dut.name!r}; names must differ")
        seen.add(dut.name)
    return duts


def _check_ports(duts: list[Dut], where: str) -> list[Dut]:
    """One worker per port: two DUTs on one port of one host would fight over it (a sim
    port is a new simulated device each time; a port on two hosts is two ports)."""
    from ..ports import is_sim

    owner: dict[tuple[str, str], str] = {}
    for dut in duts:
        key = (dut.port, dut.tx)
        if key in owner and not is_sim(dut.port):
            raise RackError(
                f"{where}: DUTs {owner[key]!r} and {dut.name!r} both name port {dut.port!r} "
                "on one worker host; one DUT per port"
            )
        owner.setdefault(key, dut.name)
    return duts


def duts_from_ports(ports: Sequence[str], tx: Sequence[str] = ()) -> list[Dut]:
    """The rack ``--port A --port B`` makes: every DUT with the command line's options."""
    duts = [Dut(default_name(i, port), port) for i, port in enumerate(ports, 1)]
    return _check_ports(_assign_tx(_check_names(duts, "--port"), tx), "--port")


def _text(table: dict[str, Any], key: str, where: str) -> str | None:
    value = table.get(key)
    if value is not None and not (isinstance(value, str) and value.strip()):
        raise RackError(f"{where}: {key} must be a non-empty string, not {value!r}")
    return value


def _dut_from_table(table: Any, index: int, folder: Path, where: str) -> Dut:
    """One ``[[dut]]`` table checked: known keys, strings, a port, a usable name."""
    at = f"{where}: dut {index}"
    if not isinstance(table, dict):
        raise RackError(f"{at}: must be a table ([[dut]]), not {table!r}")
    unknown = sorted(set(table) - _DUT_KEYS)
    if unknown:
        raise RackError(f"{at}: unknown key(s) {', '.join(unknown)} "
                        f"(known: {', '.join(sorted(_DUT_KEYS))})")  # fmt: skip
    port = _text(table, "port", at)
    if port is None:
        raise RackError(f'{at}: no port (port = "/dev/ttyUSB0", "rfc2217://HOST:PORT", ...)')
    name = _text(table, "name", at) or default_name(index, port)
    if not _NAME_OK.fullmatch(name) or name.strip(".") == "":
        raise RackError(f"{at}: name {name!r} must be letters, digits, '.', '_' or '-'")
    role = _text(table, "role", at)
    if role is not None and role not in ROLES:
        raise RackError(f"{at}: role must be one of {', '.join(ROLES)}, not {role!r}")
    declaration = _text(table, "declaration", at)
    if declaration is not None:
        declaration = str((folder / declaration).resolve())
    tx = _text(table, "tx", at)
    tx = _check_tx(tx, at) if tx is not None else LOCAL_TX
    return Dut(name, port, role, _text(table, "address", at), declaration, tx)


def load_rack_file(path: str | Path, tx: Sequence[str] = ()) -> list[Dut]:
    """The DUTs a rack file names (see the module's docstring), each mistake a
    :class:`RackError` of one line. ``tx``: the command line's ``--tx``, which replaces
    the file's."""
    where = f"rack file {path}"
    try:
        raw = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise RackError(f"{where}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise RackError(f"{where}: not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise RackError(f"{where}: {exc}") from None
    unknown = sorted(set(raw) - _TOP_KEYS)
    if unknown:
        raise RackError(f"{where}: unknown key(s) {', '.join(unknown)} (known: [[dut]], tx)")
    tables = raw.get("dut", [])
    if not isinstance(tables, list):
        raise RackError(f"{where}: dut must be an array of tables ([[dut]])")
    file_tx = raw.get("tx", [])
    if isinstance(file_tx, str):
        file_tx = [file_tx]
    if not (isinstance(file_tx, list) and all(isinstance(s, str) for s in file_tx)):
        raise RackError(f"{where}: tx must be a string or a list of strings")
    folder = Path(path).resolve().parent
    duts = [_dut_from_table(t, i, folder, where) for i, t in enumerate(tables, 1)]
    return _check_ports(_assign_tx(_check_names(duts, where), list(tx) or file_tx), where)
