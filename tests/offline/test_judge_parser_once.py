"""``judge``'s command line is parsed by one parser a process (issue 22, replay27: a
fault-matrix row's round trip parses one per row, and building it was ~1 ms of the row):
a parse leaves nothing behind that a later one reads."""

from __future__ import annotations

from conformance.offline import judge

EVERY = [
    "cap.sr",
    "--role", "recorder", "--address", "3", "--channel", "D1", "--tx-channel", "D2",
    "--invert", "--baud", "9600", "--glitch-filter-us", "5", "--force", "--report-dir", "out",
    "--strict", "--sdi-version", "1.3", "--run", "runs/x", "--passive",
]  # fmt: skip


def test_one_parser_a_process():
    assert judge._parser() is judge._parser()


def test_a_parse_after_another_reads_as_a_fresh_parser_does():
    fresh = vars(judge.build_parser().parse_args(["cap.sr"]))
    every = vars(judge._parser().parse_args(EVERY))
    assert every == vars(judge.build_parser().parse_args(EVERY))
    assert every != fresh
    assert vars(judge._parser().parse_args(["cap.sr"])) == fresh
    no_invert = vars(judge._parser().parse_args(["cap.sr", "--no-invert"]))
    assert no_invert == fresh | {"invert": False}
    assert vars(judge._parser().parse_args(["cap.sr"])) == fresh
