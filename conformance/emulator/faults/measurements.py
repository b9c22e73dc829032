"""Faults in measurements: service requests, aborts, the data buffer, counts and data
indices (4.4.5 to 4.4.11).
"""

from __future__ import annotations

import re
from dataclasses import replace

from ...protocol.commands import Kind
from ...protocol.version import V13
from ..profile import MeasurementSpec
from ..replies import Reply, ReplyKind
from .edits import (
    DATA_REPLIES,
    has_values,
    only,
    silence,
    source_kind,
    when,
    with_spec,
)
from .model import Fault


def _vary_repeat(reply: Reply) -> Reply:
    if reply.repeat == 0 or not has_values(reply):
        return reply
    match = re.search(r"[0-9](?=[^0-9]*$)", reply.body)
    if match is None:
        return reply
    i = match.start()
    digit = str((int(reply.body[i]) + reply.repeat) % 10)
    return replace(reply, body=reply.body[:i] + digit + reply.body[i + 1 :])


def _later_m2_data(reply: Reply) -> bool:
    source, cmd = reply.source, reply.command
    return (
        reply.kind is ReplyKind.DATA
        and source is not None
        and cmd is not None
        and source.kind is Kind.MEASURE
        and source.group == 2
        and cmd.index >= 1
    )


def _plain_c(reply: Reply) -> bool:
    cmd = reply.command
    return (
        reply.kind is ReplyKind.START
        and cmd is not None
        and cmd.kind is Kind.CONCURRENT
        and not cmd.crc
        and cmd.group == 0
    )


def _verify_sr(reply: Reply) -> bool:
    return reply.kind is ReplyKind.SERVICE_REQUEST and source_kind(reply) is Kind.VERIFY


def _overstated_ttt(spec: MeasurementSpec) -> MeasurementSpec:
    return replace(spec, ttt=10)


def _v13_wide_concurrent(spec: MeasurementSpec) -> MeasurementSpec:
    values = tuple(f"+{i}" for i in range(25))
    return replace(spec, values=values, metadata=tuple(("XC", " ") for _ in values))


#: Service requests.
SERVICE_REQUESTS: tuple[Fault, ...] = (
    Fault(
        "no-service-request",
        "M/MC/Mn/V with ttt > 0 never send a service request (data are ready before ttt)."
        " With no service request its form and timing cannot be judged, nor can a break be"
        " shown to abort one (R-4.4.5.1-01) and what follows an abort (-02, -03) be judged.",
        ("R-4.4.6-02",),
        settings={"service_request": False},
        inconclusive=(
            "R-4.4.5-09",
            "R-4.4.5.1-01",
            "R-4.4.5.1-02",
            "R-4.4.5.1-03",
            "R-4.4.6-01",
            "R-4.4.6-04",
        ),
    ),
    Fault(
        "late-service-request",
        "The service request comes 0.25 s after ttt expired (data were ready in time).",
        ("R-4.4.6-04",),
        settings={"service_request_late": 0.25},
    ),
    Fault(
        "late-service-request-when-repeated",
        "An M/V command measured before since power-up sends its service request 0.25 s"
        " after ttt expired; the first of each comes in time (only a case that measures"
        " again sees it late: truth31).",
        ("R-4.4.6-04",),
        settings={"service_request_late_repeated": 0.25},
    ),
    Fault(
        "service-request-after-ttt-zero",
        "M/V answered with ttt = 000 still send a service request right after the reply.",
        ("R-4.4.6-03",),
        settings={"service_request_on_ttt_zero": True},
    ),
    Fault(
        "concurrent-service-request",
        "C/CC/Cn/HA/HB send a service request when their data are ready.",
        ("R-4.4.6-05", "R-4.4.7-04", "R-5.3-01"),
        settings={"service_request_on_concurrent": True},
    ),
    Fault(
        "service-request-extra-chars",
        "The service request is 'aSR<CR><LF>' instead of 'a<CR><LF>'."
        " The service request is not recognised, so a break cannot be shown to prevent one"
        " (R-4.4.5.1-01), nor what follows an abort be judged (-02, -03).",
        ("R-4.4.6-01",),
        rewrite=only([ReplyKind.SERVICE_REQUEST], lambda r: replace(r, body=r.body + "SR")),
        inconclusive=("R-4.4.5.1-01", "R-4.4.5.1-02", "R-4.4.5.1-03"),
    ),
    Fault(
        "chatter-before-service-request",
        "Halfway between atttn and the service request the sensor sends 'aBUSY<CR><LF>'.",
        ("R-4.4.5-08",),
        settings={"chatter_before_service_request": True},
    ),
    Fault(
        "identify-sends-service-request",
        "aIM!/aIV! (and numbered forms) are followed by a service request as if measuring.",
        ("R-6.1-03",),
        settings={"service_request_on_identify": True},
        needs=("v1.4",),
    ),
)


