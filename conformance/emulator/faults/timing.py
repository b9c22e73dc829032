"""Faults in section 7 timing: the reply window, character gaps, breaks, wake-up, standby
and the baud rate, including probes just inside and outside the limits.
"""

from __future__ import annotations

from .model import Fault

#: What a sensor whose every reply starts 80 ms late leaves undecided (replies-after-retry):
#: the tool's 30 ms window and its retry 55 ms after a try miss or meet every reply, so each
#: rule below is INCONCLUSIVE naming the late reply or the reply it rests on; R-7.0-10 alone
#: is broken (truth10-12).
LATE_REPLY_UNDECIDED = (
    # a reply the rule asks for came only after the reply window (met by the retry, or heard
    # by a one-shot probe's longer listen): no "no reply", no lost data, no refused address
    "R-4.3-03",
    "R-4.4-01",
    "R-4.4.4-01",
    "R-4.4.5-03",
    "R-4.4.5.1-02",
    "R-4.4.5.1-03",
    "R-4.4.7-05",
    "R-4.4.8.1-01",
    "R-4.4.8.1-02",
    # aRC2!..aRC9!, the unsupported indices' CRC forms, answered only late (truth19)
    "R-4.4.8.1-03",
    # the retention case's D reads before and after aR0!/aRC0! answered only late, so no
    # pair compared (two silences PASSed "identical"); aIMC_001! answered only late, and no
    # plain D reply after it read in its window (truth21)
    "R-4.4.5-10",
    "R-4.4.12-03",
    # aMC1!..aMC9! and aCC1!..aCC9! answered only late: their start replies' form unread, so
    # the starts read in their windows do not PASS it for them (stop 56)
    "R-4.4.5-01",
    "R-4.4.7-01",
    "R-4.4.9-01",
    "R-4.4.10-01",
    "R-4.4.12-01",
    "R-4.4.12-02",
    "R-5.4-02",
    "R-6.1-01",
    "R-6.2-01",
    "R-6.2-05",
    "R-6.2-06",
    "R-6.2-07",
    "R-7.0-05",
    "R-7.0-07",
    "R-7.0-16",
    "R-7.1-02",
    # 0XHELP!'s multi-line reply met the retry: the rest of it is not framed
    "R-4.2-02",
    "R-4.2-03",
    "R-4.3-01",
    # silence rules whose control, an a! sent once like the probe, was answered late (R-7.0-03's
    # and R-7.0-14's probes and controls are listened to that long: SensorSession.hear_late)
    "R-4.0-01",
    "R-4.3-04",
    "R-4.4.3-02",
    "R-AppB-01",
    # nothing to judge: the replies they rest on (a started measurement, metadata records,
    # extended text) were not taken
    "R-4.4.6-03",
    "R-4.4.7.1-01",
    "R-4.4.7.1-02",
    "R-4.4.13-01",
    "R-4.4.13-02",
    "R-6.2-02",
    "R-6.2-03",
    "R-6.2-04",
    "R-6.2.1-01",
    "R-6.2.2-01",
    # aHA! and aHB! answered only late, their counts unread: high volume not shown absent
    # (undecided, not N/A), and the count rules' starts not all read (aMC1!...)
    "R-4.1-03",
    "R-4.4.8-03",
    "R-4.4.8-04",
    "R-5.1-01",
    "R-5.1-02",
    "R-5.1-03",
    "R-5.2-01",
    "R-5.2-02",
    "R-5.2-03",
    "R-5.2-04",
    "R-5.2-05",
    "R-5.2-06",
    "R-5.2-07",
    "R-5.2.1-01",
    "R-5.3-01",
)

