"""Judges for measurements: the atttn-type reply, the wait (service request or silence) and the
data collection (D or DB replies). One pass over the records yields violations for every rule
they bear on; each case keeps the requirement IDs it names (one stimulus, many judges).
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache

from ..protocol.binary import parse_binary_packet
from ..protocol.commands import CONCURRENT_KINDS, SERVICE_REQUEST_KINDS, Command, Kind
from ..protocol.responses import (
    DataReply,
    check_data_sequence,
    check_measurement_count,
    expected_value_limit,
    parse_data_reply_for,
    parse_measurement_reply_for,
    service_request,
    split_line,
)
from ..protocol.timing import TOLERANCE
from ..protocol.values import Violation, check_value, continues_split_value
from ..tool_recorder.records import Exchange, Measurement
from ..transcript import Event, decode_7e1, escape
from ..verdicts import Finding, inconclusive
from .cite import cite, listed, shown
from .late_before import (
    answered_late,
    earlier_reply,
    late_answer,
    service_request_too_late,
    service_request_too_soon,
)
from .stalled import through_stall
from .support import text_instead_of_start, text_instead_of_values, unreadable_count
from .tally import Tally
from .wake_heard import unheard
from .wire import runs

SR_MARGIN_MIN = 1.0  # s: R-4.4.5-09 margin always tolerated (SR transmission, clock drift)
SR_MARGIN_FRACTION = 0.25  # of ttt: beyond this much slack, ttt is "more than a small margin"


def where(m: Measurement | Exchange | Command) -> str:
    if isinstance(m, Measurement):
        return m.command.text()
    if isinstance(m, Exchange):
        return escape(m.text)
    return m.text()


def is_concurrent(m: Measurement) -> bool:
    return m.command.kind in CONCURRENT_KINDS


def raises_sr(m: Measurement) -> bool:
    return m.command.kind in SERVICE_REQUEST_KINDS


# -- the measurement reply ---------------------------------------------------------------------
def reply_violations(m: Measurement, version: str) -> list[Violation]:
    if not m.start.answered:
        return []
    body, framing = split_line(m.start.reply_text)
    reply = parse_measurement_reply_for(body, m.command, expected_address=m.command.address)
    return framing + reply.violations + check_measurement_count(reply, m.command, version)


# -- the wait -------------------------------------------------------------------------------
def _sr_run(
    runs_: list[list[Event]], address: str, chatter: frozenset[str] = frozenset()
) -> int | None:
    """Index of the service request: the first run that is exactly ``a<CR><LF>``, else the
    first run shaped like one (address ... CR LF), which R-4.4.6-01 then judges malformed,
    unless it is ``chatter``: a line this sensor sent before its exact service request after
    another command (:func:`known_chatter`)."""
    texts = [decode_7e1(run) for run in runs_]
    exact = next((i for i, t in enumerate(texts) if t == service_request(address)), None)
    if exact is not None:
        return exact
    return next(
        (i for i, t in enumerate(texts) if _sr_shaped(t, address) and t not in chatter), None
    )


def known_chatter(measurements: Iterable[Measurement]) -> frozenset[str]:
    """Lines shaped like a service request that a measurement's wait held before its exact
    ``a<CR><LF>``: this sensor's chatter, not its request. Where another command's wait
    holds such a line and no request, that wait had none (R-4.4.6-02), not a malformed one
    (R-4.4.6-01): chatter-before-service-request beside verify-no-service-request FAILed
    R-4.4.6-01 on aV!'s 'aBUSY' and PASSed R-4.4.6-02 (seed 4064)."""
    found: set[str] = set()
    for m in measurements:
        if not (raises_sr(m) and m.ttt and m.start.answered):
            continue
        texts = _waited_lines(m)
        request = service_request(m.command.address)
        if request in texts:
            before = texts[: texts.index(request)]
            found.update(t for t in before if _sr_shaped(t, m.command.address))
    return frozenset(found)


def _waited_lines(m: Measurement) -> list[str]:
    """The text of each run of characters ``m``'s wait held (where its service request, its
    chatter or nothing is)."""
    return [decode_7e1(run) for run in runs(list(m.waited_events))]


