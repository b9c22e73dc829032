"""The round trip the README promises, with the README's own commands (issue 19): ``export
RUN --to FMT`` then ``judge RUN/capture.FMT``, no other option, gives the run's verdicts back
for every capture format, on a clean and on a faulty sim, in either role.

Before, the default export had no tool channel and judge did not know it: the .sr was judged
passively (56 INCONCLUSIVE where the run had none) and a CSV, which kept no notes, had the
tool's own recorder judged (15 FAIL).

What a capture cannot carry: the run's timing figures come back with the capture's sample
uncertainty (one 10 us sample), so only the verdicts are compared, not the findings' figures;
a requirement the live run left INCONCLUSIVE may be decided from the capture (its timing can
be better than a link's). No requirement in these runs differs.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance.capture import embedded_meta
from conformance.cli import main
from conformance.replay.recording import OPTIONS_NOTE
from tests.support.shared_runs import copied_run

#: requirements whose verdict a capture may change, with why (none in these runs)
CANNOT_CARRY: dict[str, str] = {}


def verdicts(run: Path) -> dict[str, str]:
    data = json.loads((run / "verdicts.json").read_text(encoding="utf-8"))
    return {r["id"]: r["verdict"] for r in data["requirements"]}


def changed(live: dict[str, str], again: dict[str, str]) -> dict[str, tuple[str, str]]:
    out = {}
    for rid in live.keys() | again.keys():
        a, b = live.get(rid, "absent"), again.get(rid, "absent")
        if a != b and rid not in CANNOT_CARRY and not (a == "INCONCLUSIVE" and b != "absent"):
            out[rid] = (a, b)
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Path]:
    """One live run per port, copied once into this module (the formats share it; the runs
    themselves are made once a session: tests/support/shared_runs.py)."""
    made = {}
    for port, role in (("sim", "sensor"), ("sim://?faults=no-service-request", "sensor")):
        out = tmp_path_factory.mktemp("live") / "run"
        made[port], _code = copied_run(tmp_path_factory, out, port, role)
    return made


def round_trip(run: Path, fmt: str, tmp: Path) -> tuple[int, Path]:
    """The README's two commands; the capture where export puts it by default."""
    assert main(["export", str(run), "--to", fmt]) == 0
    capture = run / f"capture.{fmt}"
    assert capture.exists()
    again = tmp / f"judged-{fmt}"
    return main(["judge", str(capture), "--report-dir", str(again)]), again


def check(run: Path, fmt: str, tmp: Path) -> None:
    code, again = round_trip(run, fmt, tmp)
    live = verdicts(run)
    assert code == (1 if "FAIL" in live.values() else 0)
    assert not changed(live, verdicts(again))
    link = json.loads((again / "verdicts.json").read_text(encoding="utf-8"))["run"]["link"]
    assert str(link["kind"]).startswith("replay"), link  # replayed, not judged passively


@pytest.mark.parametrize("fmt", ["sr", "csv", "vcd"])
def test_the_readme_round_trip_gives_a_clean_runs_verdicts(runs, tmp_path, fmt):
    check(runs["sim"], fmt, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["sr", "csv", "vcd"])
def test_the_readme_round_trip_gives_a_faulty_runs_verdicts(runs, tmp_path, fmt):
    faulty = runs["sim://?faults=no-service-request"]
    assert "FAIL" in verdicts(faulty).values()
    check(faulty, fmt, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["sr", "csv"])
def test_the_readme_round_trip_in_the_recorder_role(tmp_path, fmt):
    """The tool's TX is the sensors' here: judge must not take it for the recorder's."""
    run = tmp_path / "run"
    main(
        [
            "--port",
            "sim://?recorder-faults=retry-too-early",
            "--role",
            "recorder",
            "--report-dir",
            str(run),
        ]
    )
    check(run, fmt, tmp_path)


@pytest.mark.parametrize("fmt", ["sr", "csv", "vcd"])
def test_the_export_says_which_channel_is_the_tools(runs, tmp_path, fmt):
    out = tmp_path / f"run.{fmt}"
    assert main(["export", str(runs["sim"]), "--to", fmt, "-o", str(out)]) == 0
    meta = embedded_meta(str(out))
    assert (meta.bus_channel, meta.tool_channel) == ("SDI12", "TOOL_TX")
    assert any(n.text.startswith(OPTIONS_NOTE) for n in meta.notes)
    assert main(["export", str(runs["sim"]), "--to", fmt, "-o", str(out), "--no-tool-channel"]) == 0
    assert embedded_meta(str(out)).tool_channel is None
