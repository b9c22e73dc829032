"""The emulator's tunable behaviour: section 7 timing numbers and behaviour switches.

Every knob a fault can turn lives here with its conforming default, so the emulator's code
reads one object instead of asking "is fault X active?" all over the place, and a fault is
mostly a set of overrides (see :mod:`conformance.emulator.faults`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..protocol.commands import HIGH_VOLUME_DATA_INDEX_MAX
from ..protocol.timing import (
    CHAR_TIME,
    MARKING_AFTER_BREAK,
    PARTIAL_COMMAND_GAP,
    STANDBY_MARKING,
    TOLERANCE,
)
from ..protocol.values import VALUES_MAX, VALUES_MAX_MEASURE

#: Spacing at least this long is a break. R-7.0-03 forbids seeing a break under 6.5 ms and
#: R-7.0-04 demands one above 12 ms; 9 ms sits in the middle, clear of both tolerances.
BREAK_THRESHOLD = 9e-3
#: First response start bit after the command's last stop bit: 8.33 ms of marking plus a
#: margin (window 7.93..15.40 ms, R-7.0-09/10).
REPLY_DELAY = 9.0e-3


@dataclass(frozen=True)
class Behaviour:
    """Every knob of the reference sensor's behaviour (timing, replies, measurements), at a
    conforming value by default; a fault is a change of one or more of them."""

    # -- receiving (section 7) ---------------------------------------------------------------
    break_threshold: float = BREAK_THRESHOLD
    # Marking needed after a break before a start bit counts as an address (R-7.0-05). The
    # lower tolerance edge, so a recorder that waits exactly 8.33 ms is never refused.
    address_marking: float = MARKING_AFTER_BREAK - TOLERANCE
    # Time after a break before the sensor can see start bits at all (R-7.0-07 allows 100 ms).
    wake_delay: float = 0.0
    #: ``wake_delay`` after every second break only (the first, third ... wake at once): a
    #: firmware whose slow wake-up depends on a state the breaks toggle (a regulator, a
    #: sleep mode entered every other time)
    wake_every_other: bool = False
    # Marking inside a command that drops it (R-AppB-01), again at the lower tolerance edge.
    partial_gap: float = PARTIAL_COMMAND_GAP - TOLERANCE
    standby_marking: float = STANDBY_MARKING  # R-7.0-15
    standby_after_foreign: bool = True  # R-7.0-14
    standby_after_reply: bool = False  # True breaks R-7.0-16
    standby_after_reply_marking: float | None = None  # < 87 ms breaks R-7.0-16
    standby_after_service_request: bool = False  # True breaks R-7.1-02
    # -- transmitting ------------------------------------------------------------------------
    reply_delay: float = REPLY_DELAY
    #: Spacing (s) the sensor holds from the command's end before its reply to it (0: none),
    #: the reply's first start bit still ``reply_delay`` after the command's end: firmware
    #: that "wakes the sensors" before every reply as a data recorder would (the 2013
    #: Arduino-SDI-12 library's ``sendCommand`` -> ``wakeSensors()``, 12.1 ms: docs/kit.md,
    #: twenty-fourth and twenty-fifth rounds). Only a reply's first line (multi-line text's
    #: later lines and service requests answer no command just ended).
    break_before_reply: float = 0.0
    char_gap: float = 0.0  # marking between reply characters (R-7.0-12)
    #: Hear no command between a command and the start of its reply: a firmware blocked in
    #: delay() before it replies (the Arduino Due sensor, docs/kit.md eighteenth round)
    deaf_until_reply: bool = False
    #: Extra marking before one character of every aI! reply (R-7.0-12): a firmware that
    #: pauses at the same point of the same reply, as it fetches the next field, say.
    ident_pause: float = 0.0
    ident_pause_at: int = 6  # the index of the character the pause comes before
    #: A stray character sent this long (s) after the LF of every aD<n>! and aI! reply
    #: (None: nothing), as a firmware that flushes one more byte from its UART after a line
    #: makes: the reply then does not end with CR LF (R-4.2-03), and a recorder that
    #: transmits at the turnaround after the LF talks over it (issue 22's risk, eff12).
    stray_after_line_end: float | None = None
    stray_char: str = "#"
    char_time: float = CHAR_TIME  # one 10-bit frame: 1200 baud (R-4.1-01)
    line_gap: float = 20e-3  # marking between the lines of multi-line text (R-4.4.13.1-03)
    line_limit: int | None = None  # cut multi-line text lines to this (None: as written)
    etx: bool = True  # ETX after the last line of multi-line text (R-4.4.13.1-01)
    # -- addressing --------------------------------------------------------------------------
    answer_foreign: bool = False  # answer a!/aI! for any address (breaks R-4.0-01)
    #: Answer a command for another address whose character before '!' is this sensor's
    #: address as if it were a! (breaks R-4.0-01): a parser fed one character at a time that
    #: starts over at its address, as the lagopus sketch on EnviroDIY's library answers 0M5!
    #: at '5' (docs/kit.md, sixteenth round).
    answer_trailing_address: bool = False
    answer_query: bool = True
    apply_address_change: bool = True
    accept_any_new_address: bool = False  # take aA$! too (breaks R-4.3-04, decision A17)
    wildcard_answer: bool = False  # answer ?I! and the like with a bare address (R-4.4.3-02)
    answer_old_address: bool = False
    address_change_ignores_tail: bool = False  # take aAbX..! as aAb! (real firmware, A12)
    # -- service requests --------------------------------------------------------------------
    service_request: bool = True
    #: Firmware that measures at once yet announces a short ttt: the M family and V announce
    #: this ttt (s, e.g. 1 for ``001``) when theirs is > 0; with :attr:`ready_after` their
    #: data (and service request) come that long after the ``atttn`` reply. Legal
    #: (R-4.4.6-02/04, and within R-4.4.5-09's margin); issue 18 saw a request 8.4 ms after
    #: the reply, where a recorder that does not listen before it talks starts its next break
    #: into it.
    announce_ttt: int | None = None
    service_request_late: float | None = None  # send it this long after ttt instead
    #: Send it this long after ttt instead, but only for an M/V command this sensor has
    #: measured before since power-up: the first of each is in time (a late request the
    #: run's cached measurements never see, only the cases that measure again: truth31).
    service_request_late_repeated: float | None = None
    service_request_on_ttt_zero: bool = False
    service_request_on_concurrent: bool = False
    service_request_on_identify: bool = False
    chatter_before_service_request: bool = False
    #: A quirk: every M/V measurement with ttt > 0 is ready this long (s) after its reply,
    #: however long its ttt (legal: the service request may come any time before ttt).
    ready_after: float | None = None
    # -- aborts ------------------------------------------------------------------------------
    break_aborts_measure: bool = True  # R-4.4.5.1-01
    abort_keeps_old_data: bool = False  # True breaks R-4.4.5.1-02 / R-4.4.7.1-02
    deaf_after_abort: bool = False
    #: Text (after the address) a faulty firmware sends unasked when a measurement a break
    #: aborted would have been ready ("" for the reference: nothing).
    abort_reply: str = ""
    break_aborts_concurrent: bool = False  # True breaks R-4.4.7-05
    foreign_aborts_concurrent: bool = False  # True breaks R-4.4.7-05
    #: A bus of several sensors only: another sensor's reply (a line ending CR LF, which no
    #: command ends with) heard while a concurrent measurement runs drops it (R-4.4.7-05) or
    #: is answered with this sensor's address as if it were a command to it (R-4.0-01).
    foreign_reply_aborts_concurrent: bool = False
    answer_foreign_reply: bool = False
    command_aborts_concurrent: bool = True  # R-4.4.7.1-01
    # -- data buffer -------------------------------------------------------------------------
    clear_on_break_after_read: bool = False
    clear_after_read: bool = False
    clear_on_standby_after_read: bool = False
    identify_clears_data: bool = False
    undefined_group_keeps_data: bool = False  # a0000 for aMn! leaves the old D buffer
    continuous_overwrites_data: bool = False  # aRn!/aRCn! replace the D buffer
    metadata_crc_sticks: bool = False  # after aIMC_nnn!, plain D replies carry a CRC
    # -- data replies ------------------------------------------------------------------------
    limit_measure: int = VALUES_MAX_MEASURE  # <values> characters per D reply after M/V
    limit_concurrent: int = VALUES_MAX  # after C (R-4.4-05)
    limit_high_volume: int = VALUES_MAX  # after HA (R-5.1-03)
    pack_slack: int = 0  # values left out of each full M/V reply (R-4.4.8.3-03)
    split_values: bool = False  # fill M/V replies to the limit, cutting a value
    drop_all_values: bool = False  # a completed measurement holds no values
    #: An M command (the M family) this sensor has measured before since power-up announces
    #: its count in full but leaves its last value out of the data; the first of each
    #: delivers all (a short count only the cases that measure again see: truth35).
    fewer_values_repeated: bool = False
    max_data_index: int = HIGH_VOLUME_DATA_INDEX_MAX  # highest D index served after HA
    groups_from_d1: bool = False  # M/V data start at D1, D0 empty (R-4.4.8.3-02)
    # -- other commands ----------------------------------------------------------------------
    continuous_needs_r0: bool = False
    answer_undefined_measure: bool = True
    answer_undefined_concurrent: bool = True
    answer_identify_measurement: bool = True
    metadata_invalid_reply: bool = True
    empty_packet: bool = True
    #: Text (after the address) a faulty firmware sends instead of the empty reply or the
    #: silence the reference gives a command it does not serve ("" for the reference).
    unknown_reply: str = ""