def _sr_shaped(text: str, address: str) -> bool:
    """A line shaped like a service request: the address ... CR LF."""
    return text.startswith(address) and text.endswith("\r\n")


def wait_violations(m: Measurement, tally: Tally, chatter: frozenset[str] = frozenset()) -> None:
    """Service-request rules (R-4.4.6-*, R-4.4.5-08/09) and the quiet rules of concurrent
    measurements (R-4.4.6-05, R-4.4.7-04, R-5.3-01); ``chatter``: :func:`known_chatter`."""
    label = where(m)
    if m.ttt is None or not m.start.answered:
        return
    chunks = runs(list(m.waited_events))
    address = m.command.address
    if raises_sr(m) and m.ttt > 0:
        sr = _sr_run(chunks, address, chatter)
        tally.observe(label, ids=["R-4.4.6-02", "R-4.4.5-08"])
        # a stall of the tool's host over the wait's characters or its end may have split,
        # misdated or hidden the service request: what the wait shows of it is undecided
        # (truth29), never the sensor's miss
        waited = through_stall(tally, m.wait_stall)
        if sr is None:
            for rid in ("R-4.4.6-01", "R-4.4.6-04", "R-4.4.5-09"):
                tally.unobservable(
                    rid,
                    "no service request arrived, so its form and timing cannot be judged "
                    "(see R-4.4.6-02)",
                )
            waited.fail(
                "R-4.4.6-02",
                label,
                f"no service request within ttt={m.ttt} s (the recorder had to wait it "
                "out and break)",
            )
        _service_request(m, chunks, sr, waited)
    if is_concurrent(m):
        tally.observe(
            label,
            ids=["R-4.4.6-05", "R-5.3-01"]
            if m.command.kind is not Kind.CONCURRENT
            else ["R-4.4.6-05", "R-4.4.7-04"],
        )
        sr = _sr_run(chunks, address)
        if sr is not None:
            msg = f"sent a service request '{escape(decode_7e1(chunks[sr]))}' after {label}"
            tally.fail("R-4.4.6-05", label, msg)
            tally.fail("R-5.3-01", label, msg)
        if chunks and m.command.kind is Kind.CONCURRENT:
            tally.fail(
                "R-4.4.7-04",
                label,
                f"sent '{escape(decode_7e1(chunks[0]))}' before it was asked for data",
            )


def _service_request(
    m: Measurement, chunks: list[list[Event]], sr: int | None, tally: Tally
) -> None:
    """R-4.4.5-08/-09, R-4.4.6-01/-04 on the run ``sr`` taken for ``m``'s service request.
    With no exact ``a<CR><LF>`` and two or more lines shaped like one (``a...<CR><LF>``),
    which one is the request cannot be told: the first, as before, for its form (every
    candidate is malformed), but what came between reply and request, and when the request
    came, are undecided (chatter-before-service-request beside service-request-extra-chars
    took the 'aBUSY' chatter for the request: an early-request WARN and an R-4.4.5-08 PASS)."""
    label = where(m)
    address = m.command.address
    before = chunks if sr is None else chunks[:sr]
    if before:
        tally.fail(
            "R-4.4.5-08",
            label,
            f"sent '{escape(decode_7e1(before[0]))}' between its reply and the service request",
        )
    if sr is None or m.reply_end is None:
        return
    text = decode_7e1(chunks[sr])
    tally.observe(label, ids=["R-4.4.6-01"])
    if text != service_request(address):
        tally.fail(
            "R-4.4.6-01",
            label,
            f"service request '{escape(text)}' is not '{address}<CR><LF>'",
        )
    shaped = [c for c in chunks[sr + 1 :] if _sr_shaped(decode_7e1(c), address)]
    if text != service_request(address) and shaped:
        why = (
            f"'{escape(text)}' and '{escape(decode_7e1(shaped[0]))}' both could be the "
            "service request"
        )
        for rid in ("R-4.4.5-08", "R-4.4.6-04", "R-4.4.5-09"):
            tally.undecide(rid, label, why)
        return
    tally.observe(label, ids=["R-4.4.6-04", "R-4.4.5-09"])
    elapsed = chunks[sr][-1].end - m.reply_end
    if elapsed > m.ttt + TOLERANCE:
        tally.fail(
            "R-4.4.6-04",
            label,
            f"service request completed {elapsed:.3f} s after the reply, past ttt={m.ttt} s",
        )
    slack = m.ttt - elapsed
    allowed = max(SR_MARGIN_MIN, SR_MARGIN_FRACTION * m.ttt)
    if slack > allowed:
        tally.fail(
            "R-4.4.5-09",
            label,
            f"service request came {elapsed:.2f} s after the reply, {slack:.2f} s "
            f"before ttt={m.ttt} s (more than the {allowed:.2f} s margin this "
            "tool tolerates)",
            warning=True,
        )