#: Aborts.
ABORTS: tuple[Fault, ...] = (
    Fault(
        "break-does-not-abort-measure",
        "A break during M/V keeps the measurement running; SR and data follow as usual."
        " With no abort shown, what follows an abort (R-4.4.5.1-02, -03) cannot be judged.",
        ("R-4.4.5.1-01",),
        settings={"break_aborts_measure": False},
        inconclusive=("R-4.4.5.1-02", "R-4.4.5.1-03"),
    ),
    Fault(
        "abort-keeps-old-data",
        "After an abort, D returns the data of the measurement before the aborted one.",
        ("R-4.4.5.1-02", "R-4.4.7.1-02", "R-4.4.7.1-01", "R-5.3-01"),
        settings={"abort_keeps_old_data": True},
    ),
    Fault(
        "no-recovery-after-abort",
        "After an abort the sensor ignores everything until the next break after the aborting one.",
        ("R-4.4.5.1-03",),
        settings={"deaf_after_abort": True},
    ),
    Fault(
        "break-aborts-concurrent",
        "A break aborts a running C/CC/HA/HB measurement (D then returns nothing).",
        ("R-4.4.7-05", "R-5.3-01"),
        settings={"break_aborts_concurrent": True},
    ),
    Fault(
        "foreign-command-aborts-concurrent",
        "A command to another address aborts a running C/CC/HA/HB measurement.",
        ("R-4.4.7-05", "R-5.3-01"),
        settings={"foreign_aborts_concurrent": True},
    ),
    Fault(
        "concurrent-not-aborted",
        "A valid command to the sensor does not abort its running concurrent measurement.",
        ("R-4.4.7.1-01", "R-4.4.7.1-02", "R-5.3-01"),
        settings={"command_aborts_concurrent": False},
    ),
)


#: Data buffer.
DATA_BUFFER: tuple[Fault, ...] = (
    Fault(
        "buffer-cleared-by-break",
        "Once all D pages were read, the next break empties the data buffer."
        " Data that do not survive a plain re-read leave nothing for the identify commands"
        " to disturb (R-6.1-03), nor an empty D0 after an abort to show the abort emptied"
        " them (R-4.4.5.1-02, R-4.4.7.1-02, R-5.3-01).",
        ("R-4.4.5-10",),
        settings={"clear_on_break_after_read": True},
        inconclusive=("R-6.1-03", "R-4.4.5.1-02", "R-4.4.7.1-02", "R-5.3-01"),
    ),
    Fault(
        "buffer-cleared-after-read",
        "Once all D pages were read, the buffer is empty (repeated D returns nothing)."
        " Data that do not survive a plain re-read leave nothing for the identify commands"
        " to disturb (R-6.1-03), nor an empty D0 after an abort to show the abort emptied"
        " them (R-4.4.5.1-02, R-4.4.7.1-02, R-5.3-01).",
        ("R-4.4.5-10",),
        settings={"clear_after_read": True},
        inconclusive=("R-6.1-03", "R-4.4.5.1-02", "R-4.4.7.1-02", "R-5.3-01"),
    ),
    Fault(
        "data-changes-on-repeat",
        "A repeated Dn returns the last digit changed."
        " Data that do not survive a plain re-read leave nothing for the identify commands"
        " to disturb (R-6.1-03).",
        ("R-4.4.5-10",),
        rewrite=only(DATA_REPLIES, _vary_repeat),
        inconclusive=("R-6.1-03",),
    ),
    Fault(
        "data-lost-after-standby",
        "Once all D pages were read, entering standby empties the data buffer."
        " Data that do not survive a plain re-read leave nothing for the identify commands"
        " to disturb (R-6.1-03), nor an empty D0 after an abort to show the abort emptied"
        " them (R-4.4.5.1-02, R-4.4.7.1-02, R-5.3-01).",
        ("R-4.4.5-10",),
        settings={"clear_on_standby_after_read": True},
        inconclusive=("R-6.1-03", "R-4.4.5.1-02", "R-4.4.7.1-02", "R-5.3-01"),
    ),
    Fault(
        "identify-clears-buffer",
        "Identify-measurement commands (aIM!, aIC!...) empty the data buffer.",
        ("R-6.1-03",),
        settings={"identify_clears_data": True},
        needs=("v1.4",),
    ),
)


