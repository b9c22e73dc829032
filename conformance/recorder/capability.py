"""What a data recorder declares it can do (``[recorder]`` of ``--declaration``), and what an
absent capability does to the run.

A logger that cannot send some command kinds (many real ones have no aV!, aC!, aR... or no
high-volume commands) is not excused by saying so where the standard makes the capability
mandatory for the version it claims: the verdicts must not certify more than the standard
allows. So the declaration is read by the level of the rule that asks for the capability:

- **optional** (a MAY rule, or a version the recorder does not claim): letter addresses
  (R-4.3-04, MAY) and, for a recorder claiming v1.3, the high-volume commands. A command
  that needs one is not asked (the job is trimmed; a job left empty is not run), and the
  rule is N/A citing the declaration.
- **mandatory** (a MUST rule for the claimed version: aC!-type commands, R-4.4.7-08; aMC!,
  aV!, aR..., the basic commands, R-4.4-02; addresses 0-9, R-4.3-03; aHA!/aHB! of a v1.4
  recorder, R-5.4-01; extended and metadata pass-through, R-4.4.14-02): the job is asked all
  the same and judged on what the recorder did, as without a declaration; a FAIL says the
  capability was declared absent and that the declaration does not excuse it.

Either way, the rules that judge *how* the recorder uses a capability it declared absent
(R-4.4.7-06/-07 for concurrent waits and storage, R-4.4.12-07 for the CRC of aMC!, R-5.1-04
and R-5.2-08 for high volume) are N/A citing the declaration when the recorder indeed sent
no such command in the run: there is nothing for them to judge. If it sent one after all,
they are judged as usual.

Without a declaration every job is asked and every capability assumed, as the report's
assumptions say.

The recorder may also say, job by job, that it cannot do one (a harness's ``cannot``, a
trigger's exit code 3, an in-process program's ``RecorderOutput.cannot``): the same levels
decide (:func:`cannot_finding`). N/A for a MAY rule or a job of optional commands only; a FAIL
resting on the recorder's words for the rule that requires the job's commands; any other rule
judged on what the wire shows.
"""

from __future__ import annotations

import contextlib
import re
from dataclasses import dataclass, replace

from ..catalog import requirement
from ..declaration import Declaration, RecorderDeclaration
from ..protocol.commands import Command, CommandError, Kind, parse_command
from ..protocol.version import format_version, is_v14
from ..recorder_jobs import Request
from ..transcript import Event, EventKind
from ..verdicts import Finding, Verdict

_TOKENS = {
    Kind.QUERY_ADDRESS: "?",
    Kind.ACKNOWLEDGE: "!",
    Kind.IDENTIFY: "I",
    Kind.CHANGE_ADDRESS: "A",
    Kind.VERIFY: "V",
    Kind.DATA: "D",
    Kind.BINARY_DATA: "DB",
    Kind.HIGH_VOLUME_ASCII: "HA",
    Kind.HIGH_VOLUME_BINARY: "HB",
    Kind.EXTENDED: "X",
    Kind.IDENTIFY_MEASUREMENT: "IM",
    Kind.METADATA: "IM",
}
_CRC_TOKENS = {
    Kind.MEASURE: ("M", "MC"),
    Kind.CONCURRENT: ("C", "CC"),
    Kind.CONTINUOUS: ("R", "RC"),
}
#: the ``[recorder]`` booleans and the command kinds each one switches off
FAMILIES = {
    "crc": ("MC", "CC", "RC"),
    "concurrent": ("C", "CC"),
    "high_volume": ("HA", "HB", "DB"),
}
#: rules that judge how a recorder uses a command kind (nothing to judge without it)
DEPENDENT_RULES = {
    "C": ("R-4.4.7-06", "R-4.4.7-07"),
    "CC": ("R-4.4.7-06", "R-4.4.7-07"),
    "MC": ("R-4.4.12-07",),
    "HA": ("R-5.1-04",),
    "HB": ("R-5.2-08",),
    "DB": ("R-5.2-08",),
}
WHAT = {
    "?": "?!",
    "!": "a!",
    "I": "aI!",
    "A": "aAb!",
    "M": "aM!",
    "D": "aDn!",
    "MC": "aMC!",
    "V": "aV!",
    "C": "aC!",
    "CC": "aCC!",
    "R": "aRn!",
    "RC": "aRCn!",
    "HA": "aHA!",
    "HB": "aHB!",
    "DB": "aDBn!",
    "X": "extended commands",
    "IM": "identify-measurement and metadata commands",
}
LETTER_RULE = "R-4.3-04"