# -- the data -------------------------------------------------------------------------------
def data_violations(m: Measurement, tally: Tally) -> None:
    if m.command.kind is Kind.HIGH_VOLUME_BINARY:
        _binary_violations(m, tally)
    else:
        _ascii_violations(m, tally)


def _ascii_violations(m: Measurement, tally: Tally) -> None:
    label = where(m)
    if m.count is None or not m.data:
        return
    replies: list[DataReply] = []
    limit = expected_value_limit(m.command)
    silent = late = too_soon = None
    whole = tally  # the tally of the values as a whole, seen through their reads' stalls
    for ex in m.data:
        dlabel = f"{label} {where(ex)}"
        # a reply the host stalled over may be cut, its rest taken for a retry's: what its
        # read shows is undecided, never FAIL (truth27), and so is what the values as a
        # whole show with it among them (their count, a value's split or room)
        here = through_stall(tally, ex.stall)
        if whole is tally:
            whole = here
        if how := _not_this_ds_reply(m, ex, tally, dlabel):
            silent = late = ex
            too_soon = ex if how == "soon" else too_soon
            break
        if not ex.answered:
            here.fail("R-4.4.8-01", dlabel, f"no reply to {where(ex)}")
            if m.command.kind is Kind.HIGH_VOLUME_ASCII:
                here.fail("R-5.1-02", dlabel, f"no reply to {where(ex)} after aHA!")
            silent = ex
            break
        body, framing, reply = _read_data_reply(ex.reply_text, m.command)
        here.observe(dlabel, framing + reply.violations, ids=shown_reply_ids(m.command, reply))
        if reply.crc and not reply.crc_ok:
            undecide_uncompared_crc(reply, tally, dlabel)
        replies.append(reply)
        if _refuses_high_index(m, ex):
            # (seed 4090) 'aUNKN' to aD10! is the sensor saying it does not serve the index:
            # as silence there is (high-volume-stops-at-d9 + unknown-command-text PASSed)
            here.fail("R-5.1-02", dlabel, f"{where(ex)} after aHA! answered '{escape(body)}'")
    tally = whole
    seq = check_data_sequence(replies, m.count, limit)
    if late is not None:  # the count was cut at a late reply, not at silence
        seq = [v for v in seq if v.requirement != "R-4.4.8-03"]
    _drop_split_fragments(replies, seq, tally, label)
    _undecide_cut_at_silence(m, replies, silent, tally, label)
    if not replies and silent is not None and too_soon is None:
        # D0 itself went unanswered: whether it returns values is unread, no conformance
        # (an Arduino Due sketch with no D0 branch, twenty-first round: R-4.4.8-04 PASSed
        # "conforms (19 checked)" on nineteen silent aD0!s; R-4.4.8-01 FAILs the silence)
        tally.undecide(
            "R-4.4.8-04",
            f"{label} {where(silent)}",
            f"no reply to {where(silent)}: whether D0 returns values is unread",
        )
    tally.observe(
        label,
        seq,
        ids=[
            "R-4.4.8-03",
            "R-4.4.8.3-01",
            "R-4.4.8.3-03",
            "R-4.4.8-01",
            "R-4.4.8.3-02",
            "R-4.4.8-04",
        ],
    )
    if m.count >= 1 and m.aborted_by is None:
        _empty_groups(m, replies, tally, label)
    if m.command.kind is Kind.HIGH_VOLUME_ASCII:
        tally.observe(label, ids=["R-5.1-02"])
        _undecide_unread_high_volume(m, replies, tally, label)


