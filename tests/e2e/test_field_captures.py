"""Field captures as they come (issue 23, item 3): a logic analyser on a field cable sees
one-sample spikes on the idle line. They are counted and shown, and the capture is judged on
what decodes, as the same capture without them is; a capture at the wrong bit rate is still
refused (tests/capture/test_errors.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from conformance.cli import main
from tests.offline.test_judge import requirements

SPIKES = 26
FRAME_TICKS = 834  # one 1200-baud frame in the export's 10 us ticks


def spiked(vcd: Path, out: Path, count: int = SPIKES) -> int:
    """``vcd`` with one-sample spacing spikes on the bus channel (``!``) put into its longest
    idle stretches, every other line of the file kept; how many were put in."""
    head, _, body = vcd.read_text(encoding="ascii").partition("$enddefinitions $end\n")
    sections = [(int(t), rest) for t, rest in re.findall(r"#(\d+)\n((?:[^#][^\n]*\n?)*)", body)]
    level, steps = None, []
    for t, rest in sections:
        change = re.search(r"^([01])!$", rest, flags=re.M)
        if change and change.group(1) != level:
            level = change.group(1)
            steps.append((t, level))
    # idle: marking longer than two frames (no character of a reply is inside it)
    idle = [(a[0], b[0]) for a, b in zip(steps, steps[1:], strict=False) if a[1] == "1"]
    idle = [(a, b) for a, b in idle if b - a > 2 * FRAME_TICKS]
    for n in range(count):
        a, b = idle[n % len(idle)]
        at = a + FRAME_TICKS + (b - a - 2 * FRAME_TICKS) * (n // len(idle) + 1) // (count + 1)
        sections += [(at, "0!\n"), (at + 1, "1!\n")]
    text = "".join(f"#{t}\n{rest}" for t, rest in sorted(sections, key=lambda x: x[0]))
    out.write_text(head + "$enddefinitions $end\n" + text, encoding="ascii")
    return count


def test_spikes_on_the_idle_line_are_shown_and_judged_through(tmp_path):
    first = tmp_path / "live"  # a short run: the spikes are many beside its frames (issue 23)
    main(["--port", "sim", "-k", "test_identification", "--report-dir", str(first)])
    clean = tmp_path / "clean.vcd"
    assert main(["export", str(first), "--to", "vcd", "-o", str(clean)]) == 0
    noisy = tmp_path / "noisy.vcd"
    assert spiked(clean, noisy) == SPIKES
    judged = {}
    for name, capture in (("clean", clean), ("noisy", noisy)):
        out = tmp_path / name
        code = main(["judge", str(capture), "--passive", "--report-dir", str(out)])
        assert code in (0, 1, 2), f"{name}: exit {code}"  # 2: passive leaves rules open
        judged[name] = out
    a, b = requirements(judged["clean"]), requirements(judged["noisy"])
    assert {k: v["verdict"] for k, v in a.items()} == {k: v["verdict"] for k, v in b.items()}
    said = json.dumps(json.loads((judged["noisy"] / "verdicts.json").read_text())["dut"])
    assert f"{SPIKES} glitch(es)" in said
    frames = sum('"kind": "char"' in line for line in (first / "transcript.jsonl").open())
    assert frames <= SPIKES * 5, frames  # as many spikes beside as few frames as refused before
