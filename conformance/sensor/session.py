"""The sensor under test as the sensor-role cases see it.

One tool recorder on one link, the identity read from ``aI!``, the declaration, and a cache of
stimuli: each exchange (say one ``aMC!`` with its service request and D replies) runs once and
is judged by every case that bears on it ("one stimulus, many judges"). Cases that need a
fresh state (aborts, address change) ask for a ``fresh`` stimulus explicitly.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from operator import is_
from typing import Any, Generic, TypeVar

from ..declaration import Declaration
from ..dut import DutClaim, Session, sensor_claim
from ..judges.support import empty_data_reply, first_filled
from ..judges.timing import REPROBE_TIMES, StampUncertainty
from ..links.base import Link
from ..links.host_stall import Stall, stalled_over
from ..preconditions import Unmet, acknowledges, shows_listening
from ..protocol import commands as cmd
from ..protocol.commands import (
    ADDRESS_CHARS,
    C_FAMILY,
    CONTINUOUS,
    M_FAMILY,
    Command,
    CommandError,
    Kind,
    parse_command,
)
from ..protocol.framing import LF
from ..protocol.responses import Identification, parse_ident, split_line
from ..protocol.timing import CHAR_TIME, STANDBY_MARKING, TOLERANCE, WAKE_LIMIT
from ..protocol.version import V14, VERSIONS, format_version, is_v14
from ..tool_recorder.records import Exchange, Measurement
from ..transcript import TOOL, Event, EventKind, decode_7e1, escape
from ..view.live_cut import Mark, live_cut
from ..view.rebuilt_records import Rebuilt, rebuild_records, records_of
from ..view.runs import runs
from ..view.segments import read_view
from .address_change import AddressChanger, Trial
from .buffer_watch import WatchedToolRecorder
from .late_watch import LATE_START_LISTEN

R = TypeVar("R", Exchange, Measurement)
T = TypeVar("T")


@dataclass
class Sweep:
    """An address sweep's exchanges, the addresses the sensor refused, and how its own
    address was put back."""

    exchanges: list[Exchange]
    refused: list[str]
    restore_note: str
    #: Of ``refused``: the addresses the sensor took (its reply named them) and then answered
    #: no ``b!`` poll at: lost, or a sensor that answers no ``a!`` anywhere.
    unanswered: list[str] = field(default_factory=list)
    #: The addresses a sensor that answers no ``a!`` was shown at by what it does answer:
    #: ``?!`` named the address and the move back from it was answered (not in ``refused``).
    heard: list[str] = field(default_factory=list)
    #: Of ``refused``: the addresses whose change drew no reply heard, from which the restore
    #: then moved the sensor back (it answered at its own address only after that move): it
    #: took them, its reply unheard (:attr:`AddressChanger.found_at`).
    found_at: list[str] = field(default_factory=list)


@dataclass
class InvalidAddressAttempt:
    """An attempt to move the sensor to an invalid address: the exchanges, and whether the
    sensor took the address."""

    exchanges: list[Exchange]
    accepted: bool
    #: an ``a!`` at the old address sent the same way right after it was answered: the
    #: sensor was listening, so its silence to ``aA<bad>!`` is a refusal, not deafness
    listening: bool = True
    #: that ``a!`` (None: none was sent), the evidence of a "not listening": ``exchanges``
    #: end with the restore's, whose last may be answered on a later try (outside29)
    control: Exchange | None = None
    #: the same ``a!`` after one more break (:attr:`HeardProbe.recheck`; None: none went)
    recheck: Exchange | None = None
    #: taken by a late reply: one naming the address came after the probe's window
    late: bool = False


@dataclass
class HeardProbe:
    """A command sent once after a break (its answer, or its silence, is the point) and the
    control that follows it: an ``a!`` sent the same way (a break, the same marking, once).

    Silence is evidence only from a sensor shown to be listening at that moment: a sensor
    that needs longer than the probe gave it to wake (R-7.0-05) misses the probe and the
    control alike, and its silence then shows nothing."""

    probe: Exchange
    control: Exchange | None  # None: no marking made the sensor hear a one-shot a!
    marking: float | None
    #: the same a! after the break after the control's, sent where the probe was silent and
    #: the control answered: the probe's wake-up and the control's are two breaks, and a
    #: sensor that wakes late after every second one (slow-wake-every-other) missed the probe
    #: and answered the control (truth36). Two answered wakes in a row show it hears every one.
    recheck: Exchange | None = None

    @property
    def listening(self) -> bool:
        """The control was answered (:func:`shows_listening`: by a valid reply where it
        maybe collided itself), and so was the recheck where one went, and the probe met no
        sensor characters: a probe that may have collided (a stray character just before
        its break, within the stamps' uncertainty) may not have been heard, so its silence
        shows nothing."""
        control = self.control
        return (
            control is not None
            and shows_listening(control)
            and not self.woke_differently
            and not self.probe.maybe_collided
        )

    @property
    def woke_differently(self) -> bool:
        """The control was answered, the recheck after the next break not: the sensor hears
        a one-shot a! after some breaks only, so the probe's break shows nothing of it."""
        return self.recheck is not None and not shows_listening(self.recheck)

    @property
    def exchanges(self) -> list[Exchange]:
        sent = [self.probe, self.control, self.recheck]
        return [ex for ex in sent if ex is not None]


@dataclass
class Aimed(Generic[T]):
    """A timed probe sent until it landed in the window it aimed at (:meth:`SensorSession.aim`):
    every try in order, and the one that landed (None: none did in the tries allowed)."""

    tries: list[T]
    landed: T | None

    @property
    def last(self) -> T:
        """What the case judges: the try that landed, else the last one (whose case then
        says it missed)."""
        return self.landed if self.landed is not None else self.tries[-1]

    @property
    def missed(self) -> str:
        """For a detail: how many tries went out, when more than one did."""
        if len(self.tries) == 1:
            return ""
        if self.landed is None:
            return f" (none of {len(self.tries)} tries landed in the window it aimed at)"
        return f" (try {len(self.tries)}: the earlier missed the window they aimed at)"


PROBE_ROUNDS = 6  # wake-ups of the bench probe at the start of a real-link run
PROBE_IDLE = 0.12  # s: marking before each, so each wake-up is from standby
#: Marking after a break (s) with which a one-shot ``a!`` is tried, shortest first, until the
#: sensor answers: the way one-off probes are then sent (:meth:`SensorSession.hearing_marking`).
#: The first is the tool recorder's own; the last lies past the 100 ms standby limit, which
#: is sound because every probe is checked by a control sent the same way.
HEARING_MARKINGS = (9e-3, 25e-3, 50e-3, 85e-3, 120e-3)
#: A hand-made wake-up whose break came back this much past the marking it aims at (a lost
#: echo, a stalled host) is sent again rather than judged (issue 18), at most PROBE_TRIES times;
#: so is a timed probe of a case that landed outside the window it aimed at (:meth:`aim`).
PROBE_LATE = 20e-3  # s
PROBE_TRIES = 5


#: Commands a whole-run judge may have sent again to confirm a rare deviation in their
#: replies (:meth:`SensorSession.reprobe`): they change nothing in the sensor, no measurement
#: starts and no address moves, so the repeats leave the run as it was.
REPROBE_KINDS = frozenset(
    {
        Kind.ACKNOWLEDGE,
        Kind.IDENTIFY,
        Kind.DATA,
        Kind.CONTINUOUS,
        Kind.IDENTIFY_MEASUREMENT,
        Kind.METADATA,
    }
)

#: The high-volume data index read past any measurement's data (R-5.2-06).
PAST_DATA_INDEX = 999

#: Breaks (s) tried before a device that ignored the usual 13 ms break is called absent.
LONGER_BREAKS = (30e-3, 60e-3, 100e-3)


class NoDeviceAnswered(RuntimeError):
    """Nothing answered at the address: a wiring/power/address problem, not a verdict."""


class SensorSession(Session):
    def __init__(
        self,
        link: Link,
        *,
        address: str | None = None,
        declaration: Declaration | None = None,
        forced_version: str | None = None,
        bus: tuple[tuple[str, str | None], ...] = (),
    ) -> None:
        self.link = link
        self.master = WatchedToolRecorder(link)
        self.declaration = declaration or Declaration()
        self.requested_address = address or self.declaration.address
        self.address = self.requested_address or "0"
        self.forced_version = forced_version or self.declaration.sdi12_version
        self.identity: Identification | None = None
        self.ident_exchange: Exchange | None = None
        self.assumptions: list[str] = []
        self.address_notes: list[str] = []  # what every address change left behind
        #: why the sensor can no longer be reached (a restore that found it nowhere), or None
        self.lost: str | None = None
        #: what ``?!`` was answered while finding the address (None: not asked, or silence)
        self.queried: str | None = None
        #: the aAb! that found out whether an undeclared address is settable (None: not tried)
        self.address_trial: Trial | None = None
        self._cache: dict[Any, Any] = {}
        self.view_disagreements = 0  # stimuli whose view record differed (see _as_seen)
        #: every measurement a case made anew, outside the cache (:meth:`fresh_measurement`):
        #: the wait rules' cases judge the cached ones, the whole-run case these (truth31)
        self.remeasured: list[Measurement] = []
        #: the concurrent measurements a case disturbed on purpose (:meth:`disturbed_
        #: measurement`), each with the part of its wait past the disturbance: the whole-run
        #: wait case judges their quiet there (truth35)
        self.disturbed: list[Measurement] = []
        #: the measurement codes a family may be tried with (None: all; a profile's groups)
        self.groups: frozenset[str] | None = None
        #: every sensor on the line with its aI! reply, when the DUT is not alone on it
        self.bus = bus
        #: the other sensors' addresses: never a spare or foreign address, never ``?!``
        self.others = frozenset(a for a, _ in bus if a != self.address)

    # -- discovery ----------------------------------------------------------------------------
    def discover(self) -> None:
        """Find the address (``?!`` if none was given) and read ``aI!`` to pick the rule set."""
        if self.requested_address is None and not self.shared:
            ex = self.master.query_address()
            body, _ = split_line(ex.reply_text)
            self.queried = body if ex.answered else None
            if ex.answered and len(body) == 1 and body in cmd.ADDRESS_CHARS:
                self.address = body
                self.assumptions.append(f"address {body!r} found with ?! (one sensor on the bus)")
            else:
                self.assumptions.append("no answer to ?!; assuming address '0'")
        ex = self.master.identify(self.address)
        self.ident_exchange = ex
        if not self._answered_here(ex):
            ack = self.master.acknowledge(self.address)
            if not self._answered_here(ack) and self._find_a_way_in():
                ex = self.master.identify(self.address)  # the break that woke it, again
                self.ident_exchange = ex
        body, _ = split_line(ex.reply_text)
        self.identity = parse_ident(body, expected_address=self.address) if ex.answered else None
        if not self.link.info.virtual_time:
            self.probe_bench()
        if self.forced_version:
            self.assumptions.append(
                f"rule set v{format_version(self.forced_version)} forced by the user/declaration"
            )

    def _find_a_way_in(self) -> bool:
        """``a!`` and ``aI!`` went unanswered after 13 ms breaks: before calling the device
        absent, try what a partial or hidden device may still answer. Longer breaks (30, 60
        and 100 ms: a sensor that wakes only on those FAILs R-7.0-04 in its case, and is judged
        on the rest with breaks it hears; True), then ``?!`` (a sensor that answers it at the
        address is there and is judged on what it does: False, the suite goes on). Only total
        silence raises :class:`NoDeviceAnswered` (exit 5)."""
        if self._wakes_on_longer_breaks():
            return True
        unanswered = (
            f"no device answered at address {self.address!r} (a! and aI! got no reply after "
            f"retries, nor a! after breaks of up to {LONGER_BREAKS[-1] * 1e3:.0f} ms"
        )
        if self.shared:  # every sensor on the line would answer ?!
            raise NoDeviceAnswered(
                f"{unanswered}); ?! is not sent on a bus shared with other sensors"
            )
        query = self.master.query_address()
        body, _ = split_line(query.reply_text)
        self.queried = body if query.answered else None
        if query.answered and body == self.address:
            self.assumptions.append(
                f"a! and aI! went unanswered, ?! was answered '{body}': judged on what the "
                "device does (no identification: the rule set is assumed)"
            )
            return False
        other = f"; ?! was answered '{escape(query.reply_text)}'" if query.answered else ""
        if not query.answered:
            found = self._answering_addresses()
            if len(found) == 1 and self.requested_address is None:
                self.address = found[0]
                self.assumptions.append(
                    f"no answer to ?! nor at '0'; of the {len(ADDRESS_CHARS)} addresses asked "
                    f"with a!, only {found[0]!r} answered: the device is judged there"
                )
                return True
            if found:
                where = ", ".join(repr(a) for a in found)
                pick = (
                    f"judge the device there with --address {found[0]}"
                    if len(found) == 1
                    else "more than one device answers: pick one with --address"
                )
                raise NoDeviceAnswered(
                    f"{unanswered}; ?! went unanswered, a! was answered at {where}): {pick}"
                )
        named = query.answered and len(body) == 1 and body in ADDRESS_CHARS
        if named and not self.requested_address:  # the address was only assumed
            self.assumptions.append(
                f"no answer at the assumed address {self.address!r} (the first ?! went "
                f"unanswered); ?! asked again was answered '{body}': the device is judged there"
            )
            self.address = body
            return True
        if named:
            # The device is there, at another address: "check its reply format" (what it
            # said was a well-formed ?! reply) or the wiring would send the user astray.
            raise NoDeviceAnswered(
                f"{unanswered}{other}): the device is at address {body!r}; judge it there "
                f"with --address {body} (or the declaration's address), or give no address "
                "and the tool asks with ?!"
            )
        talked = self._talked()
        raise NoDeviceAnswered(
            f"{unanswered}{other})"
            + (talked or ". Check wiring and power, or try ?! with one sensor on the bus.")
        )

    def _wakes_on_longer_breaks(self) -> bool:
        """``a!`` after 30, 60 and 100 ms breaks: True, the breaks kept from here, if one is
        answered by a device at the address (:meth:`_find_a_way_in`)."""
        usual = self.master.policy
        for duration in LONGER_BREAKS:
            with self._policy_for_now(break_duration=duration):
                answered = self._answered_here(self.master.acknowledge(self.address))
            if answered:
                self.master.policy = usual.but(break_duration=duration)  # kept from here
                self.assumptions.append(
                    f"a! and aI! went unanswered after {usual.break_duration * 1e3:.0f} ms "
                    f"breaks, a! answered after a {duration * 1e3:.0f} ms one: the tool "
                    f"recorder's breaks are {duration * 1e3:.0f} ms from here (R-7.0-04 judges "
                    "the short ones)"
                )
                return True
        return False

    def _answered_here(self, ex: Exchange) -> bool:
        """Whether ``a!`` or ``aI!`` at the address in use was answered by a device there: any
        reply counts (a malformed one is that device's to be judged on) but a bare other
        address. '5<CR><LF>' to '0!' is no sensor at '0': a sensor at '5', deaf to the first
        ``?!`` while it booted, answered it late from its buffer (the sixteenth round's
        lagopus sketch), and a run judged at '0' FAILed a!, aI! and every command on the
        silence of a sensor that is not there; ``_find_a_way_in`` asks ``?!`` again."""
        body, _ = split_line(ex.reply_text)
        named = len(body) == 1 and body in ADDRESS_CHARS and body != self.address
        return ex.answered and not named

    def _answering_addresses(self) -> list[str]:
        """Every other address that answers ``a!`` once (no retries: about 80 ms an address on
        a real bus, 5 s for all 61): a sensor that ignores ``?!`` at an address that is not
        '0' is found instead of called absent (seed 4158, ignores-query with
        factory-address-not-zero). Only for a device alone on the line (not ``shared``)."""
        with self._policy_for_now(retries_per_sequence=0, sequences=1):
            return [
                a for a in ADDRESS_CHARS
                if a != self.address and self.master.acknowledge(a).answered
            ]  # fmt: skip

    @contextmanager
    def _policy_for_now(self, **changes: Any) -> Iterator[None]:
        """The tool recorder's policy with ``changes`` for what runs inside, the usual one
        back after it even when the link fails there: discovery tries longer breaks and
        single asks without leaving them in force for the suite."""
        usual = self.master.policy
        self.master.policy = usual.but(**changes)
        try:
            yield
        finally:
            self.master.policy = usual

    def _talked(self) -> str:
        """What the device sent although nothing it sent was a reply: a sensor whose replies
        lack CR LF, or that answers the wrong command, is talking, so the stop must not send
        its user to the wiring (seen on an outside sensor firmware, docs/kit.md). Only for a
        device alone on the line: on a shared bus the other sensors' characters are heard."""
        heard = [
            e for e in self.link.transcript.events if e.kind is EventKind.CHAR and e.origin != TOOL
        ]
        if not heard:
            return ""
        return (
            f". The device did talk: {len(heard)} character(s), first "
            f"'{escape(decode_7e1(heard[:12]))}' at t={heard[0].start:.3f} s, none of it "
            "taken as a reply to a! or aI!: check its reply format (CR LF) and address, not "
            "the wiring"
        )

    def claim(self) -> DutClaim:
        return sensor_claim(self.identity, self.ident_exchange, self.forced_version, self.version)

    def link_facts(self) -> dict[str, Any]:
        """The tool recorder drove the line: how often the DUT talked over it, and how often
        it held a command back for a line still busy."""
        self.master.note_collisions()
        return {"collisions": self.master.collisions, "talk_holds": self.master.holds}

    @property
    def uncertainty(self) -> float:
        """The timing uncertainty findings use now (s): what the link has measured of its own
        stamps so far (never less than its declared floor), widened by the user's figure
        (applied where the port was opened)."""
        return self.link.timing_uncertainty()

    @property
    def stamp_uncertainty(self) -> StampUncertainty:
        """:attr:`uncertainty`, plus where a real link saw its own stamps irregular (a link in
        virtual time has no such places)."""
        local = None if self.link.info.virtual_time else self.link.uncertainty_between
        return StampUncertainty(self.uncertainty, local)

    def probe_bench(self, rounds: int = PROBE_ROUNDS) -> None:
        """Measure the bench before judging anything (real links): a few wake-ups and
        acknowledgements put echo, latency and jitter figures in the link's meter, so the
        first timing finding already rests on a measured uncertainty."""
        for _ in range(rounds):
            self.idle(PROBE_IDLE)
            self.master.transact(f"{self.address}!", force_break=True)
        self.assumptions.append(f"bench probed ({rounds} wake-ups): {self.bench_summary()}")

    def bench_summary(self) -> str:
        meter, echo = self.link.meter, self.link.echo
        if meter is None:
            return f"declared ±{self.link.info.timing_uncertainty * 1e3:.2f} ms"
        said = "interface echoes" if echo is not None and echo.echoes else "no echo"
        return f"{said}; {meter.summary()}"

    @property
    def version(self) -> str:
        """The rule set: forced > the ``ll`` of ``aI!`` > v1.4 (newest) as an assumption."""
        if self.forced_version:
            return self.forced_version
        if self.identity and self.identity.version in VERSIONS:
            return self.identity.version
        if "version" not in self._cache:
            self._cache["version"] = True
            self.assumptions.append("aI! gave no usable version; judging against v1.4")
        return V14

    @property
    def is_v14(self) -> bool:
        return is_v14(self.version)

    # -- cached stimuli ------------------------------------------------------------------------
    def once(self, key: Any, make: Callable[[], T]) -> T:
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    def command(self, code: str) -> Command:
        """``"MC1"`` -> the parsed command for this DUT's address."""
        return parse_command(f"{self.address}{code}!")

    def exchange(self, code: str, *, binary: bool | None = None) -> Exchange:
        """The cached reply to one command (``"I"``, ``"R0"``, ``"IMC_001"``...).

        ``Rn``/``RCn`` come from :meth:`continuous_pairs`, made as one unit."""
        if code in CONTINUOUS:
            self.continuous_pairs()
        return self.once(("x", code), lambda: self.fresh_exchange(code, binary=binary))

    def fresh_exchange(self, code: str, *, binary: bool | None = None, **kw: Any) -> Exchange:
        mark = live_cut(self.link.transcript).mark(self.link.transcript.events)
        made = self.master.transact(self.command(code), binary=binary, **kw)
        seen = self._rebuilt(mark).exchanges
        return self._as_seen(made, seen[0] if len(seen) == 1 else None)

    def measurement(self, code: str) -> Measurement:
        """The cached full measurement for ``"M"``, ``"MC"``, ``"C9"``, ``"HA"``, ``"HB"``..."""
        return self.once(("m", code), lambda: self._shared_measurement(code))

    def _shared_measurement(self, code: str) -> Measurement:
        """A cached measurement as it is made, with what must follow it at once: after
        ``aHB!`` the reads past its packets (:meth:`packets_past_data`)."""
        m = self._measure(code)
        if code == "HB" and self.link.info.binary and shows_support(m):
            self._cache[("past-data", code)] = self._read_past_data(m)
        return m

    def packets_past_data(self) -> list[Exchange]:
        """``aDBn!`` past the data of the cached ``aHB!`` measurement: the index after its last
        packet (when it was complete) and ``aDB999!``, read right after its collection. The DB
        indices refer to the latest measurement, so they ride on the one every case shares
        rather than on a measurement of their own (issue 22: one ``aHB!`` less, 4.4 s of bus
        time). Empty where HB announced no values or the link carries no binary packets."""
        self.measurement("HB")
        return self._cache.get(("past-data", "HB"), [])

    def _read_past_data(self, m: Measurement) -> list[Exchange]:
        probes = [PAST_DATA_INDEX]  # no measurement of at most 999 values fills 1000 packets
        if m.complete:
            probes.insert(0, len(m.data))
        return [self.fresh_exchange(f"DB{i}") for i in probes]

    def fresh_measurement(self, code: str, **kw: Any) -> Measurement:
        """The measurement ``code`` made anew, kept in :attr:`remeasured`: a late or
        malformed service request here is the sensor's as much as in the cached one."""
        m = self._measure(code, **kw)
        self.remeasured.append(m)
        return m

    def measure_as_sent(self, command: Command) -> Measurement:
        """``command`` measured by the engine at once, its record the engine's (a case that
        times it against its own break: no view cut), kept in :attr:`remeasured` as
        :meth:`fresh_measurement`'s are."""
        first = len(self.link.transcript.events)
        m = self.master.measure(command)
        self.master.mark_stalls((), first, [m])  # its wait, as fresh_measurement's
        self.remeasured.append(m)
        return m

    def _measure(self, code: str, **kw: Any) -> Measurement:
        mark = live_cut(self.link.transcript).mark(self.link.transcript.events)
        made = self.master.measure(self.command(code), **kw)
        seen = self._rebuilt(mark).measurements
        self.master.mark_stalls((), mark.first, [made])  # its wait, as the view's (_rebuilt)
        return self._as_seen(made, seen[0] if len(seen) == 1 else None)

    # -- what the cases judge: the stimulus as the wire shows it -------------------------------
    def _rebuilt(self, mark: Mark) -> Rebuilt:
        """The records the role-neutral view rebuilds from what the stimulus left on the wire
        since ``mark`` (the same view offline judging reads), with the tool recorder's own
        policy."""
        transcript = self.link.transcript
        # the transmissions of the run's one cut (live_cut), where they are what a cut of
        # these events alone gives; else these events cut on their own
        shared = live_cut(transcript).since(transcript.events, mark)
        policy, uncertainty = self.master.policy, self.uncertainty
        if shared is None:
            view = read_view(transcript.since(mark.first))
            rebuilt = rebuild_records(view, policy, uncertainty=uncertainty)
        else:
            rebuilt = records_of(shared, policy, uncertainty=uncertainty)
        # reads the host stalled over, as the engine's own records are marked (the same
        # notes: the engine has waited for the link to write them)
        self.master.mark_stalls(rebuilt.exchanges, mark.first, rebuilt.measurements)
        return rebuilt

    def _as_seen(self, made: R, seen: R | None) -> R:
        """The view's record of a stimulus, which the cases judge, so a live run's verdicts
        rest on the view a recording is judged by. Where the view reads the wire otherwise
        than the tool recorder did (a different command, another count of exchanges) the
        tool recorder's record stands and the run's assumptions say so: never a silent
        difference."""
        if seen is not None and same_reading(made, seen):
            _carry_late_before(made, seen)
            return seen
        self.view_disagreements += 1
        note = (
            f"{self.view_disagreements} stimulus record(s) the view read otherwise than the "
            "tool recorder (its record was judged)"
        )
        self.assumptions[:] = [a for a in self.assumptions if "the view read otherwise" not in a]
        self.assumptions.append(note)
        return made

    def continuous_pairs(self) -> dict[int, tuple[Exchange, Exchange]]:
        """``{n: (aRn!, aRCn!)}`` for n = 0..9, made once as a unit in a fixed order
        (``aRC0!``..``aRC9!``, then ``aR0!``..``aR9!``: the order a full run has always sent
        them in): a sensor's answer to ``aRn!`` may depend on the command before it (R0
        first, say), so every case judges the same sequence whichever asks first."""
        if "continuous" not in self._cache:
            for code in CONTINUOUS:
                self.once(("x", code), lambda c=code: self.fresh_exchange(c))
            self._cache["continuous"] = True
        return {i: (self._cache[("x", f"R{i}")], self._cache[("x", f"RC{i}")]) for i in range(10)}

    def standard_stimuli(self) -> list[Exchange | Measurement]:
        """The stimuli every full run makes (cached, so a full run sends nothing more): ``a!``,
        ``aI!``, every measurement of :data:`M_FAMILY` and :data:`C_FAMILY` with its D
        replies, ``aR0!``..``aRC9!`` and the declared extended commands. A case that judges
        the run's replies as a whole asks for them, so a partial run (``-k``) that selects it
        judges every kind of reply a full run does."""
        made: list[Exchange | Measurement] = [self.exchange(""), self.exchange("I")]
        made += self.family(M_FAMILY + C_FAMILY)
        made += [ex for pair in self.continuous_pairs().values() for ex in pair]
        made += [self.exchange(name) for name in self.declaration.extended]
        return made

    def fill_data_buffer(self, code: str) -> None:
        """Make sure the sensor's data buffer holds values: run the measurement ``code``
        again unless the last command the tool sent it was already a D read answered with
        values, or ``code`` delivered none when it was cached (it would fill nothing). For
        cases that judge whether an abort emptied the buffer, which must not depend on what
        the case before them left in it."""
        if self.measurement(code).value_count and not self.master.buffer_holds_values(self.address):
            self.fresh_measurement(code)

    def values_after_standby(self, m: Measurement) -> list[Exchange]:
        """With ``m``'s values read to their end: standby, a break, then ``aD0!`` and on to
        the D command that gave ``m`` its first values (:func:`first_filled`) while each
        reads empty (after ``aHB!``: ``aDB0!``). The steps that come before an abort without
        the abort: an empty D0 after an abort shows the abort emptied the buffer only where
        these leave values in it (a sensor that empties it once read, at the next break or in
        standby gives the same empty D0 whatever the abort does: abort-keeps-old-data beside
        buffer-cleared-after-read, -by-break, data-lost-after-standby PASSed R-4.4.5.1-02,
        R-4.4.7.1-02 and R-5.3-01)."""
        self.to_standby()
        if m.binary:  # aHB!'s values are read as packets; its groups never start late
            return [self.fresh_exchange("DB0", binary=True, force_break=True)]
        # the D replies of whatever measurement the buffer holds: with or without a CRC as
        # the engine's last measurement at this address had it, not as ``m`` has it
        ds = [self.fresh_exchange("D0", force_break=True)]
        while len(ds) <= first_filled(m) and ds[-1].answered and empty_data_reply(ds[-1]):
            ds.append(self.fresh_exchange(f"D{len(ds)}"))
        return ds

    def feature(self, name: str) -> bool | None:
        return self.declaration.feature(name)

    def reprobe(self, commands: Iterable[str], times: int = REPROBE_TIMES) -> list[Exchange]:
        """Send each of ``commands`` ``times`` times again (once per run and command), the
        way a recorder sends it, so a judge that found a rare deviation in its reply on a
        real-time link sees whether it recurs at the same place (issue 18): a device's does,
        a stalling host's does not. The repeats are on the transcript like any exchange, and
        the judge reads them there. A command that is not this sensor's or of a kind that
        changes its state (:data:`REPROBE_KINDS`) is not sent; the judge stays undecided."""
        made: list[Exchange] = []
        for text in commands:
            made += self.once(("reprobe", text), lambda t=text: self._reprobe(t, times))
        return made

    def _reprobe(self, text: str, times: int) -> list[Exchange]:
        try:
            command = parse_command(text)
        except CommandError:
            return []
        if command.address != self.address or command.kind not in REPROBE_KINDS:
            return []
        self.link.transcript.note(
            self.link.now(),
            f"re-probe: {escape(text)} sent {times} times again to see whether a rare "
            "deviation in its reply recurs at the same place",
        )
        return [self.master.transact(command) for _ in range(times)]

    def late_start_probe(self) -> Exchange:
        """``a!`` sent once after a break from standby, then :data:`LATE_START_LISTEN` s of
        listening with no retry, once a run: a reply that begins after it can only be its
        reply, timed from it alone (the whole-run cut places it after the command). For a
        sensor whose every reply began after the recorder's retry, in time from the retry
        and late from the try before (R-7.0-10 undecided, :func:`~conformance.judges.wire.
        starts_after_a_retry`); an answered ``a!`` changes nothing in the sensor."""

        def send() -> Exchange:
            self.link.transcript.note(
                self.link.now(),
                f"late-start probe: {self.address}! sent once after a break with no retry, "
                f"listened {LATE_START_LISTEN:.1f} s, to time a reply that began after a retry",
            )
            self.idle(self.standby_idle())
            ex = self.master.raw(f"{self.address}!", break_first=True)
            self.listen(LATE_START_LISTEN)
            return ex

        return self.once("late-start-probe", send)

    def hear_late(self, ex: Exchange) -> Exchange:
        """A one-shot ``ex`` (sent once, no retry) left unanswered, from a sensor seen to
        start its replies late (:class:`~.late_watch.LateStartWatch`): listen until that
        start (and a character) past its command, bounded by
        :data:`~.late_watch.LATE_START_MAX`, and keep what came as ``ex.heard_late``: its
        late reply, which the 30 ms window missed and the next transmission broke off
        (R-7.0-07's probe read "no reply" from the replies-after-retry sensor, truth12).
        Silence through it is silence; a sensor never seen late is not waited for."""
        late = self.master.watch.late.start
        end = ex.attempts[0].command_end if ex.attempts else None
        if ex.answered or late is None or end is None:
            return ex
        # the start was measured between two stamps, and the reply's is one more: twice the
        # link's uncertainty past it (none on the sim)
        until = end + late + CHAR_TIME + 2 * self.uncertainty
        heard = self.link.receive(max(until, self.link.now()), until=bool)
        if heard and heard[-1].char7 != LF:  # the rest of it, to its LF or a pause
            heard += self.link.receive(
                heard[-1].end + LATE_START_LISTEN,
                until=lambda got: got[-1].char7 == LF,
                idle=self.master.policy.reply_idle,
            )
        ex.heard_late = heard
        return ex

    def stalled_since(self, first: int, start: float) -> Stall | None:
        """The first stall of the tool's own host noted since transcript event ``first`` that
        may have held up the line's reading from ``start`` until now (truth30): a timed
        probe's decisive span, from the reply or break its marking counts from to the end of
        its read. :attr:`~conformance.tool_recorder.records.Attempt.stall` marks each read
        alone; a standby probe rests on the span between them too: a reply stamped late by
        the burst that delivered it makes the marking before the probe look shorter than the
        sensor saw (silence at 150 ms taken for silence at 101.9), a break's end stamped
        before the host let go of the line makes it look longer, and a cut read hides the
        answer. What the probe shows there is the host's, either way."""
        return stalled_over(self.master.stalls_since(first), start, self.link.now())

    def listen(self, duration: float) -> list[Event]:
        """Keep the line marking for ``duration`` s and return what the DUT sent meanwhile."""
        return self.link.receive(self.link.now() + duration)

    def listen_until(self, at: float) -> list[Event]:
        """:meth:`listen` up to ``at`` (at once if it has passed): a window for silence counted
        from the event its rule counts from (a reply's end, ttt and the engine's late-service-
        request grace after it), not from when the case got there, which lay a break, a
        turnaround and a read's end later (issue 22). Characters that started by ``at`` and
        arrive later are waited for, as :meth:`listen` does: they are evidence."""
        return self.link.receive(max(at, self.link.now()))

    def idle(self, marking: float) -> list[Event]:
        """Keep the line marking until it has marked ``marking`` s since its last activity,
        and return what the DUT sent meanwhile: an idle that a rule counts as marking (a
        sensor in standby after 100 ms of it, R-7.0-15; a wake-up from standby). Counted from
        the wire, not from when the case got there: after a read that ran to its deadline
        the line has marked that long already, and :meth:`listen` would also wait a frame
        and the link's latency past the end (issue 22, sixth round)."""
        return self.mark_until(self.link.last_activity() + marking)

    def standby_idle(self) -> float:
        """The marking (s) the cases leave before a stimulus that needs the sensor in standby
        (R-7.0-15: after 100 ms of marking, 0.4 ms of tolerance): :data:`PROBE_IDLE`, as
        before the bench probe's and the hearing search's wake-ups, or, on a link stamped
        more loosely than ±9.8 ms, the limit plus twice the uncertainty (once for the stamp
        the idle counts from, once for the one it ends at), so the line surely marked past
        the limit. PROBE_IDLE's margin over the limit (19.6 ms on the sim) still covers the
        catalog's sensor slow to sleep (standby-after-108ms, a fault of R-7.0-15 only) for
        the section 7 cases that need standby. It was a fixed 150 ms in the timing cases
        and 200 ms in the data-retention ones, 134-193 ms of a real run's bus time apiece
        beyond its lower bound (issue 22)."""
        return max(PROBE_IDLE, STANDBY_MARKING + TOLERANCE + 2 * self.uncertainty)

    def to_standby(self) -> float:
        """Keep the line marking until a sensor keeping R-7.0-15 is surely in standby, and
        return how long the line marked since its last activity (s): :meth:`standby_idle`
        after that activity, or, when nothing came from the DUT since the tool's last break,
        after the latest moment a sensor woken by that break may have woken (100 ms after it,
        R-7.0-07), as the emulator's slow-wake sensor counts its standby from its wake-up: a
        foreign command or a probe it did not hear leaves it awake until then."""
        last = self.link.last_activity()
        at = last + self.standby_idle()
        woken = _unanswered_break_end(self.link.transcript.events)
        if woken is not None:
            at = max(at, woken + WAKE_LIMIT + self.standby_idle())
        self.mark_until(at)
        return at - last

    def mark_until(self, at: float) -> list[Event]:
        """Keep the line marking so that the tool's next command can go out at ``at`` (a timed
        probe's marking), and return what the DUT sent meanwhile. :meth:`listen` up to ``at``
        would overshoot on a real link: a read whose limit lies ahead waits a frame and the
        link's latency past it for characters that started in time, which pushed a follow-up
        aimed 12 ms inside the 87 ms window out of it behind an RFC 2217 port. The wait ends
        at ``at`` instead and takes in what has arrived; the tool's look before transmitting
        (:meth:`ToolRecorder.look_before_transmit`) is over by then unless ``at`` lies within
        the turnaround and the look after the DUT's last character, and a DUT that talked
        meanwhile still holds the command back (:meth:`ToolRecorder.clear_to_send`)."""
        self.link.wait_until(at)
        return self.link.receive(self.link.now())

    def probe(
        self,
        text: str,
        *,
        break_s: float | None,
        marking_s: float = 9e-3,
        gap: float = 0.0,
        idle_before: float = 0.0,
        standby: bool = False,
        collide: bool = False,
    ) -> Exchange:
        """Send ``text`` once with a hand-made wake-up: ``idle_before`` s of marking, then a
        spacing of ``break_s`` (None: no break at all), then ``marking_s`` of marking.
        Timing cases use it to present breaks and markings near the section 7 thresholds.
        A break whose sending overran the aimed marking by more than ``PROBE_LATE`` (an
        echo that never came back) is sent again (:meth:`aim`): the probe lands where it
        aimed or, after ``PROBE_TRIES``, goes out late and its case judges the marking it got.
        The break waits for a quiet line like every transmission of the tool
        (:meth:`ToolRecorder.clear_to_send`); ``collide`` sends it into a talking DUT on purpose.
        ``standby``: the wake-up is from standby (:meth:`to_standby` before it, instead of
        ``idle_before``), each try's."""
        if standby:
            self.to_standby()
        elif idle_before:
            self.idle(idle_before)
        if break_s is not None:

            def send(tries: int) -> Event:
                if tries and standby:
                    self.to_standby()
                elif tries:
                    self.idle(max(idle_before, PROBE_IDLE))  # from standby, as the first was
                self.master.clear_to_send(collide=collide)
                return self.link.send_break(break_s, exact=True)

            def late(brk: Event) -> str | None:
                # the marking runs from the break's end, not from when the link returned
                over = self.link.now() - (brk.end + marking_s)
                if over <= PROBE_LATE:
                    return None
                return (
                    f"the break came back {over * 1e3:.2f} ms past the "
                    f"{marking_s * 1e3:.2f} ms of marking it aimed at"
                )

            brk = self.aim(f"probe {text!r}", send, late).last
            self.link.wait_until(brk.end + marking_s)
        return self.master.raw(text, break_first=False, gap=gap, collide=collide)

    def aim(
        self,
        what: str,
        attempt: Callable[[int], T],
        miss: Callable[[T], str | None],
        *,
        tries: int = PROBE_TRIES,
    ) -> Aimed[T]:
        """Make a timed probe until it lands in the window it aims at (issue 18): behind an
        echoing interface or a stalled host a probe meant for 83 ms of marking may go out at
        98 ms, where it proves nothing about the rule it was for. ``attempt(n)`` makes try
        ``n`` (from 0; a later try puts the sensor back in the state the first needed);
        ``miss`` says how a try missed, or None when it landed. At most ``tries`` tries; each
        miss is a note on the transcript, and the verdict rests on the try that landed."""
        made: list[T] = []
        for n in range(tries):
            got = attempt(n)
            made.append(got)
            why = miss(got)
            if why is None:
                return Aimed(made, got)
            then = "sent again" if n + 1 < tries else f"no more tries ({tries})"
            self.link.transcript.note(self.link.now(), f"{what}: {why}; {then}")
        return Aimed(made, None)

    # -- one-off probes, sent the way the sensor was shown to hear -----------------------------
    def hearing_marking(self) -> float | None:
        """The marking after a break with which the sensor answers a one-shot ``a!``: the
        shortest of :data:`HEARING_MARKINGS` that worked (found once, from standby), or None
        if none did. One-off probes (foreign addresses, malformed commands) are sent with it,
        so a sensor that is slow to wake (a fault of R-7.0-05 judged elsewhere) still hears
        them and the rules they are about get judged. It is found at :attr:`address`: a case
        that moves the sensor elsewhere asks for it before the move."""
        return self.once("hearing-marking", self._find_hearing_marking)

    def _find_hearing_marking(self) -> float | None:
        for marking in HEARING_MARKINGS:
            self.idle(PROBE_IDLE)
            ex = self.master.raw(f"{self.address}!", break_first=True, marking=marking)
            if ex.answered:
                if marking != HEARING_MARKINGS[0]:
                    self.assumptions.append(
                        f"a one-shot {self.address}! after a break was first answered with "
                        f"{marking * 1e3:.0f} ms of marking after it; one-off probes are sent so"
                    )
                return marking
        self.assumptions.append(
            f"no one-shot {self.address}! after a break was answered with any marking up to "
            f"{HEARING_MARKINGS[-1] * 1e3:.0f} ms: silence to one-off probes is not judged"
        )
        return None

    def acknowledgement(self, probes: list[Exchange]) -> list[Exchange]:
        """The controls for silence to ``a!`` ``probes``: whether the sensor answers ``a!`` at
        all (:func:`~conformance.preconditions.acknowledges`). None are needed when a probe
        was answered or an ``a!`` at its address drew a reply earlier in the run; else one
        ``a!`` now, after a break and with retries, as a recorder wakes a sensor. A probe
        answered only by what may be the characters that met it (:func:`shows_listening`)
        needs the control too."""
        if any(shows_listening(ex) for ex in probes) or self.address in self.master.acknowledged:
            return []
        return [self.master.transact(f"{self.address}!", force_break=True)]

    def acknowledges(self, probes: list[Exchange]) -> Unmet | None:
        """The "listening" outcome for silence to ``a!`` ``probes``: met if the sensor answers
        an ``a!`` (one of them, one earlier in the run, or the control :meth:`acknowledgement`
        sends now), unmet for a sensor that answers its other commands only."""
        probes = [*probes, *self.acknowledgement(probes)]
        return acknowledges(probes, self.address in self.master.acknowledged, self.address)

    def heard_probe(self, text: str, *, control_address: str | None = None) -> HeardProbe:
        """Send ``text`` once after a break with :meth:`hearing_marking`, then the control:
        ``a!`` (at ``control_address``, default the sensor's) sent the same way, and where
        the probe was silent and the control answered, the same ``a!`` after one more break
        (:attr:`HeardProbe.recheck`)."""
        marking = self.hearing_marking()
        probe = self.master.raw(text, break_first=True, marking=marking)
        control = None
        recheck = None
        if marking is not None:
            address = control_address or self.address
            control = self.master.raw(f"{address}!", break_first=True, marking=marking)
            if not probe.answered and shows_listening(control):
                # the silence is judged on the control: one more wake shows it is every wake's
                recheck = self.master.raw(f"{address}!", break_first=True, marking=marking)
        return HeardProbe(probe, control, marking, recheck)

    # -- address changes (always restored) -------------------------------------------------
    def address_change_supported(self) -> bool:
        """Declared, or found out with one change to a spare address and back."""
        declared = self.feature("address_change")
        if declared is not None:
            return declared
        return self.once("address-change", self._discover_address_change)

    def spare_address(self) -> str:
        """The address the address-change cases move the sensor to (and back from): on a
        shared bus never another sensor's."""
        taken = {self.address, *self.others}
        return next(a for a in "9876543210" + cmd.ADDRESS_CHARS[10:] if a not in taken)

    def foreign_address(self) -> str:
        """An address for "traffic to another sensor": one no address-change case ever gives
        the DUT, so even a sensor that keeps answering its old addresses is not addressed
        (and on a shared bus one no other sensor has: its silence is the point)."""
        taken = {self.address, *self.others}
        return next(a for a in "zyxwvu" + cmd.ADDRESS_CHARS[::-1] if a not in taken)

    @property
    def shared(self) -> bool:
        """Whether other sensors share the line: ``?!`` would draw every one's answer."""
        return bool(self.others)

    def bus_sensors(self) -> list[tuple[str, DutClaim]] | None:
        """Every sensor on the shared line with what its ``aI!`` said (``duts``); None alone."""
        if not self.bus:
            return None
        claims = []
        for address, reply in sorted(self.bus):
            if address == self.address:
                claims.append((address, self.claim()))
                continue
            body = split_line(reply)[0] if reply else ""
            ident = parse_ident(body, expected_address=address) if reply else None
            claims.append((address, DutClaim(ident, reply, ident.version if ident else None)))
        return claims

    def restore(self, changer: AddressChanger) -> str:
        """Put the sensor back (:meth:`AddressChanger.restore`) and note it. A sensor that
        answered ``a!`` earlier in the run and now at none of the addresses tried is lost:
        every later case would judge the silence of an address it no longer has (a PIC
        firmware that took '9' answers only lowercase letters; R-7.0-07 FAILed "no reply 90
        ms after the break" on it), so :attr:`lost` says why and the run stops. One that answers
        no ``a!`` and still answers ``?!`` with its address is there: "COULD NOT restore" was
        false for the twenty-third round's Due sensor, which refused ``0A$!`` by silence."""
        note = changer.restore()
        if changer.restored is False and self.lost is None:
            if self.master.acknowledged:
                self.lost = note
            elif (elsewhere := self._queried_elsewhere()) is not None:
                self.lost = f"{note}; ?! is answered {elsewhere} now"
            elif self.queried == self.address and not self.shared:
                # ?! still names it: where a! (never answered) cannot find it, ?! does
                changer.restored = None
                note = (
                    f"address '{self.address}' after the restore: ?! answered '{self.address}' "
                    f"(not checked with a!: the sensor answers no a! anywhere)"
                )
        self.address_notes.append(note)
        return note

    def _queried_elsewhere(self) -> str | None:
        """How ``?!`` is answered now, if not with the address it was answered with while
        finding it (None: it still is, or it never was, or other sensors share the line).
        A sensor that answers no ``a!`` cannot be checked at its address after a restore;
        its ``?!`` can. The eighteenth round's Arduino Due sensor (docs/kit.md) took
        ``0A$!`` as address -12 (``'$' - '0'``), answered ``?!`` '-12' from then on and
        nothing at '0': R-6.1-01, R-6.2-01/-05/-06/-07 FAILed and R-5.4-02 WARNed on the
        silence of an address it no longer had."""
        if self.shared or self.queried != self.address:
            return None
        ex = self.master.query_address()
        body, _ = split_line(ex.reply_text)
        if ex.answered and body == self.address:
            return None
        return f"'{escape(ex.reply_text)}'" if ex.answered else "by no one"

    def _discover_address_change(self) -> bool:
        changer = AddressChanger(self.master, self.address)
        target = self.spare_address()
        try:
            outcome = changer.change(target)
        finally:
            note = self.restore(changer)
        took = outcome.took
        self.address_trial = Trial(outcome.request, self.address, target, note)
        self.assumptions.append(
            "address change (aAb!) "
            + ("supported" if took else "not supported")
            + ", found by trying it"
        )
        return took

    def address_sweep(self, targets: str) -> Sweep:
        """Change to each address in ``targets`` and back; restore whatever happens."""
        changer = AddressChanger(self.master, self.address)
        refused, unanswered, heard, found_at = [], [], [], []
        try:
            for target in targets:
                if target == self.address:
                    continue
                outcome = changer.change(target)
                at_target = None
                if outcome.took and outcome.answered_after is None:
                    at_target = self._queried_at(changer, target)
                note = changer.restore()
                moved_back = at_target is not None and self._heard_back(changer)
                if moved_back:
                    heard.append(target)
                else:
                    if not outcome.took or outcome.answered_after is None:
                        refused.append(target)
                    if changer.found_at == target and not _heard(outcome.request):
                        found_at.append(target)
                    if outcome.took and outcome.answered_after is None:
                        unanswered.append(target)
                if not changer.restored and not moved_back:
                    break
        finally:
            note = self.restore(changer)
        return Sweep(changer.exchanges, refused, note, unanswered, heard, found_at)

    def _queried_at(self, changer: AddressChanger, target: str) -> Exchange | None:
        """For a sensor that answers no ``a!`` (none answered in the run), alone on the line,
        which took ``target`` by its reply and answered no ``b!`` poll: ``?!``, answered with
        ``target`` (the exchange), or None. The twenty-third round's Due sensor (docs/kit.md)
        takes every address 0-9 and answers only ``?!`` and ``aAb!``: the sweep stopped after
        '1' and R-4.3-03 stayed INCONCLUSIVE on the silence of a! it never answers."""
        if self.master.acknowledged or self.shared or self.queried != self.address:
            return None
        ex = self.master.query_address()
        changer.exchanges.append(ex)
        body, _ = split_line(ex.reply_text)
        return ex if ex.answered and body == target else None

    def _heard_back(self, changer: AddressChanger) -> bool:
        """Whether the restore just made moved the sensor back by a command at the address it
        was shown at (its ``bAa!`` answered with the original address: it heard a command
        there) and ``?!`` names the original address again: then the sweep goes on, though
        no ``a!`` could check the restore."""
        if changer.settled is None:
            return False  # checked with a!, or not moved back: the sweep decides as before
        ex = self.master.query_address()
        changer.exchanges.append(ex)
        body, _ = split_line(ex.reply_text)
        return ex.answered and body == self.address

    def try_invalid_address(self, bad: str) -> InvalidAddressAttempt:
        """Send ``aA<bad>!`` (raw: the grammar refuses it) and see whether the sensor took it.
        A reply naming ``bad`` that came late (in a later command's window: the control's,
        the restore's) says it moved as well: the restore then asks ``bad`` to move back,
        though the original answers ``a!`` (a sensor that answers ``a!`` anywhere was left
        at '$' and judged there, seed 7900: seven false FAILs), and it took ``bad``."""
        changer = AddressChanger(self.master, self.address)
        first = len(self.link.transcript.events)
        try:
            changer.tried.append(bad)  # if it took the bad address, restore moves it back
            heard = self.heard_probe(f"{self.address}A{bad}!")
            changer.exchanges.extend(heard.exchanges)
            body, _ = split_line(heard.probe.reply_text)
            accepted = heard.probe.answered and body == bad
            # it said it moved: restore asks '$' to move back even where the original
            # answers a! (a sensor that answers a! at any address, accepts-invalid-address
            # + answers-foreign-address, seed 4077, was left at '$': seven false FAILs)
            changer.unclear = changer.unclear or accepted
        finally:
            self.restore(changer)
        late = not accepted and self._named_since(first, bad)
        if late:
            changer.unclear = True
            self.restore(changer)
        return InvalidAddressAttempt(
            changer.exchanges,
            accepted or late,
            heard.listening,
            heard.control,
            heard.recheck,
            late=late,
        )

    def _named_since(self, first: int, address: str) -> bool:
        """Whether the sensor sent a reply naming ``address`` (a run of its characters that
        begins ``address<CR>``) in the transcript from event ``first`` on."""
        events = self.link.transcript.events[first:]
        dut = [e for e in events if e.kind is EventKind.CHAR and e.origin != TOOL]
        return any(decode_7e1(run).startswith(f"{address}\r") for run in runs(dut))

    def disturbed_measurement(self, command: Command, disturb: str) -> tuple[Measurement, Exchange]:
        """Start ``command``, send ``disturb`` while it runs, wait out ttt, then break and
        collect: how concurrent measurements are tested for (non-)aborts. A disturbance for
        the sensor's own address is sent with retries, so it is surely heard (its reply is
        the proof); one for another address is sent once, after a break with the marking the
        sensor was shown to hear (:meth:`hearing_marking`; none known: the default)."""
        marking = self.hearing_marking()  # found before the measurement: its a! would abort it
        first = len(self.link.transcript.events)
        m = self.master.measure(command, collect=False, wait="none")
        waited = len(self.link.transcript.events)
        self.listen(0.05)
        if disturb[:1] == self.address:
            poke = self.master.transact(disturb)
        else:
            poke = self.master.raw(disturb, break_first=True, marking=marking)
        if m.reply_end is not None and m.ttt:
            self.link.wait_until(m.reply_end + m.ttt + self.master.policy.ttt_margin)
            if disturb[:1] != self.address:  # aI! to itself aborts it: no wait left after
                self.link.reader_caught_up()
                self._keep_disturbed_wait(m, poke, self.link.transcript.events[waited:])
        self.master.collect(m, force_break=True)
        if self.disturbed and self.disturbed[-1] is m:
            self.master.mark_stalls((), first, [m])  # its wait, as a fresh measurement's
        return m, poke

    def _keep_disturbed_wait(self, m: Measurement, poke: Exchange, events: list[Event]) -> None:
        """Keep in :attr:`disturbed` the part of ``m``'s wait the whole-run wait case can
        judge (truth35), for a disturbance ``poke`` to another address (the measurement
        goes on through it, R-4.4.7-05; one to the sensor itself aborts it, and what the
        sensor sends after that abort is the abort rules' to judge: abort-sends-zero-reply's
        'a0000<CR><LF>' there is no concurrent measurement's service request): what the
        sensor sent (``events``) in runs begun :data:`~.late_watch.LATE_START_LISTEN` past
        the poke (a reply to it, however late, is the poke's, not the measurement's talk),
        where that part still reaches the measurement's ready time (ttt): a service request
        after a concurrent measurement comes then."""
        ends = [e.end for a in poke.attempts for e in (*a.command_events, *a.reply_events)]
        if m.reply_end is None or not m.ttt or not ends:
            return
        after = max(ends) + LATE_START_LISTEN
        if after >= m.reply_end + m.ttt:
            return  # the poke's reply window covers the time the measurement is ready
        dut = [e for e in events if e.kind is EventKind.CHAR and e.origin != TOOL]
        kept = [e for run in runs(dut) if run[0].start >= after for e in run]
        m.waited_events = kept
        self.disturbed.append(m)

    def family(self, codes: tuple[str, ...]) -> list[Measurement]:
        """Cached measurements for every command code of a family (``M_FAMILY``...); under a
        profile that limits the groups tried (``groups``), for those codes only."""
        return [self.measurement(code) for code in self.tried(codes)]

    def tried(self, codes: tuple[str, ...]) -> tuple[str, ...]:
        """``codes``, or those of them a profile lets the run try (``groups``)."""
        if self.groups is None:
            return codes
        return tuple(c for c in codes if c in self.groups)

    def defined(self, codes: tuple[str, ...]) -> list[Measurement]:
        """The measurements of ``codes`` that announced at least one value."""
        return [m for m in self.family(codes) if m.count]

    def declared_count(self, code: str) -> int | None:
        """The value count the declaration promises for ``code`` (its CRC twin shares it)."""
        counts = self.declaration.measurements
        if code in counts:
            return counts[code]
        plain = code[0] + code[2:] if code[1:2] == "C" and code[0] in "MC" else code
        return counts.get(plain)

    def check_declared_counts(self, codes: tuple[str, ...]) -> list[str]:
        """Where the sensor announces another count than declared: noted for the report."""
        notes = []
        for code in self.tried(codes):
            want = self.declared_count(code)
            got = self.measurement(code).count
            if want is not None and got != want:
                notes.append(f"declared {code} = {want} values, the sensor announced {got}")
        for note in notes:
            if note not in self.assumptions:
                self.assumptions.append(note)
        return notes

    def supports(self, code: str) -> bool:
        """Whether ``aHA!``/``aHB!`` (or a numbered group) announces values at all."""
        return bool(self.measurement(code).count)


def shows_support(m: Measurement) -> bool:
    """Whether a high-volume measurement counts as supported: values announced, or a reply
    too malformed to read a count from (judged as support); a well-formed "no values" is not."""
    return bool(m.count) or (m.start.answered and m.count is None)


def _exchange_shape(ex: Exchange) -> tuple[Any, ...]:
    return (
        ex.command,
        ex.text,
        tuple((a.reason, a.sequence, a.retry, len(a.reply_events)) for a in ex.attempts),
    )


def _same_exchange(made: Exchange, seen: Exchange) -> bool:
    """Whether two records read one exchange alike: the same command, attempts, and judged
    reply as 7E1 text and as 8N1 bytes. Both texts are pure functions of the judged reply's
    events, so where the two records hold the very same event objects (the view rebuilds
    from the events the link recorded for the engine: nearly always) they are equal without
    decoding either twice (issue 22: four decodes an exchange, about 5% of
    ``aIMn_00k!``'s CPU); else they are decoded and compared."""
    if _exchange_shape(made) != _exchange_shape(seen):
        return False
    mine, theirs = made.reply_events, seen.reply_events
    if len(mine) == len(theirs) and all(map(is_, mine, theirs)):
        return True
    return (made.reply_text, made.reply_bytes) == (seen.reply_text, seen.reply_bytes)


def same_reading(made: Exchange | Measurement, seen: Exchange | Measurement) -> bool:
    """Whether the view read a stimulus as the tool recorder did: the same command, replies,
    attempts and, for a measurement, the same ttt, count, values and service request."""
    if isinstance(made, Exchange) and isinstance(seen, Exchange):
        return _same_exchange(made, seen)
    if isinstance(made, Measurement) and isinstance(seen, Measurement):
        return (
            _same_exchange(made.start, seen.start)
            and (made.ttt, made.count, made.values, made.packets)
            == (seen.ttt, seen.count, seen.values, seen.packets)
            and made.service_request_end == seen.service_request_end
            and len(made.data) == len(seen.data)
            and all(map(_same_exchange, made.data, seen.data))
        )
    return False


def _heard(ex: Exchange) -> bool:
    """Whether ``ex`` drew anything from the DUT: a reply in a window, or late."""
    return ex.answered or bool(ex.heard_late)


def _carry_late_before(made: Exchange | Measurement, seen: Exchange | Measurement) -> None:
    """The engine's ``late_before`` links (:meth:`~.buffer_watch.WatchedToolRecorder.
    _link_late_before`) onto the view's record of the same stimulus: the wire alone, cut at
    the stimulus, has no command before it, nor after it (``next_sent``), nor a reply heard
    past the last try's window (``heard_late``, :meth:`~.buffer_watch.WatchedToolRecorder.
    _hear_late_reply`)."""
    if isinstance(made, Exchange) and isinstance(seen, Exchange):
        pairs = [(made, seen)]
    elif isinstance(made, Measurement) and isinstance(seen, Measurement):
        pairs = list(zip((made.start, *made.data), (seen.start, *seen.data), strict=True))
    else:
        return
    for a, b in pairs:
        b.late_before = a.late_before
        b.sent_before = a.sent_before  # the talk set aside before it (continued_talk)
        b.next_sent = a.next_sent  # shared: the engine fills it when it sends the next one
        b.heard_late = a.heard_late  # the late reply the engine heard past the last try


def _unanswered_break_end(events: list[Event], lookback: int = 4000) -> float | None:
    """The end of the tool's last break if no DUT character came after it (among the last
    ``lookback`` events), else None: a sensor that answered since is awake, whatever it
    needed to wake."""
    for e in reversed(events[-lookback:]):
        if e.kind is EventKind.BREAK and e.origin == TOOL:
            return e.end
        if e.kind is not EventKind.NOTE and e.origin != TOOL:  # a sensor's break is its own
            return None
    return None