def token_of(command: Command) -> str:
    """The ``[recorder] commands`` token a command needs (``0MC1!`` -> ``MC``)."""
    if command.kind in _CRC_TOKENS:
        plain, crc = _CRC_TOKENS[command.kind]
        return crc if command.crc else plain
    return _TOKENS[command.kind]


def mandatory_rule(token: str, v14: bool) -> str | None:
    """The MUST rule that requires a recorder of this version to send ``token`` (None: the
    capability is optional for it)."""
    if token in ("HA", "HB", "DB"):
        return "R-5.4-01" if v14 else None
    if token in ("C", "CC"):
        return "R-4.4.7-08"
    if token in ("X", "IM"):
        return "R-4.4.14-02"
    return "R-4.4-02"


@dataclass(frozen=True)
class Absence:
    """A command the declaration says the recorder cannot send, and why."""

    command: str
    what: str  # "aC!", "address A"
    cited: str  # "[recorder] concurrent = false (FILE:LINE)"
    mandatory: str | None  # the MUST rule that asks for it of this version; None: optional

    def text(self) -> str:
        return f"{self.command} needs {self.what}, declared absent: {self.cited}"


class Capabilities:
    """The recorder declaration read against the claimed version (``"13"``/``"14"``)."""

    def __init__(self, declaration: Declaration | None, version: str) -> None:
        self.source = declaration.source if declaration is not None else None
        self.declared: RecorderDeclaration | None = declaration.recorder if declaration else None
        self.v14 = is_v14(version)
        #: token -> where the declaration rules it out
        self.absent_tokens: dict[str, str] = {}
        rec = self.declared
        if rec is None:
            return
        for key, tokens in FAMILIES.items():
            if getattr(rec, key) is False:
                for token in tokens:
                    self.absent_tokens.setdefault(
                        token, f"[recorder] {key} = false ({rec.where[key]})"
                    )
        if rec.commands is not None:
            for token in WHAT:
                if token not in rec.commands:
                    self.absent_tokens.setdefault(
                        token, f"[recorder] commands lists no {token} ({rec.where['commands']})"
                    )

    def absence(self, text: str) -> Absence | None:
        """Why the declared recorder cannot send ``text`` (None: it can, or nothing said)."""
        rec = self.declared
        if rec is None:
            return None
        try:
            command = parse_command(text)
        except CommandError:
            return None
        if rec.addresses is not None:
            for target in (command.address, command.new_address):
                if target and target != "?" and target not in rec.addresses:
                    cited = (
                        f'[recorder] addresses = "{rec.addresses_text}" ({rec.where["addresses"]})'
                    )
                    rule = None if target.isalpha() else "R-4.3-03"
                    return Absence(text, f"address {target}", cited, rule)
        token = token_of(command)
        if token in self.absent_tokens:
            return Absence(
                text, WHAT[token], self.absent_tokens[token], mandatory_rule(token, self.v14)
            )
        return None

    def trim(self, request: Request) -> tuple[Request, list[Absence]]:
        """The request without the commands whose capability is declared absent and
        optional (never asked), and every absence found (mandatory ones stay asked)."""
        absences = [a for a in map(self.absence, request.commands) if a is not None]
        dropped = {a.command for a in absences if a.mandatory is None}
        kept = tuple(c for c in request.commands if c not in dropped)
        return replace(request, commands=kept), absences

    def assumptions(self) -> list[str]:
        """What the report says the tool assumed about the recorder's capabilities."""
        if self.declared is None:
            where = f"no [recorder] table in {self.source}" if self.source else "none given"
            return [
                f"no recorder declaration ({where}): every job asked, every command "
                "kind, CRC, concurrent and high-volume measurements and addresses 0-9, A-Z, "
                "a-z assumed supported"
            ]
        rec = self.declared
        said = []
        if self.absent_tokens:
            absent = ", ".join(WHAT[t] for t in self.absent_tokens)
            mandatory = sorted(
                {r for t in self.absent_tokens if (r := mandatory_rule(t, self.v14))}
            )
            said.append(
                f"recorder declared without {absent} ({self.source}); jobs needing a capability "
                "the claimed version makes optional are not asked (N/A); those the standard "
                f"requires ({', '.join(mandatory) or 'none'}) are asked and judged all the same"
            )
        if rec.addresses is not None:
            said.append(
                f'recorder declared to poll addresses "{rec.addresses_text}": letters outside '
                "it are not asked (R-4.3-04 is a MAY); digits outside it are asked all the same "
                "(R-4.3-03)"
            )
        return said or [f"recorder declaration {self.source}: every capability declared present"]

    def apply(self, findings: list[Finding], sent: set[str]) -> None:
        """Rewrite a case's findings for what the declaration says (see the module text);
        ``sent`` are the tokens of the commands the recorder sent in the run so far."""
        if self.declared is None:
            return
        dependent: dict[str, str] = {}
        for token, cited in self.absent_tokens.items():
            for rid in DEPENDENT_RULES.get(token, ()):
                group = [t for t, rules in DEPENDENT_RULES.items() if rid in rules]
                if all(t in self.absent_tokens for t in group) and not set(group) & sent:
                    dependent.setdefault(rid, cited)
        mandatory: dict[str, list[str]] = {}
        for token, cited in self.absent_tokens.items():
            rule = mandatory_rule(token, self.v14)
            if rule is not None:
                mandatory.setdefault(rule, []).append(f"{WHAT[token]} ({cited})")
        rec = self.declared
        if rec.addresses is not None and not set("0123456789") <= rec.addresses:
            said = f'[recorder] addresses = "{rec.addresses_text}" ({rec.where["addresses"]})'
            cited = f"addresses 0-9 ({said})"
            mandatory.setdefault("R-4.3-03", []).append(cited)
        version = "v1.4" if self.v14 else "v1.3"
        for f in findings:
            if f.requirement in dependent:
                was = f"{f.verdict}: {f.detail}"
                f.verdict = Verdict.NA
                f.detail = (
                    f"not applicable: the declaration says the recorder cannot send what this "
                    f"rule judges ({dependent[f.requirement]}), and it sent none in this run "
                    f"(otherwise: {was})"
                )
                f.consequence_of = None
            elif (
                f.requirement in mandatory
                and f.verdict is Verdict.FAIL
                and self._may_name_absent(f, mandatory[f.requirement])
            ):
                f.detail += (
                    f" — declared absent ({'; '.join(mandatory[f.requirement])}), but "
                    f"{f.requirement} requires it of a recorder claiming {version}: the "
                    "declaration does not excuse it"
                )
            elif (
                f.requirement == LETTER_RULE
                and f.verdict is Verdict.NA
                and self.declared.addresses is not None
                and not any(c.isalpha() for c in self.declared.addresses)
            ):
                f.detail = (
                    f"not applicable: letter addresses are optional (MAY) and the declaration "
                    f'says the recorder polls only "{self.declared.addresses_text}" '
                    f"({self.declared.where['addresses']}); none asked"
                )

    def _may_name_absent(self, finding: Finding, cited: list[str]) -> bool:
        """Whether a FAIL of a rule that asks for a declared-absent capability may be about
        that absence, so that the "declared absent ... does not excuse it" note belongs on
        it. A FAIL naming only commands the declaration allows (values logged wrong from
        ``0M2!``) is about something else: the note would blame the absence for it. A finding
        that names no command, or cuts its list short, keeps the note; a list cut short in
        the detail whose rest the evidence keeps (a tally's ``also:`` lines) is read whole."""
        text = " ".join([finding.detail, *finding.evidence])
        named = _COMMAND_TEXT.findall(text)
        if not named or _cut_short(finding) or any(c.startswith("addresses") for c in cited):
            return True
        for word in named:
            try:
                command = parse_command(word)
            except CommandError:
                return True  # not a command after all: keep the note, as before
            token = token_of(command)
            if token in self.absent_tokens and mandatory_rule(token, self.v14) == (
                finding.requirement
            ):
                return True
        return False