def _empty_groups(m: Measurement, replies: list[DataReply], tally: Tally, label: str) -> None:
    """R-4.4.8-04 (D0 empty although values were announced) and R-4.4.8.3-02 (an empty
    group before one with values) over a measurement's data replies as read."""
    if replies and not replies[0].values:
        tally.fail("R-4.4.8-04", label, f"D0 returned no values although {m.count} were announced")
    seen_empty = None
    for i, r in enumerate(replies):
        if not r.values and seen_empty is None:
            seen_empty = i
        elif r.values and seen_empty is not None:
            tally.fail(
                "R-4.4.8.3-02",
                label,
                f"D{seen_empty} was empty but D{i} returned values: groups out of order",
            )
            break


def _not_this_ds_reply(m: Measurement, ex: Exchange, tally: Tally, dlabel: str) -> str:
    """'' unless what the D exchange ``ex`` took may not be its reply, its rules undecided
    then: "late" (the reply came after the tool stopped listening, or the one taken may be
    the D before's) or "soon" (a service request's words begun too soon to answer it)."""
    taken_late = answered_late(ex)
    why = f"{taken_late} (R-7.0-10 judges its timing)" if taken_late else unheard(ex)
    if why:
        # its reply came after the tool stopped listening, or the one taken may be the D
        # before's: no silence, no count cut short, no values of its own to judge
        # (replies-after-retry + wrong-crc: "0C9! 0D6!: no reply to 0D6!" and "60 values
        # were returned for 99 announced" FAILed on a D6 whose reply met the retry, truth15);
        # nor silence to tries the sensor was not awake to hear (:func:`unheard`, truth23)
        hv = ["R-5.1-02"] if m.command.kind is Kind.HIGH_VOLUME_ASCII else []
        for rid in ("R-4.4.8-01", "R-4.4.8-03", *hv):
            tally.undecide(rid, dlabel, why)
        return "late"
    if m.count and (soon := service_request_too_soon(ex) or _request_owed_late(m, ex)):
        # values announced, and what came may be a service request, not this D's reply
        for rid in ("R-4.4.8-01", "R-4.4.8-03", "R-4.4.8-04"):
            tally.undecide(rid, dlabel, soon)
        return "soon"
    return ""


def _request_owed_late(m: Measurement, ex: Exchange) -> str:
    """:func:`service_request_too_late` of the D exchange ``ex`` where ``m`` may still be
    followed by a service request: a start that raises one (M family, V) whose wait held
    none exact (after ttt = 000 a faulty sensor sends it when the D command is out)."""
    if not raises_sr(m):
        return ""
    if service_request(m.command.address) in _waited_lines(m):
        return ""
    return service_request_too_late(ex)


@lru_cache(maxsize=4096)
def _read_data_reply_once(
    reply_text: str, command: Command
) -> tuple[str, tuple[Violation, ...], DataReply]:
    body, framing = split_line(reply_text, crc_positions=3 if command.returns_crc else 0)
    reply = parse_data_reply_for(body, command, expected_address=command.address)
    return body, tuple(framing), reply


def _read_data_reply(reply_text: str, command: Command) -> tuple[str, list[Violation], DataReply]:
    """A D reply to the measurement ``command``: its body, framing violations and parse,
    read once a process for each reply text and command (issue 22): every case that judges
    measurements (:func:`judge`, some sixteen a run) reads the same shared ones again. All
    three are pure functions of the text and the command; the reply (frozen, its lists
    never changed by a judge) is shared, the framing list is the caller's own."""
    body, framing, reply = _read_data_reply_once(reply_text, command)
    return body, list(framing), reply


