"""Declared interactions between emulator faults, as data (issue 18, part 7).

A combination of faults is expected to be caught by the union of its members' ``violates``;
an :class:`Interaction` records where the combination genuinely changes what a correct tool
must say (one member hides another's deviation, or the two together break a further rule).
Each entry names its members, what it adds or removes, and why in one sentence. An entry is
never added to make a combination row pass: only where a correct tool's verdicts differ.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Interaction:
    """What a set of faults does together that the members alone do not explain."""

    #: the faults that must all be in a combination; one alone means "beside any other":
    #: a deviation of that fault that shows only where the schedule falls a certain way,
    #: which any partner that moves the schedule may make it fall (it may only add)
    members: frozenset[str]
    reason: str
    #: requirements the combination may FAIL/WARN beyond the members' ``violates``
    adds: tuple[str, ...] = ()
    #: members' requirements a correct tool may PASS or leave undecided in the combination
    #: (the deviation is masked; a PASS there is no missed FAIL)
    removes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.members:
            raise ValueError("an interaction needs a member fault")
        if len(self.members) == 1 and self.removes:
            # a mask is a partner's doing: with any partner it would excuse every missed FAIL
            raise ValueError(f"interaction {sorted(self.members)}: one fault alone only adds")
        if not self.reason.strip():
            raise ValueError(f"interaction {sorted(self.members)} gives no reason")
        if not (self.adds or self.removes):
            raise ValueError(f"interaction {sorted(self.members)} changes nothing")

    def applies(self, combination: tuple[str, ...]) -> bool:
        return self.members <= set(combination)


#: Only combinations whose truth differs from the union; every other unexplained row of the
#: measurement (notes/combos-result.md) is a tool defect, listed there, not declared here.
INTERACTIONS: tuple[Interaction, ...] = (
    Interaction(
        frozenset({"no-service-request", "verify-no-service-request"}),
        "no-service-request already silences aM!'s service request too, so aV! behaves like"
        " aM! and R-4.4.11-01 holds; the missing request is one deviation, R-4.4.6-02's.",
        removes=("R-4.4.11-01",),
    ),
    Interaction(
        frozenset({"undefined-group-keeps-data", "undefined-measure-silent"}),
        "an undefined aMn! gets no answer at all, so no a0000 is ever followed by the stale D0"
        " values, and the defined groups' counts rightly hold R-4.4.8-03.",
        removes=("R-4.4.8-03",),
    ),
    Interaction(
        frozenset({"abort-sends-zero-reply", "break-does-not-abort-measure"}),
        "a break never aborts the measurement, so no abort is ever followed by the unasked"
        " a0000: the service request and data come as usual and R-4.4.5-08 holds on the wire"
        " (seed 4064: 'nothing arrived unasked after the break').",
        removes=("R-4.4.5-08",),
    ),
    Interaction(
        frozenset({"unknown-command-text", "unsupported-rc-without-crc"}),
        "every unsupported aRCn! is answered 'aUNKN', so the CRC-less empty reply never"
        " reaches the wire; the text is R-4.4.8.1-03's deviation, and no CRC format is judged"
        " on text (seed 4066).",
        removes=("R-4.4.12-02",),
    ),
    Interaction(
        frozenset({"split-value", "values-not-packed"}),
        "split-value fills every D reply after M/V to exactly 35 characters, so no reply is"
        " left one value short: the replies are full on the wire and R-4.4.8.3-03 holds"
        " (the cut is R-4.4.8.3-01's; seed 4068).",
        removes=("R-4.4.8.3-03",),
    ),
    Interaction(
        frozenset({"more-values-than-announced", "values-not-packed"}),
        "aM!'s D0 holds one value fewer than would fit, so it returns the 3 announced"
        " ('0+22.15+1013.2+45.7') and the fourth, the one too many, is left for aD1!, which"
        " a recorder (and this tool, decision A12) never sends once the count is read: no"
        " reply on the wire holds more values than announced, and R-4.4.8-03 holds there"
        " (seed 4187 with verify-no-service-request: aM! read 9 times, never a D1 after it).",
        removes=("R-4.4.8-03",),
    ),
    Interaction(
        frozenset({"values-not-packed", "values-over-35"}),
        "each D reply after M/V holds one value fewer than its 40-character limit would take;"
        " with the reference sensor's 9- and 10-character values the one left out is the one"
        " that crossed 35: aM2!'s replies carry 27, 27, 18 and 9 value characters, none over"
        " 35, so R-4.4-05 holds on the wire (seed 4149).",
        removes=("R-4.4-05",),
    ),
    Interaction(
        frozenset({"address-change-not-applied", "answers-old-address"}),
        "the address change never takes effect, so the address the sensor keeps answering is"
        " its own, not an old one beside the new: nothing answers a foreign address and"
        " R-4.0-01 holds (seed 4068).",
        removes=("R-4.0-01",),
    ),
    Interaction(
        frozenset({"undefined-concurrent-silent", "unknown-command-text"}),
        "an undefined aCn! gets no answer at all, so no 'aUNKN' is ever sent to one, and the"
        " defined concurrent replies rightly hold R-4.4.7-01 (seed 4069).",
        removes=("R-4.4.7-01",),
    ),
    Interaction(
        frozenset({"undefined-measure-silent", "unknown-command-text"}),
        "an undefined aMn!/aMCn! gets no answer at all, so no 'aUNKN' is ever sent to one, and"
        " the defined groups' replies rightly hold R-4.4.5-01 (seed 4105: aM3!..aM9! and"
        " aMC3!..aMC9! unanswered through nine tries each, no 'aUNKN' to any M command).",
        removes=("R-4.4.5-01",),
    ),
    Interaction(
        frozenset({"undefined-group-keeps-data", "unknown-command-text"}),
        "an undefined aMn! is answered 'aUNKN', not a0000, so no a0000 is ever followed by the"
        " stale D0 values, and the defined groups' counts rightly hold R-4.4.8-03 (seed 4115:"
        " 0M3! -> '0UNKN' nine times; the stale-data case found no a0000 group: N/A).",
        removes=("R-4.4.8-03",),
    ),
    Interaction(
        frozenset({"measure-count-zero", "metadata-missing-record"}),
        "aM! and aMC! announce no values, so their aIM_002!/aIMC_002! name an index past the"
        " count and the bare 'a<CR><LF>' is the right answer: the record metadata-missing-"
        "record drops is never owed, and R-6.2-07 holds on the wire (seed 4075).",
        removes=("R-6.2-07",),
    ),
    Interaction(
        frozenset({"chatter-before-service-request", "no-service-request"}),
        "the chatter is timed halfway to the service request, and with none sent the sensor"
        " sends nothing between atttn and the data: R-4.4.5-08 holds on the wire (seed 4081;"
        " sending the chatter anyway leaves one 'aBUSY' line that reads as a malformed"
        " request, R-4.4.6-01's, not as chatter before a request that never comes).",
        removes=("R-4.4.5-08",),
    ),
    Interaction(
        frozenset({"early-address", "slow-wake"}),
        "a sensor that wakes 110 ms after the break while a retry is on the line needs marking"
        " before it takes an address, and early-address removes that marking: it takes the"
        " tail of a command for one ('0!' inside '0D0!') and answers it, so the wire holds"
        " empty D replies and unanswered changes that the rules on them rightly FAIL (seed"
        " 4082: 0D0! -> '0<CR><LF>' 9 ms after the retry that it woke inside).",
        adds=(
            "R-4.4.4-01",
            "R-4.4.5-03",
            "R-4.4.5-10",
            "R-4.4.8-03",
            "R-4.4.8-04",
            "R-4.4.8.3-02",
            "R-5.2-02",
        ),
    ),
    Interaction(
        frozenset({"crc-on-continuous", "early-address", "slow-wake"}),
        "aR1!'s reply carries a CRC nobody asked for, so the tool retries it after a break;"
        " the sensor wakes 110 ms after each break inside the next try and early-address"
        " lets it take that try's tail ('1!') for a command to another sensor, after which it"
        " sleeps: 0R2!..0R6! go unanswered through nine tries each (28.44-30.97 s), so the"
        " rules that they be answered rightly FAIL (seed 4152).",
        adds=("R-4.4-01", "R-4.4.8.1-01"),
    ),
    Interaction(
        frozenset({"abort-keeps-old-data", "buffer-cleared-after-read"}),
        "the measurement before the aborted one was read to its end, which emptied the buffer,"
        " so the old data the abort brings back are none: D0 after the abort is empty on the"
        " wire, and aI! was shown to abort aC! (R-4.4.7.1-01: an aC! not aborted fills D0 with"
        " new values; seed 4094). R-4.4.5.1-02 and R-4.4.7.1-02 are INCONCLUSIVE: the same"
        " steps without an abort leave D0 empty too.",
        removes=("R-4.4.7.1-01",),
    ),
    Interaction(
        frozenset({"abort-keeps-old-data", "buffer-cleared-by-break"}),
        "the measurement before the aborted one was read to its end, and the break before the"
        " D0 that follows the abort empties such a buffer, so the old data the abort brings"
        " back are none: D0 after each abort is empty on the wire ('0', '0AP@'), and aI! was"
        " shown to abort aC! (R-4.4.7.1-01; seed 4118 with missing-crlf). R-4.4.5.1-02,"
        " R-4.4.7.1-02 and R-5.3-01 are INCONCLUSIVE: the same steps without an abort leave"
        " D0 (DB0 after aHB!) empty too.",
        removes=("R-4.4.7.1-01",),
    ),
    Interaction(
        frozenset({"abort-keeps-old-data", "data-lost-after-standby"}),
        "the measurement before the aborted one was read to its end and the sensor then went"
        " to standby, which emptied the buffer, so the old data the abort brings back are"
        " none: D0 after each abort is empty on the wire (seed 4148 with abort-sends-zero-"
        "reply: 0D0! at 81.55 s read all 3 values, the abort's 0D0! -> '0<CR><LF>'), and aI!"
        " was shown to abort aC! (R-4.4.7.1-01). R-4.4.5.1-02, R-4.4.7.1-02 and R-5.3-01 are"
        " INCONCLUSIVE: the same steps without an abort leave D0 (DB0 after aHB!) empty too.",
        removes=("R-4.4.7.1-01",),
    ),
    Interaction(
        frozenset({"buffer-cleared-after-read", "undefined-group-keeps-data"}),
        "the data an undefined aMn! leaves readable were read to their end before it, which"
        " emptied them, so its a0000 is followed by an empty D0 and R-4.4.8-03 holds on the"
        " wire (seed 4094).",
        removes=("R-4.4.8-03",),
    ),
    Interaction(
        frozenset({"late-service-request", "ttt-overstated"}),
        "every service request is held until 0.25 s past the announced ttt, so the 1.5 s"
        " readiness ttt-overstated gives is never on the wire: aM!'s request comes after its"
        " 10 s, which shows a ttt too short (R-4.4.6-04), not one overstated (seed 4125).",
        removes=("R-4.4.5-09",),
    ),
    Interaction(
        frozenset({"binary-fewer-values", "binary-no-empty-packet"}),
        "the packets end one value short of aHB!'s count and the index after them gets no"
        " empty packet, so aDB10!, inside the announced count, returns no packet at all:"
        " R-5.2-02 (every aDBn! returns a packet) is broken on the wire, and R-5.2-07 is left"
        " undecided, since a withheld packet and data that end early look alike (seed 4129).",
        adds=("R-5.2-02",),
    ),
    Interaction(
        frozenset({"binary-size-big-endian", "d0-empty"}),
        "the measurement holds no values, so aDB0! returns the empty packet, whose size"
        " 0x0000 reads the same in either byte order: every packet on the wire is"
        " '0<00 00><00><0F 00>', well formed, and R-5.2-02 holds there (seed 4143).",
        removes=("R-5.2-02",),
    ),
    Interaction(
        frozenset({"binary-invalid-type", "d0-empty"}),
        "the measurement holds no values, so aDB0! returns the empty packet, and the type"
        " code 11 binary-invalid-type puts on DB0's values has no values to go on: the one"
        " packet on the wire is '0<00 00><00><0F 00>', type 0, a valid code, and R-5.2.1-01"
        " holds there (seed 4186 with extended-not-x: 0DB0! and 0DB999! alike).",
        removes=("R-5.2.1-01",),
    ),
    Interaction(
        frozenset({"binary-no-empty-packet", "d0-empty"}),
        "aHB! announces 33 values but the measurement holds none, so aDB0! is already past"
        " the data, and binary-no-empty-packet answers that with nothing: an aDBn! inside the"
        " announced count returns no packet at all, R-5.2-02 broken on the wire as with"
        " binary-fewer-values (seed 4155 with metadata-missing-units).",
        adds=("R-5.2-02",),
    ),
    Interaction(
        frozenset({"high-volume-stops-at-d9", "high-volume-unsupported-silent"}),
        "the sensor has no aHA! (silent to it), so no D10 after one is ever owed: the values"
        " high-volume-stops-at-d9 withholds do not exist, and every measurement that did"
        " start delivered its count, R-4.4.8-03 holding on the wire over 11 of them (seed"
        " 4156 with extended-no-crlf).",
        removes=("R-4.4.8-03", "R-5.1-02"),
    ),
    Interaction(
        frozenset({"buffer-cleared-after-read", "high-volume-two-digit-count"}),
        "aHA!'s count is unreadable, so its data are never read and R-5.3-01 is judged on"
        " aHB! alone, whose packets read up to the count (never past it to the empty one) are"
        " not 'all read': the control DB0 after standby and a break still holds values, so the"
        " empty DB0 after aI! shows the abort emptied the buffer, and R-5.3-01 holds on the"
        " wire (seed 4248 with value-eight-digits: 'aHB! ... 0I! aborted it').",
        removes=("R-5.3-01",),
    ),
    Interaction(
        frozenset({"buffer-cleared-after-read", "high-volume-stops-at-d9"}),
        "aD10! and on after aHA! get no answer, so aHA!'s pages past D9 are never read and"
        " its buffer is never 'all read': the control D0 after standby and a break still"
        " holds values (0D0! -> '0+1000.000...'), so the empty D0 after aI! shows the abort"
        " emptied it; aHB!'s packets, read up to the count, are kept the same way, and"
        " R-5.3-01 holds on the wire for both (seed 6200, truth22, with metadata-semicolon-"
        "in-field: 'aHA! survived a break and zI!, and 0I! aborted it').",
        removes=("R-5.3-01",),
    ),
    Interaction(
        frozenset({"data-lost-after-standby", "standby-ignored"}),
        "the sensor never drops to standby by itself, so the standby that would empty its"
        " buffer never comes: the control reads after standby and a break hold values, and the"
        " empty D0 after each abort, and the data unchanged by identify commands, are shown on"
        " the wire (seed 4248 with partial-command-accepted).",
        removes=("R-4.4.5.1-02", "R-4.4.7.1-02", "R-5.3-01", "R-6.1-03"),
    ),
    Interaction(
        frozenset({"data-lost-after-standby", "never-standby"}),
        "never-standby is standby-ignored and stays-awake-after-foreign at once: the sensor"
        " never sleeps, neither after 100 ms of marking nor after another address's command,"
        " so the standby that would empty its buffer never comes and the data read back after"
        " a break, the standby attempt and aI!/a!/aR0!/aRC0! are the same on the wire; the"
        " control reads hold values, the empty D0 after each abort and the identify commands'"
        " unchanged data are shown (seed 4258 with factory-address-not-zero).",
        removes=("R-4.4.5-10", "R-4.4.5.1-02", "R-4.4.7.1-02", "R-5.3-01", "R-6.1-03"),
    ),
    Interaction(
        frozenset({"answers-foreign-address", "never-standby", "standby-after-60ms"}),
        "answers-foreign-address's standby after it answers another address and standby-after-"
        "60ms's 60 ms after a reply together leave the sensor shown in standby, where never-"
        "standby beside either alone is not ('the sensor was not shown in standby'): the"
        " spacing probes find it asleep, silent after a 5.00 ms spacing and woken by a 12.60 ms"
        " break, so R-7.0-03 and R-7.0-04 hold on the wire (seed 4251).",
        removes=("R-7.0-03", "R-7.0-04"),
    ),
    Interaction(
        frozenset({"concurrent-service-request", "no-service-request"}),
        "the sensor sends no service request at all (the emulator's switch silences the"
        " concurrent ones too), so none follows aC!, aCC!, aHA! or aHB! and the rules that"
        " forbid one there hold on the wire (seed 4137).",
        removes=("R-4.4.6-05", "R-4.4.7-04", "R-5.3-01"),
    ),
)
