"""Section 4.4.12: the CRC variants (aMC!, aCC!, aRC!) and the CRC itself."""

from __future__ import annotations

import pytest

from conformance import preconditions as precondition
from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as judge
from conformance.judges.crc_sticks import after_late_request
from conformance.judges.late_before import answered_late
from conformance.judges.support import (
    serves_continuous,
    text_instead_of_start,
    unreadable_count,
)
from conformance.protocol.commands import C_FAMILY, M_FAMILY
from conformance.results import counted
from conformance.verdicts import Finding, Verdict, failed, inconclusive, passed, warned

requirements = pytest.mark.requirements
CRC_CODES = tuple(c for c in M_FAMILY + C_FAMILY if c[:2] in ("MC", "CC"))
PLAIN_CODES = tuple(c for c in M_FAMILY + C_FAMILY if c not in CRC_CODES)


def _with_continuous(sensor, ids) -> list[Finding]:
    """Findings over the D replies of every measurement plus the R/RC replies, the worse
    of the two per rule as a run combines them (:func:`~conformance.results.counted`): a
    side that observed nothing does not outvote one that judged the rule (crc-missing: the
    D replies after aMC!/aCC! hold no CRC to check, the aRCn! replies do)."""
    ms = sensor.defined(M_FAMILY + C_FAMILY)
    found = judge.judge(ms, ids, sensor.version)
    pairs = {i: (sensor.exchange(f"R{i}"), sensor.exchange(f"RC{i}")) for i in range(10)}
    more = {f.requirement: f for f in xjudge.continuous(pairs, ids)}
    merged = []
    for f in found:
        other = more.get(f.requirement)
        both = counted([f] if other is None else [f, other])
        # of two undecided, the one over observations (an aRCn! CRC not compared) says more
        # than the one that saw nothing (seed 4198, + measure-ttt-two-digits: the unreached
        # one was kept, and the exploration's PASS outvoted it)
        merged.append(max(both, key=_weight))
    return merged


def _weight(finding: Finding) -> tuple[int, int]:
    """Worse first; between two INCONCLUSIVEs, the one over more observations (ties keep
    the D replies' finding, as before)."""
    undecided = finding.verdict is Verdict.INCONCLUSIVE
    return finding.verdict.rank, (finding.observed or 0) if undecided else 0


def _crc_served(sensor, case) -> None:
    """A CRC is judged where one was asked for and served: a CRC-variant measurement that
    announced values, or an aRCn! with values (CRC variants are mandatory from v1.3, so
    their absence is R-4.4.12-01's FAIL and leaves these rules undecided, not N/A)."""
    rc = [sensor.exchange(f"RC{i}") for i in range(10)]
    case.requires(
        "supported",
        precondition.shown_supported(
            bool(sensor.defined(CRC_CODES)) or any(serves_continuous(ex) for ex in rc),
            "no CRC-variant measurement announced values and no aRCn! returned any",
        ),
    )


@requirements("R-4.4.12-01")
@pytest.mark.preconditions("none")
def test_crc_commands_supported(sensor, case):
    """A sensor claiming v1.3 or later answers aMC!, aMC1..9!, aCC!, aCC1..9! and aRC0..9!."""
    case.expect("a reply to each CRC-variant command")
    ms = [sensor.measurement(c) for c in CRC_CODES]
    exchanges = [m.start for m in ms] + [sensor.exchange(f"RC{i}") for i in range(10)]
    case.evidence("CRC-variant commands", exchanges)
    case.add(
        xjudge.answered(
            "R-4.4.12-01", exchanges, "CRC variants are mandatory from v1.3", late_is_reply=True
        )
    )
    # plain aMC!/aCC! are always defined: 'aUNKN' to one is the sensor saying it does not
    # know it (joembedded's sketch, docs/kit.md). An undefined aMCn!/aCCn! group's text is
    # R-4.4.9-02's, an aRCn!'s R-4.4.8.1-03's.
    text = [m.start for m in ms if m.command.group == 0 and text_instead_of_start(m)]
    if text:
        case.add(
            failed(
                "R-4.4.12-01",
                "not supported: " + "; ".join(xjudge.shown(ex) for ex in text),
                evidence=xjudge.cite(text),
                observed=len(text),
            )
        )


@requirements("R-4.4.12-02", "R-4.4.12-03")
@pytest.mark.preconditions(supported=("R-4.4.12-02",), none=("R-4.4.12-03",))
def test_crc_presence(sensor, case):
    """D replies after a CRC variant, and RC replies, end with 3 CRC characters; replies to
    the plain commands carry none."""
    case.expect("3 CRC characters before CR LF exactly where a CRC was asked for")
    case.evidence("D replies and R/RC replies", sensor.defined(M_FAMILY + C_FAMILY))
    case.extend(_with_continuous(sensor, case.requirements))
    _crc_served(sensor, case)


