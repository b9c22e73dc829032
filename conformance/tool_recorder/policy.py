"""The engine's timing and patience choices, in seconds, kept apart from the rules.

Section 7 gives windows (break >= 12 ms, retry 16.67-87 ms after the command...); a recorder
must pick a point inside each. Those points live here so that the same engine can be a strict
"golden recorder" (recorder role) or a patient observer that waits a little longer so a late
or broken sensor leaves evidence instead of being missed (sensor role).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..protocol.timing import CHAR_TIME, MULTILINE_GAP_MAX, RETRY_MAX, TOLERANCE


@dataclass(frozen=True)
class Policy:
    """How the tool's recorder times its stimuli: each figure sits inside its section 7 limit
    with a margin, so a link's own latency cannot push the tool out of spec."""

    # R-7.0-02: >= 12 ms of spacing; 12 + 0.4 tolerance + margin.
    break_duration: float = 13e-3
    # R-7.0-06: >= 8.33 ms of marking after the break before the first start bit.
    post_break_marking: float = 9e-3
    # How far inside the 87 ms no-break window (R-7.0-17, R-7.1-01, R-7.2-02) the engine
    # stays, so a link's own latency cannot push a follow-up past the limit.
    window_margin: float = 3e-3
    # Marking the engine leaves after the DUT's last character before it drives the line:
    # the DUT may hold the line for 7.5 ms (+0.4) after its last stop bit (R-7.0-11).
    turnaround: float = 9e-3
    # Listen before talk: the longest the engine holds a break or command while the DUT keeps
    # the line active (a babbling DUT must not hang the tool); past it the engine transmits
    # anyway and says so in a NOTE. Longer than any legal reply (75 values: 0.7 s).
    max_hold: float = 1.0
    # Wait for the first reply start bit. The spec's limit is 15.4 ms (R-7.0-10); the engine
    # listens longer so a late reply is recorded (and judged late) rather than missed. Must
    # stay below RETRY_MAX so a retry can still follow within 87 ms.
    first_char_timeout: float = 30e-3
    # Marking after a reply character that ends the attempt. 7.2 makes 8.33 ms a retry
    # trigger; observing longer records a reply that resumes after a pause.
    reply_idle: float = 50e-3
    # Bounds so a babbling DUT cannot hang the engine.
    max_reply_chars: int = 300
    max_binary_bytes: int = 1010
    # Multi-line extended replies (a<STX>...<ETX>, 4.4.13.1) may be long help texts.
    max_text_chars: int = 4000
    # Where inside the 16.67-87 ms retry window the retry goes: this long after the end of
    # the invalid reply or of the first-character timeout (R-7.2-02, R-7.2-06).
    retry_gap: float = 25e-3
    # R-7.2-03/04: retries per sequence, and how many break+command+retries sequences.
    retries_per_sequence: int = 2
    sequences: int = 3
    # Wait for the next line of multi-line text (R-4.4.13.1-04 says 150 ms; an observer waits
    # longer so lines that come late are evidence, not lost).
    line_wait: float = 0.5
    # Listen this long past ttt for a late service request before breaking for D0.
    late_sr_grace: float = 0.5
    # Extra wait past ttt before breaking for D0 without a service request (R-4.4.5-04,
    # R-4.4.7-06 say "at least ttt").
    ttt_margin: float = 5e-3
    # Observer mode (sensor role): when every retry still drew an invalid reply, read what
    # the last one holds (ttt/count, values, packet values) and carry on, so one broken rule
    # (a wrong CRC, a missing CR LF) leaves evidence for its own judge instead of starving
    # every other judge of data. The golden recorder does not salvage.
    salvage: bool = True

    def __post_init__(self) -> None:
        if self.first_char_timeout + self.window_margin >= RETRY_MAX:
            raise ValueError("first_char_timeout leaves no room for a retry within 87 ms")
        if self.retries_per_sequence < 0 or self.sequences < 1:
            raise ValueError("need at least one sequence and no negative retry count")

    @classmethod
    def golden(cls) -> Policy:
        """The recorder as the standard describes it: 8.33 ms marking inside a reply ends
        it (R-7.2-05) and D0 follows ttt without extra grace (R-4.4.5-05)."""
        return cls(
            reply_idle=CHAR_TIME + TOLERANCE,
            late_sr_grace=0.0,
            first_char_timeout=20e-3,
            salvage=False,
            line_wait=MULTILINE_GAP_MAX + TOLERANCE,
        )

    def but(self, **changes: object) -> Policy:
        """A copy with some fields changed (``Policy().but(sequences=1)``)."""
        return replace(self, **changes)  # type: ignore[arg-type]
