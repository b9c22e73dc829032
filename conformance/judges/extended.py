"""Judges for extended commands (4.4.13) and multi-line text (4.4.13.1, decision A10).

A reply whose read the tool's own host stalled over (:attr:`~conformance.tool_recorder.
records.Exchange.stall`) may be cut, its rest a late burst, and its stamps moved by the
stall: what its framing, line lengths and the marking between its lines show is the host's,
INCONCLUSIVE with the stall named (:mod:`.stalled`, truth29); a reply outside any stall is
judged as ever.
"""

from __future__ import annotations

from ..protocol.framing import ETX, LF
from ..protocol.timing import MULTILINE_GAP_MAX
from ..protocol.values import VALUES_MAX
from ..tool_recorder.records import Exchange
from ..transcript import Event, escape
from ..verdicts import Finding
from .late_before import answered_late
from .stalled import through_stall, unless_stalled
from .tally import Tally
from .timing import judge_window

LINE_MAX = VALUES_MAX  # a multi-line text line is held to the longest reply's values part


def is_multiline(ex: Exchange) -> bool:
    return ex.answered and ex.reply_text[1:2] == "\x02"


def extended_replies(exchanges: list[Exchange], address: str) -> list[Finding]:
    tally = Tally(("R-4.4.13-01", "R-4.4.13-02"))
    for ex in exchanges:
        label = escape(ex.text)
        if late := answered_late(ex):
            # a reply after the window, or one that may be the command before's: no reply of
            # this command's to judge (0XSN!'s late reply, 80 ms after its retry, was taken
            # by the 0XHELP! after it, answers-foreign-address + replies-after-retry, truth15)
            for rid in tally.ids:
                tally.undecide(rid, label, f"{late} (R-7.0-10 judges its timing)")
            continue
        if not ex.answered:
            continue  # an extended command may be unknown to the sensor: silence is allowed
        # only a command the sensor answers shows that it implements that name
        tally.observe(label, ids=["R-4.4.13-02"])
        if ex.text[1:2] != "X":
            tally.fail("R-4.4.13-02", label, f"{label} does not use the aX...! form", warning=True)
        tally.observe(label, ids=["R-4.4.13-01"])
        text = ex.reply_text.rstrip("\x03") if is_multiline(ex) else ex.reply_text
        if not text.startswith(address) or not text.endswith("\r\n"):
            through_stall(tally, ex.stall).fail(
                "R-4.4.13-01",
                label,
                f"reply '{escape(ex.reply_text)}' does not run from the address to CR LF",
            )
    return tally.findings()


def lines(events: list[Event]) -> list[list[Event]]:
    """Split a multi-line reply into lines, each ending with its LF."""
    out: list[list[Event]] = [[]]
    for e in events:
        out[-1].append(e)
        if e.char7 == LF:
            out.append([])
    return [line for line in out if line]


def multiline(exchanges: list[Exchange], address: str, uncertainty: float) -> list[Finding]:
    ids = ("R-4.4.13.1-01", "R-4.4.13.1-02", "R-4.4.13.1-03")
    tally = Tally(ids)
    timing: list[Finding] = []
    for ex in exchanges:
        label = escape(ex.text)
        tally.observe(label)
        here = through_stall(tally, ex.stall)  # what a stalled read shows is undecided
        events = ex.reply_events
        text = ex.reply_text
        if not (text.startswith(address + "\x02") and text.endswith("\r\n\x03")):
            here.fail(
                "R-4.4.13.1-01",
                label,
                f"reply '{escape(text[:20])}...{escape(text[-6:])}' is not framed "
                "a<STX>...<CR><LF><ETX>",
            )
        body_lines = lines([e for e in events if e.char7 != ETX])
        for n, line in enumerate(body_lines, 1):
            content = "".join(chr(e.char7) for e in line).rstrip("\r\n")
            if n == 1:
                content = content[2:]  # address and STX do not count
            if len(content) > LINE_MAX:
                here.fail(
                    "R-4.4.13.1-02",
                    label,
                    f"line {n} has {len(content)} characters (at most {LINE_MAX})",
                )
            # character gaps inside a line are the general rule's (R-7.0-12, whole run)
        for before, after in zip(body_lines, body_lines[1:], strict=False):
            between = judge_window(
                "R-4.4.13.1-03",
                "marking between lines",
                after[0].start - before[-1].end,
                uncertainty,
                high=MULTILINE_GAP_MAX,
                evidence=[label],
            )
            timing.append(unless_stalled(between, [ex]))
    findings = tally.findings()
    worst = max(timing, key=lambda f: f.verdict.rank, default=None)
    if worst is not None:
        findings = [
            worst if f.requirement == "R-4.4.13.1-03" and worst.verdict.rank > f.verdict.rank else f
            for f in findings
        ]
    return findings
