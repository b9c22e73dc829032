"""The rack's ``junit.xml``: one ``<testsuite>`` per DUT, for a CI that shows racks by unit.

Each DUT's suite holds the test cases of its own junit.xml (pytest's rendering of its run),
renamed after the DUT and given the DUT's port, verdict and exit status as properties, plus
one case of the rack's own, ``verdict``, that fails unless the DUT's run exited 0: a DUT
that wrote no junit.xml (its port could not be opened, its worker was lost) still shows as
an error, never as an empty, green suite.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from ..atomic import atomic_path
from ..exits import EXIT_COMPLIANT, EXIT_NON_COMPLIANT

_COUNTS = ("tests", "failures", "errors", "skipped")


def _own_cases(folder: Path | None) -> list[ET.Element]:
    """The test cases of a DUT's junit.xml (none when it has no readable one)."""
    path = folder / "junit.xml" if folder is not None else None
    if path is None or not path.is_file():
        return []
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return []
    return list(root.iter("testcase"))


def _verdict_case(row: dict[str, Any]) -> ET.Element:
    """The rack's case for a DUT: passes only when its run exited 0 (compliant)."""
    case = ET.Element("testcase", classname=f"rack.{row['name']}", name="verdict", time="0")
    code = row["exit_code"]
    if code == EXIT_COMPLIANT:
        return case
    text = f"exit {code} ({row['meaning']}); verdict {row['verdict'] or 'none'}"
    text += "".join(f"; {line}" for line in row["errors"])
    kind = "failure" if code == EXIT_NON_COMPLIANT else "error"
    ET.SubElement(case, kind, message=text[:500]).text = text
    return case


def _suite(row: dict[str, Any], folder: Path | None) -> ET.Element:
    suite = ET.Element("testsuite", name=row["name"])
    props = ET.SubElement(suite, "properties")
    for key in ("port", "role", "verdict", "exit_code", "complete", "serial", "folder"):
        ET.SubElement(props, "property", name=key, value=str(row.get(key)))
    cases = [*_own_cases(folder), _verdict_case(row)]
    suite.extend(cases)
    counts = {
        "tests": len(cases),
        "failures": sum(c.find("failure") is not None for c in cases),
        "errors": sum(c.find("error") is not None for c in cases),
        "skipped": sum(c.find("skipped") is not None for c in cases),
    }
    for key in _COUNTS:
        suite.set(key, str(counts[key]))
    suite.set("time", str(row.get("wall_s") or 0))
    return suite


def write_junit(rows: list[dict[str, Any]], rack_dir: Path) -> Path:
    """``rack_dir/junit.xml`` from the DUTs' rows and their own junit.xml files."""
    root = ET.Element("testsuites", name="sdi12-conform rack")
    for row in rows:
        folder = rack_dir / row["folder"] if row["folder"] else None
        root.append(_suite(row, folder))
    for key in _COUNTS:
        root.set(key, str(sum(int(s.get(key, 0)) for s in root)))
    path = rack_dir / "junit.xml"
    with atomic_path(path) as tmp:
        ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    return path