@requirements("R-4.4.12-03")
@pytest.mark.preconditions("supported")
def test_crc_request_ends_with_its_command(sensor, case):
    """A CRC asked for on a metadata command (aIMC_001!) is for that reply only: the D
    replies of a plain aM! after it carry no CRC."""
    # aM! stands for the first plain measurement that announced values, and aIMC_001! for
    # its CRC twin's metadata command (aMC!'s for aV!): see _plain_with_values
    case.expect("aIMC_001!, then aM! and its D replies without a CRC")
    if not sensor.is_v14:
        case.not_applicable("metadata commands exist from SDI-12 v1.4 on")
        return
    plain = _plain_with_values(sensor)
    if not case.requires(
        "supported",
        precondition.shown_supported(
            plain is not None,
            "no plain measurement (aM!, aMn!, aV!, aC!, aCn!) announced values, so no D "
            "reply could show a CRC that outlived its command",
        ),
    ):
        return
    code = plain.command.text()[1:-1]
    meta = sensor.fresh_exchange(f"I{_crc_twin(code)}_001")
    m = sensor.fresh_measurement(code)
    case.evidence(
        f"{_bare(meta.text)}, then {_bare(m.command.text())} and its D replies", [meta, m]
    )
    findings = judge.judge([m], case.requirements, sensor.version)
    if not meta.answered and any(f.verdict is Verdict.FAIL for f in findings):
        # a CRC on a plain D reply breaks the rule whether or not the metadata command that
        # asked for it was answered (metadata-crc-sticks + metadata-silent, seed 4091)
        case.extend(findings)
        return
    if not meta.answered and answered_late(meta):
        # heard all the same: its reply came after the window (R-7.0-10's)
        case.extend(after_late_request(meta, findings))
        return
    if not case.requires(
        "supported",
        precondition.shown_supported(
            meta.answered, f"{_bare(meta.text)} got no reply to follow", [xjudge.cited(meta)]
        ),
    ):
        return
    case.extend(findings)


def _plain_with_values(sensor):
    """The first plain measurement (aM! first) that announced values, so D replies follow
    it (empty ones too show a CRC that outlived its command): a fixed aM! left this case
    nothing to judge when aM! announced none, and the PASS of the D replies read before any
    CRC metadata command then stood alone (issue 22, after-landing check:
    measure-count-zero + metadata-crc-sticks)."""
    return next((m for m in sensor.family(PLAIN_CODES) if m.count), None)


def _bare(text: str) -> str:
    """``0IMC_001!`` as ``aIMC_001!``: the evidence label names the command, not the address."""
    return "a" + text[1:]


def _crc_twin(code: str) -> str:
    """The CRC variant of a plain measurement code (aV! has none: aMC!'s stands in)."""
    return "MC" if code == "V" else code[0] + "C" + code[1:]


@requirements("R-4.4.12-05", "R-4.4.12-06")
@pytest.mark.preconditions("supported")
def test_crc_value_and_encoding(sensor, case):
    """The CRC is CRC-16/ARC over the reply from the address up to the CRC, sent as three
    characters 0x40 | 6-bit groups."""
    case.expect("recomputed CRC equals the 3 characters sent")
    case.evidence("D replies and R/RC replies", sensor.defined(CRC_CODES))
    case.extend(_with_continuous(sensor, case.requirements))
    _crc_served(sensor, case)


@requirements("R-4.4.12-04")
@pytest.mark.preconditions("supported")
def test_crc_variant_same_measurement(sensor, case):
    """A CRC variant takes the same measurement as its plain twin (same count)."""
    case.expect("aMC! announces the same n as aM!, aCC! the same nn as aC!, and so on")
    pairs = []
    for plain in PLAIN_CODES:
        if plain == "V":
            continue
        twin = plain[0] + "C" + plain[1:]
        pairs.append((sensor.measurement(plain), sensor.measurement(twin)))
    case.evidence("plain and CRC measurement replies", [x.start for p in pairs for x in p])
    # a reply in digits that gives no count (a two-digit ttt) hides the n it was to compare
    unread = [(a, b) for a, b in pairs if unreadable_count(a) or unreadable_count(b)]
    pairs = [(a, b) for a, b in pairs if a.count is not None and b.count is not None]
    # a start reply that may be the command before's, late, is no count of its own to
    # compare (answers-foreign-address + replies-after-retry WARNed "0M2! announced 9 but
    # 0MC2! 2", truth15)
    late = [
        text
        for pair in pairs
        if (text := xjudge.answered_late(pair[0].start) or xjudge.answered_late(pair[1].start))
    ]
    pairs = [
        (a, b)
        for a, b in pairs
        if not (xjudge.answered_late(a.start) or xjudge.answered_late(b.start))
    ]
    if not case.requires(
        "supported",
        precondition.shown_supported(bool(pairs), "no plain/CRC pair announced its counts"),
    ):
        return
    differ = [(a, b) for a, b in pairs if a.count != b.count]
    if differ:
        case.add(
            warned(
                "R-4.4.12-04",
                "; ".join(
                    f"{a.command} announced {a.count} but {b.command} {b.count}"
                    for a, b in differ[:3]
                ),
                evidence=xjudge.cite(x.start for pair in differ for x in pair),
                observed=len(pairs),
            )
        )
    elif unread:
        # (seed 4088) crc-variant-different-count's aMC! went unread beside aM!'s: 'the
        # same counts' over the other pairs would PASS the one pair that differs
        case.add(
            inconclusive(
                "R-4.4.12-04",
                f"{len(pairs)} plain/CRC pairs announce the same counts, but no count could be"
                " read in "
                + ", ".join(f"{a.command}/{b.command}" for a, b in unread)
                + ": not compared",
                evidence=xjudge.cite(x.start for pair in unread for x in pair),
                observed=len(pairs),
            )
        )
    elif late:
        case.add(
            inconclusive(
                "R-4.4.12-04",
                f"{len(pairs)} plain/CRC pairs announce the same counts, but "
                + "; ".join(late[:3])
                + " (R-7.0-10 judges its timing): not compared",
                observed=len(pairs),
            )
        )
    else:
        case.add(
            passed(
                "R-4.4.12-04",
                f"{len(pairs)} plain/CRC pairs announce the same counts",
                observed=len(pairs),
            )
        )