#: Timing.
TIMING: tuple[Fault, ...] = (
    Fault(
        "response-too-early",
        "Replies start 5 ms after the command's last stop bit (limit 7.93 ms).",
        ("R-7.0-09",),
        settings={"reply_delay": 5e-3},
    ),
    Fault(
        "response-too-late",
        "Replies start 20 ms after the command's last stop bit (limit 15.40 ms).",
        ("R-7.0-10",),
        settings={"reply_delay": 20e-3},
    ),
    Fault(
        "replies-after-retry",
        "Replies start 80 ms after the command's last stop bit (limit 15.40 ms), as an Arduino"
        " Due sensor with delay(80) before every reply (docs/kit.md, eighteenth round): the"
        " recorder's retry, 55 ms after an unanswered try, has ended before the reply begins,"
        " which is 8 ms after the retry and 80 ms after the first try; a command heard before"
        " the reply starts (the retry) goes unheard, the firmware being blocked in delay()."
        " It breaks R-7.0-10 alone; the rules whose replies the tool's window and retries"
        " miss or meet are INCONCLUSIVE naming the late reply (LATE_REPLY_UNDECIDED).",
        ("R-7.0-10",),
        settings={"reply_delay": 80e-3, "deaf_until_reply": True},
        inconclusive=LATE_REPLY_UNDECIDED,
    ),
    Fault(
        "inter-char-gap",
        "3 ms of marking between reply characters (limit 1.66 ms)."
        " No two reply characters come back to back, so the bit rate cannot be told from the"
        " gaps (R-4.1-01).",
        ("R-7.0-12",),
        settings={"char_gap": 3e-3},
        inconclusive=("R-4.1-01",),
    ),
    Fault(
        "ident-pause",
        "4 ms of marking before the seventh character of every aI! reply, the rest of the "
        "reply back to back (limit 1.66 ms): a deviation that recurs at the same point of the "
        "same reply, as a firmware that fetches its next field mid-reply makes.",
        ("R-7.0-12",),
        settings={"ident_pause": 4e-3, "ident_pause_at": 6},
    ),
    Fault(
        "stray-after-line-end",
        "A stray '#' 2 ms after the LF of every aD<n>! and aI! reply, as a firmware that"
        " flushes one more byte after a line sends: the reply does not end with CR LF"
        " (R-4.2-03) and the '#' it sent on its own does not start with its address"
        " (R-4.3-01); a recorder that transmits at the turnaround after the LF (9 ms after"
        " its stamp, issue 22) would talk over it.",
        ("R-4.2-03", "R-4.3-01"),
        settings={"stray_after_line_end": 2e-3},
    ),
    Fault(
        "ignores-short-breaks",
        "Spacing under 12.9 ms is not taken as a break (a 12.5 ms break goes unseen).",
        ("R-7.0-04",),
        settings={"break_threshold": 12.9e-3},
    ),
    Fault(
        "wakes-on-short-spacing",
        "Spacing of 4 ms or more counts as a break, so a 5 ms pulse wakes the sensor.",
        ("R-7.0-03",),
        settings={"break_threshold": 4e-3},
    ),
    Fault(
        "early-address",
        "An address right after the break is accepted (no 8.33 ms of marking needed).",
        ("R-7.0-05",),
        settings={"address_marking": 0.0},
    ),
    Fault(
        "late-address-after-break",
        "After a break the sensor needs 20 ms of marking before it looks for an address. The"
        " probes sent 9 ms after a hand-made break (the 5 ms pulse's, the cut aI!) go unheard,"
        " and so do their controls: R-7.0-03 and R-AppB-01 stay undecided (precondition"
        " listening not met), never a PASS on silence it never heard.",
        ("R-7.0-05",),
        settings={"address_marking": 20e-3},
        inconclusive=("R-7.0-03", "R-AppB-01"),
    ),
    Fault(
        "slow-wake",
        "The sensor needs 110 ms after a break before it can see a start bit. The probes"
        " sent 9 ms after a hand-made break (the 5 ms pulse's, the cut aI!) go unheard, and so"
        " do their controls: R-7.0-03 and R-AppB-01 stay undecided (precondition listening"
        " not met), never a PASS on silence it never heard.",
        ("R-7.0-07", "R-7.0-05"),
        settings={"wake_delay": 110e-3},
        inconclusive=("R-7.0-03", "R-AppB-01"),
    ),
    Fault(
        "slow-wake-every-other",
        "After every second break the sensor needs 110 ms before it can see a start bit;"
        " after the others it wakes at once (it wakes late only every other time). Each"
        " wake-up rule probes two wakes in a row, one of which is slow.",
        ("R-7.0-07", "R-7.0-05"),
        settings={"wake_delay": 110e-3, "wake_every_other": True},
        # the controls sent "one break, then once" beside these probes land on slow wakes;
        # a silent probe's control goes at two wakes in a row (truth36), one of them slow
        inconclusive=("R-4.3-04", "R-4.4.3-02", "R-4.4.4-03", "R-AppB-01"),
        masks={"slow-wake": "slow-wake is the same slow wake after every break, not every other"},
    ),
    Fault(
        "standby-ignored",
        "The sensor never drops to standby by itself: it answers after any marking.",
        ("R-7.0-15",),
        settings={"standby_marking": float("inf")},
    ),
    Fault(
        "no-follow-up-without-break",
        "After each reply the sensor needs a break again (follow-ups within 87 ms fail)."
        " Its silence to a! after a command for another address is then no sign of that"
        " command's standby (R-7.0-14: the control a! sent as late is unanswered too)."
        " Its aI! into a running concurrent measurement is answered only after a break of"
        " the tool's, which may as well be what aborted it (R-4.4.7.1-01/02).",
        ("R-7.0-16",),
        settings={"standby_after_reply": True},
        inconclusive=("R-7.0-14", "R-4.4.7.1-01", "R-4.4.7.1-02"),
    ),
    Fault(
        "deaf-after-service-request",
        "After its service request the sensor needs a break before aD0!.",
        ("R-7.1-02",),
        settings={"standby_after_service_request": True},
    ),
    Fault(
        "partial-command-accepted",
        "Marking inside a command never drops it: a command with an 8.33 ms gap is answered.",
        ("R-AppB-01",),
        settings={"partial_gap": float("inf")},
    ),
    Fault(
        "stays-awake-after-foreign",
        "A command to another address does not send the sensor to standby.",
        ("R-7.0-14",),
        settings={"standby_after_foreign": False},
    ),
)


