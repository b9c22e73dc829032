"""Judges of data collection: D0, D1, ... in order until every value is in (R-4.4.8-05),
concurrent storage (R-4.4.7-07/08), high-volume ASCII and binary (R-5.1-04, R-5.2-08,
R-5.4-01)."""

from __future__ import annotations

from collections.abc import Collection, Sequence

from ...links.host_stall import Stall
from ...protocol.binary import parse_binary_packet
from ...protocol.commands import CommandError, Kind, parse_command
from ...transcript import decode_8n1, escape
from ...verdicts import Finding
from ...view.segments import Transmission
from ..tally import Tally
from .common import CUT_SHORT, MIN_CONCURRENT_STORE
from .measurements import ObservedMeasurement, collection_end, read_past_empty
from .stalls import over_collection, tried_again


def judge_data_collection(
    taken: Sequence[ObservedMeasurement], stalls: Sequence[Stall] = ()
) -> list[Finding]:
    """R-4.4.8-05: aD0!, aD1!, ... in order until every announced value is in; after a valid
    empty reply the measurement is issued again. A collection that ended on a reply the
    recorder found invalid is left to the retry rules (section 7.2), unless a valid empty
    reply before it was read past without the measurement issued again. One that stopped
    short across a noted stall of the tool's host (``stalls``) is undecided naming it, where
    the stall can account for it (:func:`.stalls.tried_again`, :func:`.stalls.
    over_collection`, truth33). One :class:`DataCollection` given each of ``taken`` in
    order."""
    collection = DataCollection(stalls)
    for m in taken:
        collection.take(m)
    return collection.findings()


class DataCollection:
    """:func:`judge_data_collection` of measurements given one at a time (issue 22,
    memory27: the recorder pass hands each one over once it is over and forgets it):
    :meth:`take` each in the order begun, then :meth:`findings`; what it holds is the
    tally, never a measurement."""

    def __init__(self, stalls: Sequence[Stall] = ()) -> None:
        self.stalls = stalls
        self.tally = Tally(("R-4.4.8-05",))

    def take(self, m: ObservedMeasurement) -> None:
        """The next measurement, in the order begun."""
        if m.kind is Kind.HIGH_VOLUME_BINARY or not m.count:
            return
        tally = self.tally
        where = escape(m.start.text)
        tally.observe(where)
        indices = [d[1] for s, _ in m.data if (d := s.data_index) is not None]
        order = [i for n, i in enumerate(indices) if n == 0 or indices[n - 1] != i]
        if order != list(range(len(order))):
            tally.fail("R-4.4.8-05", where, f"data indices went {order}, not 0, 1, 2, ...")
            return
        have = len(m.values())
        if have >= m.count:
            return
        last, problem, empty = collection_end(m)
        past = read_past_empty(m) if problem is not None else None
        if past is not None and (m.next_start is None or m.next_start.text != m.start.text):
            tally.fail(
                "R-4.4.8-05",
                where,
                f"{escape(past.text)} came back empty and the measurement was not issued "
                f"again (the recorder read on, to {escape(last.text) if last else '?'})",
            )
            return
        if problem is not None:
            return
        if m.cut_at is not None:
            tally.undecide("R-4.4.8-05", where, _cut_with(have, m))
            return
        if empty:
            if m.next_start is None or m.next_start.text != m.start.text:
                tally.fail(
                    "R-4.4.8-05",
                    where,
                    f"{escape(last.text) if last else 'aD0!'} came back empty and the "
                    "measurement was not issued again",
                )
            return
        stop = escape(last.text) if last is not None else "the reply"
        short = f"stopped after {stop} with {have} of {m.count} values"
        _stopped_short(tally, "R-4.4.8-05", m, where, short, self.stalls)

    def findings(self) -> list[Finding]:
        """R-4.4.8-05 over every measurement taken."""
        return self.tally.findings("every announced value collected in order")