#: Counts.
COUNTS: tuple[Fault, ...] = (
    Fault(
        "fewer-values-than-announced",
        "aM! announces 3 values but D returns 2.",
        ("R-4.4.8-03",),
        profile=with_spec("M", lambda s: replace(s, values=s.values[:-1], announced=3)),
        replaces="the count aM! announces against the values it delivers",
    ),
    Fault(
        "fewer-values-when-repeated",
        "An M command (aM!, aMC!, aMn!...) of two or more values measured before since"
        " power-up announces its count in full and delivers one value fewer; the first of"
        " each delivers all (only a case that measures again sees the count fall short:"
        " truth35).",
        ("R-4.4.8-03",),
        settings={"fewer_values_repeated": True},
    ),
    Fault(
        "more-values-than-announced",
        "aM! announces 3 values but D returns 4.",
        ("R-4.4.8-03",),
        profile=with_spec("M", lambda s: replace(s, values=(*s.values, "+1"), announced=3)),
        replaces="the count aM! announces against the values it delivers",
    ),
    Fault(
        "d0-empty",
        "Completed measurements hold no values: D0 answers 'a<CR><LF>'."
        " With no values delivered, neither a disturbed concurrent or high-volume measurement"
        " (R-4.4.7-05, R-5.3-01)"
        " nor data the identify commands could disturb (R-6.1-03) can be compared; nor is there"
        " a value whose format, length or grouping could be judged (R-4.4.8-02, R-4.4-05,"
        " R-4.4.8.3-01..03: precondition buffered not met, where an empty D reply once PASSed),"
        " nor a buffer whose values a repeated D0 could show kept or lost (R-4.4.5-10);"
        " nor, after aHA!, a reply's length or a D past D9 (R-5.1-02, R-5.1-03), nor, after"
        " aHB!, a payload (R-5.2-04, R-5.2-05: all PASSed on the empty replies, seeds"
        " 4100, 4104). Nor has a break's abort data to keep: D0 after it is empty whatever the"
        " sensor does with its buffer (R-4.4.5.1-02, seed 4227).",
        ("R-4.4.8-04", "R-4.4.8-03", "R-4.4.5-03", "R-5.2-07"),
        settings={"drop_all_values": True},
        inconclusive=(
            "R-4.4.5-10",
            "R-4.4.7-05",
            "R-6.1-03",
            "R-5.3-01",
            "R-4.4.8-02",
            "R-4.4-05",
            "R-4.4.8.3-01",
            "R-4.4.8.3-02",
            "R-4.4.8.3-03",
            "R-5.1-02",
            "R-5.1-03",
            "R-5.2-04",
            "R-5.2-05",
            "R-4.4.5.1-02",
        ),
    ),
    Fault(
        "undefined-measure-silent",
        "Undefined aMn!/aMCn! get no answer instead of a0000.",
        ("R-4.4.9-01", "R-4.4.9-02", "R-4.4-01", "R-4.4.12-01", "R-6.1-01"),
        settings={"answer_undefined_measure": False},
    ),
    Fault(
        "undefined-concurrent-silent",
        "Undefined aCn!/aCCn! get no answer instead of a00000.",
        ("R-4.4.10-01", "R-4.4.10-02", "R-4.4-01", "R-4.4.12-01", "R-6.1-01"),
        settings={"answer_undefined_concurrent": False},
    ),
    Fault(
        "high-volume-stops-at-d9",
        "After HA, aD10! and higher get no answer, so values past D9 cannot be read.",
        ("R-5.1-02", "R-4.4.8-03"),
        settings={"max_data_index": 9},
        needs=("HA",),
    ),
    Fault(
        "continuous-needs-r0-first",
        "aRn! (n > 0) answers as unsupported unless aR0! was the previous command.",
        ("R-4.4.8.1-02",),
        settings={"continuous_needs_r0": True},
    ),
)