def _undecide_unread_high_volume(
    m: Measurement, replies: list[DataReply], tally: Tally, label: str
) -> None:
    """aHA!'s rules on what its D replies hold, undecided where they held none of the values
    owed: R-5.1-03's 75 characters and uncut values where no reply held a value, R-5.1-02's
    D10..D999 where values were still owed and no index past D9 was read (d0-empty beside
    high-volume-stops-at-d9, seed 4100, and beside high-volume-values-over-75, seed 4100:
    both PASSed on the empty D0 and D1 of 120 announced values). A FAIL found stands."""
    if not m.count or m.complete:
        return
    if not any(r.values for r in replies):
        tally.undecide(
            "R-5.1-03",
            label,
            f"no D reply held a value of the {m.count} announced: their length and cut unseen",
        )
    past_d9 = [
        ex for ex in m.data if ex.answered and ex.command is not None and ex.command.index >= 10
    ]
    if not past_d9:
        tally.undecide(
            "R-5.1-02",
            label,
            f"values still owed of the {m.count} announced, and no D command past D9 was"
            " answered: the reading stopped before it",
        )


def shown_reply_ids(command: Command, reply: DataReply) -> list[str]:
    """The rules one D (or R) reply is an observation of: a reply that should carry a CRC and
    carries none (R-4.4.12-02's deviation) shows nothing of the CRC's value or encoding
    (crc-missing + crc-wrong-encoding + extended-not-x, seed 4179: R-4.4.12-05 PASSed
    "17 checked" on aMC!/aCC!'s CRC-less replies while every CRC on the wire was encoded
    as no CRC-16 and none was compared; the aRCn! replies, encoded so too, PASSed it as well
    once those were left out)."""
    ids = data_reply_ids(command)
    if command.returns_crc and reply.crc is None:
        return [i for i in ids if i not in ("R-4.4.12-05", "R-4.4.12-06")]
    return ids


def uncompared_crc(reply: DataReply) -> bool:
    """A CRC whose encoding is no CRC-16's (R-4.4.12-06) is not compared with the text
    (protocol.responses._check_crc), so it shows nothing of R-4.4.12-05 either way."""
    wrong = any(v.requirement == "R-4.4.12-05" for v in reply.violations)
    return bool(reply.crc) and not reply.crc_ok and not wrong


def undecide_uncompared_crc(reply: DataReply, tally: Tally, where_: str) -> None:
    """R-4.4.12-05 undecided on an :func:`uncompared_crc` (crc-wrong-encoding + wrong-crc
    + value-two-points, seed 4118: R-4.4.12-05 PASSed "17 checked" where every CRC was off
    by one and none compared)."""
    if uncompared_crc(reply):
        tally.undecide(
            "R-4.4.12-05",
            where_,
            f"CRC '{escape(reply.crc or '')}' is encoded as no CRC-16: its value not compared",
        )


def _undecide_cut_at_silence(
    m: Measurement, replies: list[DataReply], silent: Exchange | None, tally: Tally, label: str
) -> None:
    """R-4.4.8.3-01 and -03 judge a reply by the next one's first value (its unsigned tail,
    or a value that would have fitted): where the next D went unanswered with values still
    owed, the replies read and unread may have cut one, and the rules are undecided there
    (m2-later-data-silent + split-value, seed 4099: R-4.4.8.3-01 PASSed although aM2!'s
    D0, cut at 35 characters, was followed by a D1 nobody heard; + groups-start-at-d1,
    seed 4098: D0 empty, D1 silent, none of aM2!'s values read)."""
    if silent is None or m.complete:
        return
    for rid in ("R-4.4.8.3-01", "R-4.4.8.3-03"):
        tally.undecide(
            rid,
            f"{label} {where(silent)}",
            f"no reply to {where(silent)} with values still owed: whether the reply before"
            " cut one, or left room for one, is unread",
        )


def data_reply_ids(command: Command) -> list[str]:
    """The rules one ASCII D (or R) reply is checked against, given what asked for it."""
    ids = ["R-4.4.8-01", "R-4.4.8-02", "R-4.2-02", "R-4.2-03", "R-4.3-01"]
    if command.kind is Kind.HIGH_VOLUME_ASCII:
        return ids + ["R-5.1-03", "R-4.4.12-05", "R-4.4.12-06"]
    if command.kind is Kind.CONTINUOUS:
        ids.append("R-4.4.8.1-01")
    else:
        ids.append("R-4.4-05")
    if command.returns_crc:
        return ids + ["R-4.4.12-02", "R-4.4.12-05", "R-4.4.12-06"]
    return ids + ["R-4.4.12-03"]


