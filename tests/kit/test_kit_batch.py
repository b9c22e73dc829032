"""The sensor sketch on the harness protocol's ``batch`` feature (the kit answers
``hello 2+batch``): told with ``chars`` messages and QUIET fields it wakes itself for its idle
polls instead of asking. Run again with the tool offering no feature (plain version-2
messages, a ``time`` for every poll), it must put down the same line, instant for instant,
and get the same verdicts: the sketch observes the same times either way."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance.conduct import run_into
from conformance.harness import protocol as proto
from tests.kit.conftest import LOGGER, LOGGER_DECLARATION, SENSOR, SKETCHES, TINY_SDI12

DECLARATION = str(SENSOR / "sdi12_sensor.toml")
#: cases with waits of ttt seconds the sketch polls through, service requests, a measurement
#: aborted by a break, concurrent measurements among other sensors' traffic
KEYWORD = "service_request or break_aborts_measurement or concurrent_survives"


def line_events(folder: Path) -> list[dict]:
    """The transcript: line events and notes (a job's end among them), but the run's options,
    which name the run's folder."""
    rows = (json.loads(line) for line in (folder / "transcript.jsonl").read_text().splitlines())
    return [row for row in rows if not row["text"].startswith("run-options")]


def both_ways(port: str, options: dict, tmp_path: Path, monkeypatch) -> tuple[dict, dict]:
    """The run with the batch feature, then with the tool offering none (it takes the
    feature as unknown); asserts both put down the same line and the same summary."""
    batched = run_into(tmp_path / "batched", port, **options)
    monkeypatch.setattr(proto, "BATCH", "not-offered")
    plain = run_into(tmp_path / "plain", port, **options)
    events = line_events(tmp_path / "batched")
    assert len(events) > 100
    assert events == line_events(tmp_path / "plain")
    assert batched["summary"] == plain["summary"]
    assert batched["summary"]["counts"]["PASS"] >= 3
    return batched, plain


@pytest.mark.slow  # two runs; CI runs it, the inner loop keeps test_batch.py's scripted device
def test_the_sketch_makes_the_same_line_batched_or_not(kit_build, tmp_path, monkeypatch):
    port = f"exec:{kit_build(SENSOR, (TINY_SDI12,))}"
    options = {"declaration": DECLARATION, "keyword": KEYWORD}
    batched, plain = both_ways(port, options, tmp_path, monkeypatch)
    assert len(line_events(tmp_path / "batched")) > 300
    verdicts = {r["id"]: r["verdict"] for r in batched["requirements"]}
    assert verdicts == {r["id"]: r["verdict"] for r in plain["requirements"]}


@pytest.mark.slow  # two recorder runs
def test_the_logger_sketch_makes_the_same_line_batched_or_not(kit_build, tmp_path, monkeypatch):
    """The recorder role: told QUIET (the played sensors' next character), the logger sketch
    wakes itself while it waits for a reply or a service request; a job's end is told at
    the time it came, so the next job starts where it did before."""
    port = f"exec:{kit_build(LOGGER, (TINY_SDI12,))}"
    options = {"declaration": LOGGER_DECLARATION, "role": "recorder"}
    options["keyword"] = "service_request or crc_mismatch or transparent"
    both_ways(port, options, tmp_path, monkeypatch)


def test_a_sketch_spinning_after_its_reply_hears_the_follow_up_batched_or_not(
    kit_build, tmp_path, monkeypatch
):
    """Sixteenth round (docs/kit.md): a sensor that spins on its receive queue after a reply
    of back-to-back frames ran on to the QUIET the tool told for the reply's first frame,
    which the tool shortened once it heard the LF; the follow-up it then sent 20 ms after the
    reply (R-7.0-16), and the break and command after it, came in the sketch's past and went
    unheard: R-7.0-16 FAILed and, on the lagopus sketch, R-4.3-04 PASSed "refused '$'" on a
    command never heard. A ``sent`` QUIET is now dropped when the sketch has begun another
    frame since, so the line is the same batched or not."""
    port = f"exec:{kit_build(SKETCHES / 'spin_sensor', (TINY_SDI12,))}"
    options = {"address": "0", "keyword": "test_follow_up_without_break"}
    batched = run_into(tmp_path / "batched", port, **options)
    monkeypatch.setattr(proto, "BATCH", "not-offered")
    plain = run_into(tmp_path / "plain", port, **options)
    events = line_events(tmp_path / "batched")
    assert len(events) > 20
    assert batched["summary"] == plain["summary"]
    assert events == line_events(tmp_path / "plain")
    verdicts = {r["id"]: r["verdict"] for r in batched["requirements"]}
    assert verdicts["R-7.0-16"] == "PASS", verdicts