#: Added to complete the sensor-role coverage: data replies after aM2!.
COVERAGE_DATA: tuple[Fault, ...] = (
    Fault(
        "m2-later-data-silent",
        "After aM2!/aMC2! the sensor answers aD0! but not aD1! and later; whether D0 cut a"
        " value, or left room for D1's first, is then unread (R-4.4.8.3-01, -03; seed 4099).",
        ("R-4.4.8-01", "R-4.4.8-03"),
        rewrite=when(_later_m2_data, silence),
        inconclusive=("R-4.4.8.3-01", "R-4.4.8.3-03"),
    ),
)


#: Added to complete the sensor-role coverage: ttt, aC!, D0 and aV!.
COVERAGE: tuple[Fault, ...] = (
    Fault(
        "ttt-overstated",
        "aM! announces ttt = 10 s but the data are ready (and the SR sent) after 1.5 s.",
        ("R-4.4.5-09",),
        profile=with_spec("M", _overstated_ttt),
    ),
    Fault(
        "concurrent-unsupported",
        "aC! gets no answer (the CRC and numbered variants still work).",
        ("R-4.4.7-08", "R-4.4-01"),
        rewrite=when(_plain_c, silence),
    ),
    Fault(
        "groups-start-at-d1",
        "M/V data start at D1; D0 answers with no values.",
        ("R-4.4.8.3-02", "R-4.4.8-04", "R-4.4.5-03"),
        settings={"groups_from_d1": True},
    ),
    Fault(
        "verify-no-service-request",
        "aV! never sends its service request (aM! does).",
        ("R-4.4.6-02", "R-4.4.11-01"),
        rewrite=when(_verify_sr, silence),
    ),
)


#: Found on a third-party sensor (issue 10): an undefined group and the data buffer.
THIRD_PARTY_GROUPS: tuple[Fault, ...] = (
    Fault(
        "undefined-group-keeps-data",
        "aMn! for an undefined group answers a0000 but leaves the previous measurement's "
        "values in D0.",
        ("R-4.4.8-03",),
        settings={"undefined_group_keeps_data": True},
    ),
)


#: Found on a third-party sensor (issue 10): R and the data buffer.
THIRD_PARTY_BUFFER: tuple[Fault, ...] = (
    Fault(
        "continuous-overwrites-data",
        "aRn!/aRCn! share the D buffer: after one, the last measurement's D replies are empty.",
        ("R-4.4.5-10",),
        settings={"continuous_overwrites_data": True},
    ),
)


#: Version specific.
VERSION_13: tuple[Fault, ...] = (
    Fault(
        "v13-concurrent-over-20",
        "v1.3 profile: aC! announces and delivers 25 values (the 2000 text allows 20).",
        ("R-4.4.7-03",),
        profile=with_spec("C", _v13_wide_concurrent),
        version=V13,
        replaces="the values of aC!",
    ),
)