def _refuses_high_index(m: Measurement, ex: Exchange) -> bool:
    """A reply of text, neither values nor empty (:func:`text_instead_of_values`, which
    knows the empty form with its CRC, ``a<CRC>``: aHA!'s replies always carry one), to an
    ``aDn!`` of two or more digits after ``aHA!``: the D commands past D9 exist only for
    high-volume data (R-5.1-02)."""
    command = ex.command
    if m.command.kind is not Kind.HIGH_VOLUME_ASCII or command is None:
        return False
    return (
        command.kind is Kind.DATA
        and command.index >= 10
        and text_instead_of_values(ex, m.command.returns_crc)
    )


def _drop_split_fragments(
    replies: list[DataReply], seq: list[Violation], tally: Tally, label: str
) -> None:
    """A value split across two replies is an R-4.4.8.3-01 fault; its unsigned tail is not
    also a grammar fault of R-4.4.8-02 when the two halves make a valid value."""
    for v in seq:
        if v.requirement != "R-4.4.8.3-01":
            continue
        for before, after in zip(replies, replies[1:], strict=False):
            if continues_split_value(after.values) and before.values:
                joined = before.values[-1] + after.values[0]
                if not [x for x in check_value(joined) if not x.warning]:
                    fragment = f"'{escape(after.values[0])}'"
                    bucket = tally.violations.get("R-4.4.8-02", [])
                    bucket[:] = [b for b in bucket if fragment not in b[1].message]


def _binary_violations(m: Measurement, tally: Tally) -> None:
    label = where(m)
    if m.count is None:
        return
    total = 0
    ids = ["R-5.2-02", "R-5.2-03", "R-5.2-04", "R-5.2-05", "R-5.2.1-01", "R-4.1-03"]
    countable = True
    whole = tally  # seen through the first stall over a packet's read (as ASCII data's)
    for ex in m.data:
        dlabel = f"{label} {where(ex)}"
        if late := late_answer(ex):
            # its packet came after the windows, met by the retry and set aside as bus
            # contention: no silence, no count cut short (replies-after-retry + parity-error
            # behind an echoing 16 ms USB link FAILed "no packet returned for 0DB0!",
            # outside28)
            for rid in ("R-5.2-02", "R-5.2-07"):
                tally.undecide(rid, dlabel, f"{late} (R-7.0-10 judges its timing)")
            return
        here = through_stall(tally, ex.stall)
        if whole is tally:
            whole = here
        if not ex.answered:
            if not countable:
                # (seed 4088) read on past a packet whose values could not be counted, so
                # this index may be past the data, where the empty packet is R-5.2-06's
                # (binary-invalid-type + binary-no-empty-packet FAILed R-5.2-02 on DB10)
                tally.undecide(
                    "R-5.2-02",
                    dlabel,
                    f"no packet for {where(ex)}, which may lie past the data: the packets"
                    " before it could not be counted",
                )
            elif total < m.count:
                here.fail("R-5.2-02", dlabel, f"no packet returned for {where(ex)}")
            return
        packet = parse_binary_packet(ex.reply_bytes, expected_address=m.command.address)
        if packet.payload_known:
            here.observe(dlabel, packet.violations, ids=ids)
        else:
            here.observe(dlabel, packet.violations, ids=[i for i in ids if i != "R-5.2-05"])
            tally.undecide(
                "R-5.2-05",
                dlabel,
                "its size field disagrees with its length and its CRC does not check: how"
                " long its payload was is not on the wire",
            )
        if packet.is_empty:
            break
        if any(v.requirement in ("R-5.2.1-01", "R-5.2-05", "R-5.2-02") for v in packet.violations):
            countable = False  # unknown type, ragged payload or broken framing: uncountable
        total += len(packet.values)
    if countable and m.count and total == 0:
        # (seed 4104, d0-empty + binary-payload-not-multiple) the empty packet alone has
        # no payload whose length or size could be judged: R-5.2-04/-05 PASSed on it
        for rid in ("R-5.2-04", "R-5.2-05"):
            tally.undecide(
                rid, label, f"no packet held a payload of the {m.count} values announced"
            )
    if countable:
        whole.observe(label, ids=["R-5.2-07"])
        if total != m.count:
            whole.fail("R-5.2-07", label, f"packets held {total} values for {m.count} announced")


