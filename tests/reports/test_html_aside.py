"""report.html rendered by a forked process (``conduct(..., html_aside=True)``, the main
command's own process) is the page the run renders itself; the parent writes it when the
child did not; no fork where another thread runs."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from conformance.reports import html_aside

#: one fresh interpreter (no thread but the main one, as the main command's process): the
#: same run rendered both ways; prints whether the first forked
BOTH_WAYS = """
import os, sys
from conformance.conduct import conduct
from conformance.run import RunOptions
forks = []
real_fork = os.fork
def fork():
    pid = real_fork()
    if pid:
        forks.append(pid)
    return pid
os.fork = fork
for folder, aside in ((sys.argv[2], True), (sys.argv[3], False)):
    conduct(RunOptions(port=sys.argv[1], role="sensor", report_dir=folder), html_aside=aside)
print(len(forks))
"""


def normalised(page: str) -> str:
    """A page without what differs between two renderings of one run: the date and time it
    was made, the durations, the run's folder."""
    page = re.sub(r"tests took [^.]+\.", "tests took DURATION.", page)
    page = re.sub(r"\d\d-\w\w\w-\d{4}", "DATE", page)
    page = re.sub(r"\d\d:\d\d:\d\d", "TIME", page)
    page = re.sub(r"\d+ ms", "N ms", page)
    page = re.sub(r"&#34;duration&#34;: [0-9.e-]+", "DURATION", page)
    # a case's shown duration: "N ms" under a second, "HH:MM:SS" from one on (a loaded
    # machine takes a case across that line in one rendering and not the other)
    page = re.sub(r"(&#34;duration&#34;: &#34;)(?:TIME|N ms)(&#34;)", r"\1DURATION\2", page)
    page = re.sub(r"(col-duration\\&#34;&gt;)(?:TIME|N ms)(&lt;)", r"\1DURATION\2", page)
    return re.sub(r"/(aside|plain)\b", "/FOLDER", page)


@pytest.mark.parametrize(
    "port",
    [
        "sim",  # the default selection keeps one (two runs in a subprocess: a few seconds)
        pytest.param("sim://?faults=wrong-crc", marks=pytest.mark.slow),
        pytest.param("sim://?faults=response-too-late", marks=pytest.mark.slow),
    ],
)
def test_the_forked_page_is_the_page(port: str, tmp_path: Path) -> None:
    """The cases' HTML pieces made when the page is rendered, in a child process, give the
    page the run renders as each case ends (a clean run, one with FAIL evidence on the wire,
    one with timing diagrams)."""
    aside, plain = tmp_path / "aside", tmp_path / "plain"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    done = subprocess.run(
        [sys.executable, "-c", BOTH_WAYS, port, str(aside), str(plain)],
        capture_output=True, text=True, env=env, check=True, timeout=300,
    )  # fmt: skip
    assert done.stdout.split()[-1] == "1", done.stdout + done.stderr  # the first run forked
    pages = [normalised((f / "report.html").read_text(encoding="utf-8")) for f in (aside, plain)]
    assert "sdi12-case" in pages[0] and 'id="sdi12-top"' in pages[0]
    assert pages[0] == pages[1]
    for name in ("junit.xml", "verdicts.json"):
        assert (aside / name).is_file()
    document = json.loads((aside / "verdicts.json").read_text(encoding="utf-8"))
    assert document["summary"]["verdict"] in ("COMPLIANT", "NON-COMPLIANT")


class _Page:
    """pytest-html's report object as :class:`html_aside.Aside` uses it."""

    def __init__(self) -> None:
        self.rendered = 0

    def _generate_report(self, *args: object, **kwargs: object) -> None:
        self.rendered += 1


class _Ours:
    """The conformance plugin's HTML hooks as :class:`html_aside.Aside` uses them."""

    def __init__(self) -> None:
        self.aside: object = "set"
        self.summaries: list[tuple[list[str], list[str], list[str]]] = []

    def pytest_html_results_summary(self, prefix, summary, postfix, session) -> None:
        self.summaries.append((prefix, summary, postfix))


def _child_exiting(code: int) -> int:
    pid = os.fork()
    if pid == 0:
        os._exit(code)
    return pid


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork only")
def test_the_parent_writes_the_page_when_the_child_did_not() -> None:
    page, ours = _Page(), _Ours()
    aside = html_aside.Aside(_child_exiting(1), page, ours)  # type: ignore[arg-type]
    aside.summary_lists = (["p"], [], ["q"])
    aside.generate()
    assert aside.wrote is False
    assert page.rendered == 1  # made here
    assert ours.summaries == [(["p"], [], ["q"])] and ours.aside is None  # with our summary
    assert aside.wait() is False  # waited for once


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork only")
def test_the_parent_leaves_the_page_to_a_child_that_wrote_it() -> None:
    page, ours = _Page(), _Ours()
    aside = html_aside.Aside(_child_exiting(0), page, ours)  # type: ignore[arg-type]
    aside.summary_lists = (["p"], [], ["q"])
    aside.generate()
    assert aside.wrote is True and page.rendered == 0 and ours.summaries == []


def test_no_fork_while_another_thread_runs() -> None:
    stop = threading.Event()
    other = threading.Thread(target=stop.wait, daemon=True)
    other.start()
    try:
        assert not html_aside.can_fork()
    finally:
        stop.set()
        other.join()


def test_no_page_no_fork() -> None:
    """Without pytest-html's page among the plugins nothing is forked."""
    assert html_aside.pytest_html_page([object(), _Page()]) is None


#: the main command's way (forked page) in a fresh interpreter: prints whether the parent
#: compiled pytest-html's template (it should not: the child renders the page)
PARENT_COMPILES = """
import sys
from conformance.conduct import conduct
from conformance.reports import html_aside
from conformance.run import RunOptions
seen = []
class Look:
    def pytest_unconfigure(self, config):
        page = html_aside.pytest_html_page(config.pluginmanager.get_plugins())
        seen.append(page._template._template is not None)
options = RunOptions(port="sim", role="sensor", report_dir=sys.argv[1],
                     keyword="test_query_address")
conduct(options, html_aside=True, plugins=[Look()])
print(seen)
"""


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork only")
def test_the_parent_of_a_forked_page_never_compiles_its_template(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    done = subprocess.run(
        [sys.executable, "-c", PARENT_COMPILES, str(tmp_path / "run")],
        capture_output=True, text=True, env=env, check=True, timeout=300,
    )  # fmt: skip
    assert done.stdout.split()[-1] == "[False]", done.stdout + done.stderr
    page = (tmp_path / "run" / "report.html").read_text(encoding="utf-8")
    assert "sdi12-case" in page  # the child rendered it, with the template
