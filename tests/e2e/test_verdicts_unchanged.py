"""A run's verdicts do not move when its judging is made cheaper (issue 22).

The golden files in ``tests/golden/`` hold, for the clean simulated sensor and a few faults
(a CRC fault, a late response, a character-gap fault, a parity fault), every requirement's
verdict and each of its findings' verdict, detail text, evidence, figures and wire reference,
as the judges gave them before the speed-up (run metadata left out: times, durations, the
report folder). A change meant to alter verdicts regenerates them
(``python -m tests.e2e.test_verdicts_unchanged``) and says so; a speed-up never does.
"""

from __future__ import annotations

import json
import subprocess
import sys
from typing import Any

import pytest

from tests.support.paths import TESTS

GOLDEN = TESTS / "golden"
#: golden name -> the sim port of its run; the fault matrix's run of each fault is the same
RUNS = {
    "clean": "sim",
    "inter-char-gap-tolerance": "sim://?faults=inter-char-gap-tolerance",
    "wrong-crc": "sim://?faults=wrong-crc",
    "response-too-late": "sim://?faults=response-too-late",
    "parity-error": "sim://?faults=parity-error",
}
#: the runs the fast default selection keeps (the others are marked slow)
FAST = {"clean", "inter-char-gap-tolerance"}
FINDING_KEYS = (
    "test", "verdict", "detail", "measured_ms", "limit_ms", "uncertainty_ms", "evidence",
    "decision", "observed", "consequence_of", "wire",
)  # fmt: skip


def digest(data: dict[str, Any]) -> dict[str, Any]:
    """What of a verdicts.json must not change: the summary, every requirement's verdict and
    findings, every case's verdict."""
    return {
        "summary": data["summary"],
        "requirements": {
            r["id"]: {
                "verdict": r["verdict"],
                "consequence_of": r["consequence_of"],
                "findings": [{k: f[k] for k in FINDING_KEYS} for f in r["findings"]],
            }
            for r in data["requirements"]
        },
        "tests": {t["id"]: t["verdict"] for t in data["tests"]},
    }


def dump(digested: dict[str, Any]) -> str:
    """The golden file's text: one line per requirement and per case, so a change shows as
    the lines it touches."""
    lines = [f'{{"summary": {json.dumps(digested["summary"])},', '"requirements": {']
    reqs = list(digested["requirements"].items())
    lines += [
        f"{json.dumps(rid)}: {json.dumps(r, ensure_ascii=False)}{',' if i < len(reqs) - 1 else ''}"
        for i, (rid, r) in enumerate(reqs)
    ]
    lines.append('}, "tests": {')
    tests = list(digested["tests"].items())
    lines += [
        f"{json.dumps(t)}: {json.dumps(v)}{',' if i < len(tests) - 1 else ''}"
        for i, (t, v) in enumerate(tests)
    ]
    lines.append("}}")
    return "\n".join(lines) + "\n"


#: one run in a process of its own, as a user's run is (the exploration no longer depends on
#: the modules a process loaded, tests/sensor/test_exploration.py; the fresh process keeps
#: every other state of a pytest worker out of the comparison too)
RUN_SCRIPT = (
    "import json, sys\n"
    "from conformance.conduct import run_once\n"
    "sys.stdout.write(json.dumps(run_once(sys.argv[1])))\n"
)


def run_fresh(port: str) -> dict[str, Any]:
    """verdicts.json of the sensor suite against ``port``, run in a process of its own."""
    done = subprocess.run(
        [sys.executable, "-c", RUN_SCRIPT, port], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout)


def _params() -> list[Any]:
    return [pytest.param(name, marks=[] if name in FAST else [pytest.mark.slow]) for name in RUNS]


@pytest.mark.parametrize("name", _params())
def test_verdicts_match_the_golden_run(name: str) -> None:
    golden = json.loads((GOLDEN / f"{name}.json").read_text(encoding="utf-8"))
    now = digest(run_fresh(RUNS[name]))
    assert now["summary"] == golden["summary"]
    assert now["tests"] == golden["tests"]
    assert list(now["requirements"]) == list(golden["requirements"])
    for rid, expected in golden["requirements"].items():
        assert now["requirements"][rid] == expected, rid


def test_the_golden_runs_are_not_all_clean() -> None:
    """The fault runs' golden files hold the FAILs their faults cause: a comparison that
    could only ever see PASSes would prove little."""
    failing = {
        name
        for name in RUNS
        if json.loads((GOLDEN / f"{name}.json").read_text(encoding="utf-8"))["summary"]["counts"][
            "FAIL"
        ]
    }
    assert failing == set(RUNS) - {"clean"}


def main() -> None:
    """Write the golden files from the current code (only for an intended verdict change)."""
    for name, port in RUNS.items():
        text = dump(digest(run_fresh(port)))
        (GOLDEN / f"{name}.json").write_text(text, encoding="utf-8")
        print(f"{name}: {len(text)} characters", file=sys.stderr)


if __name__ == "__main__":
    main()
