"""Timing constants of SDI-12 section 7 (v1.3 section 5), in seconds.

Kept in one place so that the emulator, the tool recorder and the judges can never disagree
about a limit. Every value carries the spec's +/-0.40 ms tolerance (R-7.0-01) unless noted;
the tolerance is applied by the judges, never folded into the constants.
"""

from __future__ import annotations

BAUD = 1200
BITS_PER_FRAME = 10  # start + 7 data + parity + stop (7E1), or start + 8 data + stop (8N1)
CHAR_TIME = BITS_PER_FRAME / BAUD  # 8.333 ms: one character on the wire
BIT_TIME = 1 / BAUD  # 0.833 ms: one bit (a capture decoder and a spacing probe count in bits)

TOLERANCE = 0.40e-3  # R-7.0-01: +/-0.40 ms on every limit that does not say otherwise

BREAK_MIN = 12e-3  # R-7.0-02: a recorder's break is at least 12 ms of spacing
BREAK_ALWAYS = 12e-3  # R-7.0-04: spacing longer than this is always a break for a sensor
BREAK_NEVER = 6.5e-3  # R-7.0-03: spacing shorter than this is never a break
MARKING_AFTER_BREAK = CHAR_TIME  # R-7.0-05/06: 8.33 ms of marking after a break
WAKE_LIMIT = 100e-3  # R-7.0-07: a sensor can detect a start bit within 100 ms of the break
RESPONSE_START_MIN = CHAR_TIME - TOLERANCE  # R-7.0-09: 8.33 ms of marking first, so 7.93 ms
RESPONSE_START_MAX = 15.0e-3  # R-7.0-10: latest first response start bit (+0.40 ms)
RELEASE_LINE = 7.5e-3  # R-7.0-08/11: release the line after the last stop bit
INTER_CHAR_GAP_MAX = 1.66e-3  # R-7.0-12/13: marking between characters, no tolerance
STANDBY_MARKING = 100e-3  # R-7.0-15: after 100 ms of marking a sensor is in standby
NO_BREAK_WINDOW = 87e-3  # R-7.0-16/17, R-7.1-01: follow-up without break only within 87 ms
RETRY_MIN = 16.67e-3  # R-7.2-02: earliest retry after the command's last stop bit
RETRY_MAX = 87e-3  # R-7.2-02: latest retry without a break
RETRY_AFTER_BREAK = 100e-3  # R-7.2-03: one retry starts more than 100 ms after the break
PARTIAL_COMMAND_GAP = CHAR_TIME  # R-AppB-01: 8.33 ms marking inside a command drops it
ADDRESS_CHANGE_QUIET = 1.0  # R-4.4.4-02: a sensor may ignore commands for 1 s after aAb!
MULTILINE_GAP_MAX = 150e-3  # R-4.4.13.1-03: at most 150 ms between lines of multi-line text


def frames(count: int) -> float:
    """Wire time of ``count`` back-to-back characters."""
    return count * CHAR_TIME