def _cut_short(finding: Finding) -> bool:
    """Whether the detail's list ends ``(+N more)`` with fewer than N of the rest kept as
    ``also:`` evidence lines (``judges.tally``): what it leaves out may name any command."""
    hidden = sum(int(n) for n in _MORE.findall(finding.detail))
    kept = sum(1 for line in finding.evidence if line.startswith("also: "))
    return kept < hidden


#: a list cut short in a detail (``judges.cite.listed``, ``exchanges``)
_MORE = re.compile(r"\(\+(\d+) more\)")
#: command text as findings quote it (``0M2!``, ``0XHELP!``, ``aHA!``)
_COMMAND_TEXT = re.compile(r"(?<![\w!])[0-9A-Za-z?][0-9A-Za-z_?]*!")


def job_rules(commands: tuple[str, ...], v14: bool) -> tuple[dict[str, list[str]], set[str]]:
    """The rules that require a recorder of this version to send ``commands`` (rule -> the
    commands), and the optional rules that let it lack some of them (R-4.3-04 for letter
    addresses). A command needing only an optional capability adds no mandatory rule."""
    mandatory: dict[str, list[str]] = {}
    optional: set[str] = set()
    for text in commands:
        try:
            command = parse_command(text)
        except CommandError:
            continue
        targets = [t for t in (command.address, command.new_address) if t and t != "?"]
        if any(t.isalpha() for t in targets):
            optional.add(LETTER_RULE)
            continue
        if targets:
            mandatory.setdefault("R-4.3-03", []).append(text)
        rule = mandatory_rule(token_of(command), v14)
        if rule is None:
            optional.add(DEPENDENT_RULES.get(token_of(command), ("",))[0])
        else:
            mandatory.setdefault(rule, []).append(text)
    return mandatory, optional - {""}