#: Added to complete the sensor-role coverage: the baud rate.
COVERAGE_BAUD: tuple[Fault, ...] = (
    Fault(
        "fast-baud",
        "Replies go out at 1300 baud: each character takes 7.69 ms instead of 8.33 ms.",
        ("R-4.1-01",),
        settings={"char_time": 10 / 1300},
    ),
)


#: Added to complete the sensor-role coverage: the gap that has no tolerance.
COVERAGE_GAP: tuple[Fault, ...] = (
    Fault(
        "inter-char-gap-tolerance",
        "1.9 ms of marking between reply characters: inside 1.66 + 0.40 ms, but that gap "
        "has no tolerance."
        " No two reply characters come back to back, so the bit rate cannot be told from the"
        " gaps (R-4.1-01).",
        ("R-7.0-12", "R-7.0-01"),
        settings={"char_gap": 1.9e-3},
        inconclusive=("R-4.1-01",),
    ),
)


#: Timing just inside the limits (boundary probes, issue 10).
BOUNDARIES: tuple[Fault, ...] = (
    Fault(
        "standby-after-40ms",
        "The sensor drops to standby 40 ms after its last reply, not 100 ms: a follow-up "
        "without a break at 40..87 ms goes unanswered, so its silence to a! after a command"
        " for another address shows no standby of that command's (R-7.0-14). Its aI! into a"
        " running concurrent measurement is answered only after a break of the tool's, which"
        " may as well be what aborted it (R-4.4.7.1-01/02).",
        ("R-7.0-16",),
        settings={"standby_after_reply_marking": 40e-3},
        inconclusive=("R-7.0-14", "R-4.4.7.1-01", "R-4.4.7.1-02"),
    ),
    Fault(
        "standby-after-60ms",
        "The sensor drops to standby 60 ms after its last reply, not 100 ms; a! after a"
        " command for another address comes later than that, so its silence there shows no"
        " standby of that command's (R-7.0-14).",
        ("R-7.0-16",),
        settings={"standby_after_reply_marking": 60e-3},
        inconclusive=("R-7.0-14",),
    ),
    Fault(
        "standby-after-108ms",
        "The sensor stays awake for 108 ms of marking (100 ms + 0.40 ms are allowed).",
        ("R-7.0-15",),
        settings={"standby_marking": 108e-3},
    ),
)


#: A break from the sensor (docs/kit.md, twenty-fifth round): what the sim bus's sensor break
#: (``sim.bus.BreakFrame``) shows in a fault-matrix row.
SENSOR_BREAK: tuple[Fault, ...] = (
    Fault(
        "break-before-reply",
        "The sensor holds the line spacing 12.1 ms from the end of every command it answers"
        " (a break of its own), marks 8.4 ms and replies 20.5 ms after the command, as the"
        " 2013 Arduino-SDI-12 library's sendCommand -> wakeSensors() does on a sensor built"
        " as a recorder (the AgriApps sketch, docs/kit.md twenty-fifth round): no 8.33 ms"
        " of marking before its first spacing (R-7.0-09, a recorder's UART reads a start"
        " bit there) and its reply's first start bit past 15.40 ms (R-7.0-10).",
        ("R-7.0-09", "R-7.0-10"),
        settings={"break_before_reply": 12.1e-3, "reply_delay": 20.5e-3},
    ),
)
