"""R-5.2-06: an aDBn! past the data returns the empty packet (size 0, type 0, its CRC).

Judged here, not in the case, so what the tool took as each probe's reply is decided in one
place: a probe answered only after its reply window, or answered with what may be the
command before's late reply (:func:`~.late_before.answered_late`), shows nothing of what the
sensor returns for it. A sensor 80 ms late and deaf until it answers sent 0DB999!'s empty
packet into each retry, which the engine set aside as bus contention: "0DB999! returned
'(nothing)'" FAILed beside never-standby, answers-foreign-address and others
(replies-after-retry, truth18); no PASS rests on such a probe either.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..protocol.binary import parse_binary_packet
from ..tool_recorder.records import Exchange
from ..verdicts import Finding, failed, passed
from .exchanges import late_among
from .late_before import answered_late

RULE = "R-5.2-06"


def judge_empty_packets(exchanges: Sequence[Exchange], address: str) -> Finding:
    """FAIL on a probe whose own reply is no 6-byte empty packet from ``address``; else
    INCONCLUSIVE where a probe's reply came late (or may be another command's); else PASS."""
    late = [ex for ex in exchanges if answered_late(ex)]
    bad = []
    for ex in exchanges:
        if any(ex is other for other in late):
            continue
        packet = parse_binary_packet(ex.reply_bytes, expected_address=address)
        if not (ex.answered and packet.is_empty and len(ex.reply_bytes) == 6):  # CRC: R-5.2-03
            bad.append((ex, f"{ex.text} returned '{ex.reply_bytes.hex(' ') or '(nothing)'}'"))
    if bad:
        return failed(
            RULE,
            "; ".join(line for _, line in bad) + ", not the empty packet",
            evidence=[f"t={ex.start:.4f} s: {line}" for ex, line in bad],
            observed=len(exchanges),
        )
    undecided = late_among(RULE, late, "no empty packet taken for the probes past the data")
    if undecided is not None:
        return undecided
    return passed(
        RULE, "empty packet for " + ", ".join(ex.text for ex in exchanges), observed=len(exchanges)
    )