def cannot_finding(
    rid: str, job: str, words: str, commands: tuple[str, ...], findings: list[Finding], version: str
) -> Finding | None:
    """The verdict on ``rid`` of a case judged on ``job``, which the recorder said it cannot
    do. N/A when the job needs only what the standard lets a recorder lack, or ``rid`` is a
    MAY (what only the missing job left undecided, or a MAY's FAIL, is dropped from
    ``findings``). A FAIL, resting on the recorder's own words, when ``rid`` is a rule that
    requires the job's commands of a recorder of this version (R-4.4-02 for aM!, R-4.3-03
    for the addresses 0-9...). Any other rule: None, judged on what the case saw."""
    v14 = is_v14(version)
    mandatory, optional_rules = job_rules(commands, v14)
    level = requirement(rid).level
    said = f"the recorder said it cannot do {job}" + (f" ({words})" if words else "")
    if not mandatory or level == "MAY" or (rid in optional_rules and rid not in mandatory):
        dropped = {Verdict.INCONCLUSIVE} | (
            {Verdict.FAIL, Verdict.WARN} if level == "MAY" else set()
        )
        findings[:] = [f for f in findings if not (f.requirement == rid and f.verdict in dropped)]
        why = f"{rid} is a MAY" if level == "MAY" else "the job needs only optional capabilities"
        return Finding(rid, Verdict.NA, f"not applicable: {said}; {why}")
    if rid not in mandatory:
        return None
    verdict = Verdict.WARN if level == "SHOULD" else Verdict.FAIL
    needed = " ".join(mandatory[rid])
    return Finding(
        rid,
        verdict,
        f"{said}, but {rid} ({level}) requires a v{format_version(version)} recorder to send "
        f"{needed}",
        evidence=[said],
        observed=1,
    )


def sent_tokens(events: list[Event], is_recorder) -> set[str]:  # noqa: ANN001
    """The command tokens of what the recorder transmitted in ``events``."""
    tokens: set[str] = set()
    text = ""
    for e in events:
        if e.kind is EventKind.BREAK:
            text = ""
        if e.kind is not EventKind.CHAR or not is_recorder(e):
            continue
        text += chr(e.wire & 0x7F)  # 7E1 on the wire: the parity bit off
        if text.endswith("!"):
            with contextlib.suppress(CommandError, KeyError):
                tokens.add(token_of(parse_command(text)))
            text = ""
        text = text[-40:]
    return tokens