def judge_concurrent_storage(
    taken: Sequence[ObservedMeasurement],
    asked: Sequence[str] = (),
    sent: Collection[str] = (),
    cut: bool = False,
) -> list[Finding]:
    """R-4.4.7-07: a concurrent measurement of more than 20 values: at least 20 read and stored
    (the 2000 text's MUST); fewer than announced is a WARN (the capacity should be documented,
    which the tool cannot see). R-4.4.7-08: the recorder uses aC!-type commands: each one in
    ``asked`` (what the scenarios told it to send) must be on the wire. One in ``sent`` (the
    texts the recorder transmitted) that no valid reply answered shows the command, not what
    the recorder does with a measurement: undecided (the reason is another rule's, such as a
    wake-up the played sensor could not hear, R-7.0-06). ``cut``: a job of the view was cut at
    its budget, so a command asked and not sent may still have been owed (undecided)."""
    tally = Tally(("R-4.4.7-07", "R-4.4.7-08"))
    started = {m.start.text for m in taken}
    for text in asked:
        if parse_command(text).kind is not Kind.CONCURRENT or text in started:
            continue
        if text in sent:
            tally.undecide("R-4.4.7-08", escape(text), "sent, never validly answered")
        elif cut:
            tally.undecide("R-4.4.7-08", escape(text), CUT_SHORT)
        else:
            tally.fail("R-4.4.7-08", escape(text), f"asked for {escape(text)}, never sent it")
    for m in taken:
        if m.kind is not Kind.CONCURRENT:
            continue
        where = escape(m.start.text)
        have = len(m.values())
        tally.observe(where, ids=["R-4.4.7-08"])
        if not have and m.count and not _ended_on_problem(m) and not _issued_again(m):
            if m.cut_at is not None:
                tally.undecide("R-4.4.7-08", where, _cut_with(have, m))
            else:
                tally.fail("R-4.4.7-08", where, f"read none of the {m.count} values")
        if m.count <= MIN_CONCURRENT_STORE:
            continue
        if have < m.count and _ended_on_problem(m):
            # the last D command drew no valid reply: how many values the recorder would
            # store is unseen (why it went unheard is another rule's, e.g. R-7.0-17)
            tally.undecide("R-4.4.7-07", where, "collection ended on a D command unanswered")
            continue
        if have < m.count and m.cut_at is not None:
            tally.undecide("R-4.4.7-07", where, _cut_with(have, m))
            continue
        tally.observe(where, ids=["R-4.4.7-07"])
        if have < MIN_CONCURRENT_STORE:
            tally.fail(
                "R-4.4.7-07", where, f"read {have} of {m.count} values (at least 20 are due)"
            )
        elif have < m.count:
            tally.fail(
                "R-4.4.7-07",
                where,
                f"read {have} of {m.count} values (fewer than announced)",
                warning=True,
            )
    return tally.findings("values read")


def _cut_with(have: int, m: ObservedMeasurement) -> str:
    """Why a collection the tool's budget cut short decides nothing of what came next."""
    return (
        f"{have} of {m.count} values in when the tool cut the job at its budget "
        f"(t={m.cut_at:.3f} s), the recorder still in this measurement"
    )


def _issued_again(m: ObservedMeasurement) -> bool:
    """The same command sent again before any data was asked for (a retry: a recorder on a
    busy host that heard the reply late repeats the command, section 7.2): the values are
    owed by the measurement that command started, not by this one. Completeness: R-4.4.8-05."""
    return not m.data and m.next_start is not None and m.next_start.text == m.start.text


def _stopped_short(
    tally: Tally,
    rid: str,
    m: ObservedMeasurement,
    where: str,
    short: str,
    stalls: Sequence[Stall],
) -> None:
    """``rid`` FAILs ``short`` (a collection of ``m`` that stopped before every value was
    in), or is undecided naming the stall where a noted stall of the tool's host can account
    for it (:func:`.stalls.over_collection` over its data, :func:`.stalls.tried_again` where
    none came: truth33)."""
    stall = over_collection(m, stalls) if m.data else tried_again(m, stalls)
    if stall is not None:
        tally.undecide(rid, where, f"{short}, but {stall.why()}")
    else:
        tally.fail(rid, where, short)


def _ended_on_problem(m: ObservedMeasurement) -> bool:
    return collection_end(m)[1] is not None


def judge_high_volume(
    taken: Sequence[ObservedMeasurement],
    is_v14: bool,
    sent: Collection[str] = (),
    cut: bool = False,
    stalls: Sequence[Stall] = (),
) -> list[Finding]:
    """R-5.1-04: after aHA! data commands go past aD9! as needed, without leading zeros.
    R-5.2-08: after aHB! aDBn! commands in 7E1, packets checked, collection stops at the empty
    packet or once every value is in. R-5.4-01: a v1.4 recorder issues aHA! and aHB! and reads
    their data back; one it sent (``sent``: the texts it transmitted) that no valid reply
    answered leaves the reading back unseen (undecided, not a FAIL); so does one not sent in a
    view with a job cut at its budget (``cut``), and a collection that cut left unfinished.
    A collection stopped short across a noted stall of the tool's host (``stalls``) is
    undecided naming it (:func:`_stopped_short`). One :class:`HighVolume` given each of
    ``taken`` in order."""
    high_volume = HighVolume(stalls)
    for m in taken:
        high_volume.take(m)
    return high_volume.findings(is_v14, sent, cut)


