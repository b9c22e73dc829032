"""A device that sends markup must not be able to run anything in the report (design.md 7).

The whole suite runs in-process against a simulated sensor whose identification and extended
command replies carry ``<script>`` and ``"><img onerror=...>``; the resulting report.html is
rendered in headless Chromium with every case expanded, and the test asserts that no dialog
opened, no script failed, and none of the payloads became an element. A control page proves
that the same harness does catch such a payload when it is not escaped.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

import conformance.run
from conformance import cli
from conformance.emulator import default_profile, sim_sensor
from conformance.ports import OpenedPort, SimSpec, sim_declaration
from tests.support.report_browser import SCREENSHOTS, Chromium, require_chromium

# Renders a hostile report in headless Chromium.
pytestmark = pytest.mark.browser

SCRIPT = "<script>alert('script')</script>"
IMG = '"><img src=x onerror=alert("img")>'
SVG = "<svg/onload=alert('svg')>"

PAYLOADS = """(function(){
  var found = [];
  document.querySelectorAll('img[onerror], svg[onload], img[src="x"]')
    .forEach(function(e){ found.push(e.outerHTML); });
  document.querySelectorAll('script').forEach(function(s){
    if (s.textContent.indexOf("alert(") >= 0) found.push(s.outerHTML.slice(0, 80)); });
  return {elements: found, text: document.body.innerText};
})()"""


def hostile_port(port: str, **_bench: str) -> OpenedPort:
    """The reference sensor, but its identification and extended replies are markup.

    The identification fields are overwritten past the profile's width checks on purpose: a
    hostile device does not respect R-4.4.2-01 either.
    """
    profile = replace(default_profile("14"), extended={"XSN": IMG, "XHELP": f"{SCRIPT}\n{SVG}"})
    object.__setattr__(profile, "vendor", SCRIPT)
    object.__setattr__(profile, "model", IMG)
    _bus, link, emulator = sim_sensor(profile)
    return OpenedPort(link, [emulator], sim_declaration(emulator.profile, SimSpec()))


@pytest.fixture(scope="module")
def hostile_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("hostile")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(conformance.run, "open_port", hostile_port)
        code = cli.main(["--port", "sim", "--report-dir", str(out)])
    assert code == cli.EXIT_NON_COMPLIANT  # the 67-character identification breaks R-4.4.2-01
    data = json.loads((out / "verdicts.json").read_text(encoding="utf-8"))
    assert SCRIPT in data["dut"]["identification"] and IMG in data["dut"]["identification"]
    return out


def test_the_payloads_reach_the_report_file(hostile_report):
    """Otherwise the browser test below would prove nothing: the markup is in the file,
    escaped, in the header and in the wire transcripts."""
    page = (hostile_report / "report.html").read_text(encoding="utf-8")
    assert "&lt;script&gt;alert(&#x27;script&#x27;)&lt;/script&gt;" in page
    assert "&quot;&gt;&lt;img src=x onerror=alert(&quot;img&quot;)&gt;" in page
    assert "onerror=alert(" in page  # the text survives, as text
    assert "<img src=x" not in page and SCRIPT not in page


def test_hostile_identification_executes_nothing(hostile_report):
    require_chromium()
    with Chromium(1280, 720) as browser:
        browser.open(hostile_report / "report.html")
        browser.evaluate("document.getElementById('show_all_details').click()")
        browser.evaluate("new Promise(r => setTimeout(r, 500))")  # let any onerror fire
        found = browser.evaluate(PAYLOADS)
        browser.screenshot(SCREENSHOTS / "report-hostile.png")
        problems = browser.log.problems
    assert problems == [], problems
    assert found["elements"] == []
    # the payloads are shown to the reader as text: in the header and in the wire log
    assert SCRIPT in found["text"] and IMG in found["text"]
    assert "<svg/onload=alert('svg')>" in found["text"]


def test_the_harness_catches_an_unescaped_payload(tmp_path):
    """Control: the same checks fail on a page that does not escape the identification."""
    require_chromium()
    page = tmp_path / "unsafe.html"
    page.write_text(f"<html><body><p>identification: 014{IMG}</p></body></html>", "utf-8")
    with Chromium(800, 600) as browser:
        browser.open(page)
        browser.evaluate("new Promise(r => setTimeout(r, 300))")
        found = browser.evaluate(PAYLOADS)
        problems = browser.log.problems
    assert any(p.startswith("dialog: alert: img") for p in problems), problems
    assert found["elements"], "the injected <img> was not seen"