def judge(
    measurements: Iterable[Measurement],
    ids: Iterable[str],
    version: str,
    ok: dict[str, str] | str = "conforms",
) -> list[Finding]:
    """Findings for ``ids`` over ``measurements``: reply, wait and data rules together.
    One :meth:`Measurements.add` of them all (the windowed judge's code path)."""
    fold = Measurements(ids, version)
    fold.add(measurements)
    return fold.findings(ok)


class Measurements:
    """:func:`judge` over a recording's measurements given a window at a time (issue 22's
    windowed judge): each window's measurements :meth:`add`-ed in order, the findings those
    of the whole recording's. A measurement's records end in its window, but one rule reads
    the whole run: the lines :func:`known_chatter` finds before any sensor's exact service
    request decide which line of another measurement's wait is its request. So a
    measurement whose request that could change (:func:`_waits_on_chatter`) is held, with
    every one after it (the tally keeps the whole run's order), until the chatter it needs
    is known or :meth:`findings`; the rest are judged as they come and let go. Carried: the
    tally, the chatter found so far and the measurements held."""

    def __init__(self, ids: Iterable[str], version: str) -> None:
        self.tally = Tally(ids)
        self.version = version
        self.chatter: set[str] = set()
        self.held: list[Measurement] = []

    def add(self, measurements: Iterable[Measurement]) -> None:
        """The next window's measurements."""
        for m in measurements:
            self.chatter.update(known_chatter([m]))
            self.held.append(m)
        chatter = frozenset(self.chatter)
        settled = 0
        for m in self.held:
            if _waits_on_chatter(m, chatter):
                break
            self._judge(m, chatter)
            settled += 1
        del self.held[:settled]

    def findings(self, ok: dict[str, str] | str = "conforms") -> list[Finding]:
        """The findings over everything added (the measurements held judged now)."""
        chatter = frozenset(self.chatter)
        for m in self.held:
            self._judge(m, chatter)
        self.held.clear()
        return self.tally.findings(ok)

    def _judge(self, m: Measurement, chatter: frozenset[str]) -> None:
        tally = self.tally
        if earlier := earlier_reply(m.start):
            # the reply taken may be the command before's, late: no words of this start's
            # to judge, nor values it announced (replies-after-retry + wrong-crc, truth15)
            for rid in tally.ids:
                tally.undecide(rid, where(m), f"{earlier} (R-7.0-10 judges its timing)")
            return
        if soon := service_request_too_soon(m.start):
            # a service request's words begun before any reply may: no start reply's words
            # to judge (replies-after-retry + service-request-after-ttt-zero: 0MC1!'s '00002'
            # met its retry, the request after it came 0 ms after the next try, and R-4.4.5-01
            # FAILed "0MC1!: reply '0' does not have the form atttn", truth19)
            for rid in tally.ids:
                tally.undecide(rid, where(m), soon)
            return
        if not m.start.answered and (late := answered_late(m.start)):
            # its reply came only after the window: its form is unread, so the other starts'
            # PASS does not stand for it (unknown-command-text's text to 0C1!..0C9! came only
            # late beside replies-after-retry: R-4.4.7-01 PASSed "2 checked: 0C!, 0CC!")
            for rid in _reply_ids(m):
                tally.undecide(rid, where(m), f"{late} (R-7.0-10 judges its timing)")
        through_stall(tally, m.start.stall).observe(
            where(m),
            reply_violations(m, self.version),
            ids=[i for i in _reply_ids(m) if m.start.answered],
        )
        if unreadable_count(m):
            # no count to hold to 1..9 (measure-ttt-two-digits beside measure-count-zero
            # PASSed R-4.4.5-02 on 21 replies none of which gave a count, seed 4066)
            tally.undecide("R-4.4.5-02", where(m), "its reply gives no readable count")
        if text_instead_of_start(m) and "R-4.4.7-02" in _reply_ids(m):
            # 'aUNKN' to aC! starts no measurement to call real or not (R-4.4.7-08 FAILs the
            # missing support); "conforms" was said of joembedded's sketch (docs/kit.md)
            tally.undecide("R-4.4.7-02", where(m), "its reply is text, no measurement started")
        wait_violations(m, tally, chatter)
        data_violations(m, tally)