class HighVolume:
    """:func:`judge_high_volume` of measurements given one at a time (as
    :class:`DataCollection`): :meth:`take` each in the order begun, then :meth:`findings`
    (R-5.4-01 reads only what the high-volume measurements left, and whether the recorder
    claims v1.4, asked at the end), or :meth:`collections` (R-5.1-04 and R-5.2-08 alone,
    which that claim does not touch: what a recording shows). What it holds is the
    R-5.1-04 / R-5.2-08 tally and, per high-volume kind, whether any was taken, whether its
    data were read and whether it ended unheard."""

    def __init__(self, stalls: Sequence[Stall] = ()) -> None:
        self.stalls = stalls
        self.tally = Tally(("R-5.1-04", "R-5.2-08"))
        self.used = {Kind.HIGH_VOLUME_ASCII: False, Kind.HIGH_VOLUME_BINARY: False}
        self.unheard: set[Kind] = set()  # started, its collection ended on a D command unanswered
        self.taken: set[Kind] = set()  # started (a valid reply)

    def take(self, m: ObservedMeasurement) -> None:
        """The next measurement, in the order begun."""
        used, tally = self.used, self.tally
        if m.kind not in used:
            return
        self.taken.add(m.kind)
        where = escape(m.start.text)
        have = len(m.values())
        used[m.kind] = used[m.kind] or have > 0
        if not have and _ended_on_problem(m):
            self.unheard.add(m.kind)
        rid = "R-5.1-04" if m.kind is Kind.HIGH_VOLUME_ASCII else "R-5.2-08"
        tally.observe(where, ids=[rid])
        if m.cut_at is not None and have < m.count:
            tally.undecide(rid, where, _cut_with(have, m))
        zeros = [s for s, _ in m.data if (d := s.data_index) and d[2] != str(d[1])]
        if zeros:
            tally.fail(rid, where, f"{escape(zeros[0].text)} has leading zeros")
        if m.kind is Kind.HIGH_VOLUME_BINARY:
            parity = [e for s, _ in m.data for e in s.chars if not e.parity_ok]
            if parity:
                tally.fail(rid, where, "a DB command was not sent in 7E1 (parity)")
            last, problem, empty = collection_end(m)
            if problem is None and have < m.count and not empty and m.cut_at is None:
                short = f"stopped with {have} of {m.count} values, no empty packet"
                _stopped_short(tally, rid, m, where, short, self.stalls)
            extra = _after_done(m)
            if extra:
                tally.fail(rid, where, f"{escape(extra.text)} sent after every value was in")
        else:
            last, problem, _ = collection_end(m)
            if problem is None and have < m.count and m.cut_at is None:
                stop = escape(last.text) if last else "D0"
                short = f"stopped at {stop} with {have} of {m.count} values"
                _stopped_short(tally, rid, m, where, short, self.stalls)

    def findings(
        self, is_v14: bool, sent: Collection[str] = (), cut: bool = False
    ) -> list[Finding]:
        """R-5.1-04, R-5.2-08 and R-5.4-01 over every measurement taken (``is_v14``,
        ``sent``, ``cut``: :func:`judge_high_volume`'s); asked again, the same."""
        return [*self.collections(), *self._v14(is_v14, sent, cut)]

    def collections(self) -> list[Finding]:
        """R-5.1-04 and R-5.2-08 over every measurement taken."""
        return self.tally.findings("conforms")

    def _v14(self, is_v14: bool, sent: Collection[str], cut: bool) -> list[Finding]:
        """R-5.4-01 (each rule of a :class:`Tally` is found from its own observations
        alone: this one's tally apart gives what one tally of the three gave)."""
        tally = Tally(("R-5.4-01",))
        if is_v14:
            for kind, ok in self.used.items():
                tally.observe(kind.value.replace("a", "", 1), ids=["R-5.4-01"])
                if ok:
                    continue
                if kind in self.unheard or (
                    any(_kind_of(text) is kind for text in sent) and kind not in self.taken
                ):
                    tally.undecide(
                        "R-5.4-01", str(kind), f"{kind} sent, its data never validly answered"
                    )
                elif cut:
                    tally.undecide(
                        "R-5.4-01", str(kind), f"{kind}: {CUT_SHORT}, or its data not read"
                    )
                else:
                    tally.fail("R-5.4-01", str(kind), f"{kind} was not issued or its data not read")
        else:
            tally.not_applicable("R-5.4-01", "the recorder does not claim v1.4")
        return tally.findings("conforms")


def _kind_of(text: str) -> Kind | None:
    try:
        return parse_command(text).kind
    except CommandError:
        return None


def _after_done(m: ObservedMeasurement) -> Transmission | None:
    """A DB command sent after the values were complete (or after the empty packet)."""
    total = 0
    for i, (s, problem) in enumerate(m.data):
        if problem is not None:
            continue
        packet = parse_binary_packet(decode_8n1(s.reply))
        total += len(packet.values)
        if total >= m.count or not packet.values:
            later = [t for t, _ in m.data[i + 1 :] if t.text != s.text]
            return later[0] if later else None
    return None
