"""The console's first line says what is known of the device, and nothing else.

The eighteenth round's Arduino Due sensor (docs/kit.md) answers ``?!`` but not ``aI!``: the
line read "SDI-12 not known (the run stopped before aI!)" although the run had sent aI!
(R-4.4.2-01 FAILed "aI! got no reply") and went on to the end."""

from __future__ import annotations

from conformance.reports.console import _identity_lines


def _data(version: str | None) -> dict:
    return {
        "dut": {"address": "0", "identification": None, "sdi12_version": version},
        "run": {"role": "sensor", "port": "exec:./fw", "link": {"kind": "exec"}},
    }


def test_an_unanswered_ai_is_not_called_a_stopped_run():
    first = _identity_lines(_data(None))[0]
    assert "stopped" not in first, first
    assert first.startswith("DUT 0 · SDI-12 not known (no version from aI!)"), first


def test_a_known_version_is_printed():
    assert _identity_lines(_data("1.3"))[0].startswith("DUT 0 · SDI-12 1.3 ·")