def _waits_on_chatter(m: Measurement, chatter: frozenset[str]) -> bool:
    """Whether chatter found later may still change which line of ``m``'s wait
    :func:`wait_violations` takes for its service request: it asks :func:`_sr_run` with the
    chatter, there is no exact ``a<CR><LF>``, and a line shaped like one is not known as
    chatter yet (chatter only grows: once all are, the choice is final)."""
    if m.ttt is None or not m.start.answered or not (raises_sr(m) and m.ttt > 0):
        return False
    address = m.command.address
    texts = _waited_lines(m)
    if service_request(address) in texts:
        return False
    return any(_sr_shaped(t, address) and t not in chatter for t in texts)


def unread_data(measurements: Iterable[Measurement], ids: Iterable[str]) -> list[Finding]:
    """``ids`` INCONCLUSIVE where a measurement's start reply gave no readable count
    (:func:`~conformance.judges.support.unreadable_count`): its D replies were never asked
    for, so a PASS over the other measurements' replies would speak for values nobody read
    (measure-ttt-two-digits beside value-ten-chars PASSed R-4.4.8-02 on aC!'s replies while
    aM!'s ten-character value stayed in the sensor). A violation found elsewhere still
    FAILs: the run's verdict is the worst of its findings. Observed: those start replies.
    One :meth:`UnreadData.add` of them all (the windowed judge's code path)."""
    fold = UnreadData()
    fold.add(measurements)
    return fold.findings(ids)


class UnreadData:
    """:func:`unread_data` over a recording's measurements given a window at a time (issue
    22's windowed judge): carried, the start exchanges of those whose reply gave no readable
    count (each is quoted), not the measurements."""

    def __init__(self) -> None:
        self.starts: list[Exchange] = []

    def add(self, measurements: Iterable[Measurement]) -> None:
        """The next window's measurements."""
        self.starts += [m.start for m in measurements if unreadable_count(m)]

    def findings(self, ids: Iterable[str]) -> list[Finding]:
        """``ids`` INCONCLUSIVE over every unread start reply added (none: no finding)."""
        starts = self.starts
        if not starts:
            return []
        detail = (
            "no value count in "
            + listed([shown(ex) for ex in starts])
            + ": no D command followed, so the values held there are unjudged"
        )
        return [
            inconclusive(rid, detail, evidence=cite(starts), observed=len(starts)) for rid in ids
        ]


def _reply_ids(m: Measurement) -> list[str]:
    kind = m.command.kind
    if kind in (Kind.MEASURE, Kind.VERIFY):
        counted = ["R-4.4.5-02"] if m.count is not None else []
        return ["R-4.4.5-01", *counted, "R-4.2-02", "R-4.2-03"]
    if kind is Kind.CONCURRENT:
        # R-4.4.7-02 (aC! measures for real) is about plain aC!/aCC! only: an aCn! reply
        # cannot break it, so it is no check of it (the lagopus sketch, silent to aC! and
        # aCC!, PASSed it "conforms (2 checked: 5C5!, 5CC5!)" on its a! answer to each)
        plain = ["R-4.4.7-02"] if m.command.group == 0 else []
        if not m.count:
            # no count to bound (R-4.4.7-03); a00000 to plain aC!/aCC! is no answer of the
            # kind (R-4.4.7-02 judges it), so its format stands for nothing either
            plain_zero = m.count == 0 and m.command.group == 0
            return [*([] if plain_zero else ["R-4.4.7-01"]), *plain, "R-4.2-02", "R-4.2-03"]
        return ["R-4.4.7-01", *plain, "R-4.4.7-03", "R-4.2-02", "R-4.2-03"]
    if kind is Kind.HIGH_VOLUME_ASCII:
        return ["R-5.1-01", "R-4.2-02", "R-4.2-03"]
    return ["R-5.2-01", "R-4.2-02", "R-4.2-03"]
