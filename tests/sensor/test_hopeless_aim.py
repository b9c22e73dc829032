"""A timed probe that no try can land is sent once (issue 22, fifth round): R-7.0-05's
answered probe aims at 9 ms of marking after a break, and a link stamped to 5 ms can never
show that marking to be 8.33 ms or more, so the four more tries it made (about 1 s of a real
run) could land only by a host stall. The verdict stays INCONCLUSIVE and says why; with
exact stamps the probe lands on its first try as before.

The sim stands in for a real link through the user's ``--timing-uncertainty-ms``."""

from __future__ import annotations

import json

import pytest

from conformance import cli
from conformance.capture import read_transcript_jsonl
from conformance.transcript import EventKind


def _run(tmp_path, *extra: str) -> tuple[dict, int]:
    code = cli.main(
        ["--port", "sim", "-k", "test_marking_after_break", "--report-dir", str(tmp_path), *extra]
    )
    assert code in (cli.EXIT_COMPLIANT, cli.EXIT_NON_COMPLIANT)
    data = json.loads((tmp_path / "verdicts.json").read_text(encoding="utf-8"))
    (finding,) = next(r for r in data["requirements"] if r["id"] == "R-7.0-05")["findings"]
    events = read_transcript_jsonl(str(tmp_path / "transcript.jsonl"))
    breaks = sum(1 for e in events if e.kind is EventKind.BREAK)
    return finding, breaks


@pytest.mark.parametrize("uncertainty_ms", ["5", "0.7"])
def test_a_probe_that_cannot_land_goes_out_once(tmp_path, uncertainty_ms):
    finding, breaks = _run(tmp_path, "--timing-uncertainty-ms", uncertainty_ms)
    assert finding["verdict"] == "INCONCLUSIVE"
    assert "none of" not in finding["detail"]
    assert "cannot show 8.33 ms of marking from 9: one try" in finding["detail"]
    # the two probes' breaks (9 ms, then 2 ms of marking) and the wake-ups around them: five
    # tries of the first probe made four breaks more; with exact stamps the 9 ms probe lands,
    # is answered and goes out at a second wake (one break more: slow-wake-every-other)
    _, exact_breaks = _run(tmp_path / "exact")
    assert breaks == exact_breaks - 1


def test_with_exact_stamps_the_probe_lands_first_time(tmp_path):
    finding, _ = _run(tmp_path)
    assert finding["verdict"] == "PASS"


def _ready(tmp_path, *extra: str) -> tuple[dict, int, int]:
    """R-7.0-07's finding, the run's breaks, and how many tries its probe made (notes)."""
    code = cli.main(
        [
            "--port",
            "sim",
            "-k",
            "test_ready_within_100ms_of_break",
            "--report-dir",
            str(tmp_path),
            *extra,
        ]
    )
    assert code in (cli.EXIT_COMPLIANT, cli.EXIT_NON_COMPLIANT)
    data = json.loads((tmp_path / "verdicts.json").read_text(encoding="utf-8"))
    (finding,) = next(r for r in data["requirements"] if r["id"] == "R-7.0-07")["findings"]
    events = read_transcript_jsonl(str(tmp_path / "transcript.jsonl"))
    breaks = sum(1 for e in events if e.kind is EventKind.BREAK)
    missed = sum(1 for e in events if e.kind is EventKind.NOTE and "a! 90 ms after" in e.text)
    return finding, breaks, missed


def test_a_command_90_ms_after_the_break_that_cannot_show_100_goes_out_once(tmp_path):
    """Behind ``--echo --usb-latency 16`` (±15.4 ms) the probe landed at 102.1 ms five times
    over (issue 22, usb12): 90 ms + 15.4 ms is past 100.4 ms whatever the landing."""
    finding, breaks, missed = _ready(tmp_path, "--timing-uncertainty-ms", "15.4")
    assert finding["verdict"] == "INCONCLUSIVE"
    assert "none of" not in finding["detail"]
    assert (
        "cannot show a command 90 ms after a break to be within 100 ms: one try"
        in (finding["detail"])
    )
    assert missed == 1  # one try, noted as missed, and no more
    _, exact_breaks, exact_missed = _ready(tmp_path / "exact")
    assert exact_missed == 0
    assert breaks == exact_breaks - 1  # the landed, answered probe's second wake


def test_a_command_90_ms_after_the_break_within_reach_is_judged(tmp_path):
    """At ±10 ms 90 ms can still be shown within 100.4 ms: the probe lands and is judged."""
    finding, _, missed = _ready(tmp_path, "--timing-uncertainty-ms", "10")
    assert finding["verdict"] == "PASS"
    assert missed == 0
