"""Field captures as they come (issue 23, item 3): a logic analyser on a field cable sees
one-sample spikes on the idle line and edges that chatter as they cross the threshold. The
glitch filter removes them, counts them and says so, and the capture is judged on what
decodes, as the same capture without them is; a capture at the wrong bit rate is still refused
unless ``--force`` (tests/capture/test_errors.py)."""

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


def chattering(vcd: Path, out: Path) -> int:
    """``vcd`` with every level change of the bus channel (``!``) bouncing once: the new
    level, one tick (10 us) of the old one, then the new one for good; how many edges."""
    head, _, body = vcd.read_text(encoding="ascii").partition("$enddefinitions $end\n")
    lines: dict[int, list[str]] = {}
    for t, rest in re.findall(r"#(\d+)\n((?:[^#][^\n]*\n?)*)", body):
        lines.setdefault(int(t), []).extend(x for x in rest.splitlines() if x)
    edges = 0
    level = None
    for t in sorted(lines):
        change = next((x for x in lines[t] if x.endswith("!") and len(x) == 2), None)
        if change is None or change[0] == level:
            continue
        first, level = level is None, change[0]
        if first:
            continue  # the level the capture starts at: no edge
        edges += 1
        lines.setdefault(t + 1, []).append(f"{1 - int(level)}!")
        lines.setdefault(t + 2, []).append(f"{level}!")
    text = "".join(f"#{t}\n" + "".join(x + "\n" for x in lines[t]) for t in sorted(lines))
    out.write_text(head + "$enddefinitions $end\n" + text, encoding="ascii")
    return edges


def _judged_alike(tmp_path: Path, make) -> tuple[dict, dict]:
    """A short run's capture judged clean and as ``make(clean, noisy)`` spoils it: both
    verdict sets, and the spoilt one's verdicts.json."""
    first = tmp_path / "live"  # a short run: the noise is much beside its frames (issue 23)
    main(["--port", "sim", "-k", "test_identification", "--report-dir", str(first)])
    clean = tmp_path / "clean.vcd"
    assert main(["export", str(first), "--to", "vcd", "-o", str(clean)]) == 0
    noisy = tmp_path / "noisy.vcd"
    make(clean, noisy)
    judged = {}
    for name, capture in (("clean", clean), ("noisy", noisy)):
        out = tmp_path / name
        code = main(["judge", str(capture), "--passive", "--report-dir", str(out)])
        assert code in (0, 1, 2), f"{name}: exit {code}"  # 2: passive leaves rules open
        judged[name] = out
    a, b = requirements(judged["clean"]), requirements(judged["noisy"])
    assert {k: v["verdict"] for k, v in a.items()} == {k: v["verdict"] for k, v in b.items()}
    frames = sum('"kind": "char"' in line for line in (first / "transcript.jsonl").open())
    return json.loads((judged["noisy"] / "verdicts.json").read_text()), {"frames": frames}


def test_spikes_on_the_idle_line_are_shown_and_judged_through(tmp_path):
    data, seen = _judged_alike(tmp_path, lambda clean, noisy: spiked(clean, noisy))
    said = json.dumps(data["dut"])
    assert f"{SPIKES} pulse(s) shorter than that removed" in said, said
    assert "stamps widened" not in said  # a spike on a marking stretch moves no edge
    assert seen["frames"] <= SPIKES * 5  # as many spikes beside as few frames as refused before


def test_chattering_edges_are_filtered_and_widen_the_stamps(tmp_path):
    """Every edge bouncing once for 10 us (the export's tick; the issue's case was 2 us):
    exit 4 before the filter ('framing/parity errors and glitches'), now the clean capture's
    verdicts, each edge's uncertainty widened by the filter's 52 us and said so."""
    made = {}
    data, _ = _judged_alike(tmp_path, lambda c, n: made.setdefault("edges", chattering(c, n)))
    said = json.dumps(data["dut"])
    assert f"{made['edges']} pulse(s) shorter than that removed" in said, said
    assert f"{made['edges']} beside an edge that stayed" in said and "stamps widened" in said
    assert data["run"]["link"]["timing_uncertainty_ms"] >= 0.052
    # without the filter (--glitch-filter-us 0) the capture is refused, as it was before it
    off = ["judge", str(tmp_path / "noisy.vcd"), "--passive", "--glitch-filter-us", "0"]
    assert main([*off, "--report-dir", str(tmp_path / "off")]) == 4
    forced = tmp_path / "forced"  # --force judges it all the same, and says why it looked bad
    assert main([*off, "--force", "--report-dir", str(forced)]) in (0, 1, 2)
    notes = json.dumps(json.loads((forced / "verdicts.json").read_text())["dut"])
    assert "judged although the decode looks wrong (--force)" in notes, notes
