"""The SDI-12 value grammar (``pd.d``): split, check, format and pack measurement values.

Values travel as text with a mandatory sign that doubles as the only delimiter, so a reply's
``<values>`` part can be split without knowing how many values it holds. The grammar is small
but has edge cases the standard leaves open (``+.5``, ``+5.``, ``-0``, leading zeros);
requirements.md decision A13 accepts them with a warning, and this module is the one place
that decision is implemented.

:class:`Violation` lives here, in the lowest protocol layer, so that both this module and
:mod:`conformance.protocol.responses` (which re-exports it) can produce findings without a
circular import.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from conformance.transcript import escape

VALUE_REQ = "R-4.4.8-02"  # sign, 1-7 digits, at most one '.', at most 9 characters
MAX_DIGITS = 7
MAX_CHARS = 9
#: ``<values>`` characters in one D reply after M/MC/Mn/V (R-4.4-05: room for pre-1.2
#: recorders) ...
VALUES_MAX_MEASURE = 35
#: ... and after the C family and HA, and in an R reply (R-4.4-05, R-5.1-03, R-4.4.8.1-01).
VALUES_MAX = 75


@dataclass(frozen=True)
class Violation:
    """One broken rule found in a reply, tied to a requirement ID of requirements.md.

    ``warning`` marks SHOULD rules and the lenient decisions of requirements.md section 5, so a
    judge can turn it into WARN instead of FAIL without knowing the rule itself.
    """

    requirement: str
    message: str
    warning: bool = False


class Checked:
    """Mixin of every parse result: ``ok`` when none of its ``violations`` is an error, so
    a caller (the tool's recorder deciding whether to retry) need not know the rules."""

    violations: list[Violation]

    @property
    def ok(self) -> bool:
        return not errors(self.violations)


def errors(violations: list[Violation]) -> list[Violation]:
    """The violations that are not warnings (the ones that make a reply non-conforming)."""
    return [v for v in violations if not v.warning]


_SIGN_SPLIT = re.compile(r"[+-][^+-]*|[^+-]+")


def split_values(text: str) -> list[str]:
    """Cut a ``<values>`` string at every sign: ``"+1.23-4.5+6"`` -> ``["+1.23", "-4.5", "+6"]``.

    Text before the first sign becomes a token of its own (it then fails :func:`check_value`
    for its missing sign) so that nothing the sensor sent is silently dropped.
    """
    return _SIGN_SPLIT.findall(text)


def continues_split_value(values: list[str]) -> bool:
    """A reply's :func:`split_values` begin with the rest of a value the reply before cut in
    two: its first token has no sign (R-4.4.8.3-01's deviation; counted once with its first
    half, R-4.4.8-03)."""
    return bool(values) and values[0][0] not in "+-"


def check_value(value: str) -> list[Violation]:
    """Violations of the value grammar for one token of :func:`split_values`.

    Hard failures (missing sign, a character other than digits and one '.', no digit, more than
    seven digits, more than nine characters) follow R-4.4.8-02; the odd-but-legal spellings of
    decision A13 come back as warnings.
    """
    shown = escape(value)
    if not value or value[0] not in "+-":
        return [Violation(VALUE_REQ, f"value '{shown}' has no leading '+' or '-' sign")]
    body = value[1:]
    found: list[Violation] = []
    stray = sorted({c for c in body if c not in "0123456789."})
    if stray:
        chars = escape("".join(stray))
        found.append(Violation(VALUE_REQ, f"value '{shown}' contains non-numeric '{chars}'"))
    if body.count(".") > 1:
        found.append(Violation(VALUE_REQ, f"value '{shown}' has more than one decimal point"))
    digits = sum(c.isdigit() for c in body)
    if digits == 0:
        found.append(Violation(VALUE_REQ, f"value '{shown}' has no digit"))
    if digits > MAX_DIGITS:
        found.append(Violation(VALUE_REQ, f"value '{shown}' has {digits} digits (at most 7)"))
    if len(value) > MAX_CHARS:
        found.append(
            Violation(VALUE_REQ, f"value '{shown}' is {len(value)} characters long (at most 9)")
        )
    if found:
        return found
    return _odd_spellings(value)


def _odd_spellings(value: str) -> list[Violation]:
    """Decision A13 warnings for a value that is otherwise well formed."""
    body = value[1:]
    whole, dot, fraction = body.partition(".")
    shown = escape(value)
    found = []
    if dot and not whole:
        found.append(Violation(VALUE_REQ, f"value '{shown}' has no digit before '.'", True))
    if dot and not fraction:
        found.append(Violation(VALUE_REQ, f"value '{shown}' ends with '.'", True))
    if len(whole) > 1 and whole[0] == "0":
        found.append(Violation(VALUE_REQ, f"value '{shown}' has a leading zero", True))
    if value[0] == "-" and not any(c in "123456789" for c in body):
        found.append(Violation(VALUE_REQ, f"value '{shown}' is a negative zero", True))
    return found


def format_value(x: float | int | str, decimals: int | None = None) -> str:
    """A clean SDI-12 value string for ``x``; raises ValueError if none exists.

    Integers keep every digit. Floats get ``decimals`` places, or, when that is None, as many
    places as the seven-digit budget allows with trailing zeros removed (SDI-12 has no
    exponent, so tiny values round towards zero). A string is returned unchanged if it is
    already a value without any violation, warnings included, so emulator output never needs
    the A13 leniency.
    """
    if isinstance(x, str):
        problems = check_value(x)
        if problems:
            raise ValueError(problems[0].message)
        return x
    if isinstance(x, bool):
        raise ValueError("a boolean is not a measurement value")
    if isinstance(x, int):
        text = str(abs(x))
        if len(text) > MAX_DIGITS:
            raise ValueError(f"{x} needs more than 7 digits")
        return ("-" if x < 0 else "+") + text
    if not math.isfinite(x):
        raise ValueError(f"{x} has no SDI-12 representation")
    if decimals is not None:
        if decimals < 0:
            raise ValueError("decimals must not be negative")
        text = _fixed(x, decimals)
        if text is None:
            raise ValueError(f"{x} with {decimals} decimals needs more than 7 digits")
        return text
    for places in range(MAX_DIGITS - 1, -1, -1):
        text = _fixed(x, places)
        if text is not None:
            if "." in text:
                text = text.rstrip("0").rstrip(".")
            return _signed_zero_fix(text)
    raise ValueError(f"{x} needs more than 7 digits")


def _fixed(x: float, places: int) -> str | None:
    """``x`` with ``places`` decimals and a sign, or None if that exceeds seven digits."""
    text = f"{abs(x):.{places}f}"
    if sum(c.isdigit() for c in text) > MAX_DIGITS:
        return None
    return _signed_zero_fix(("-" if x < 0 else "+") + text)


def _signed_zero_fix(text: str) -> str:
    """Rounded to zero, a negative number would print as ``-0``; A13 warns on that, so use +."""
    if text[0] == "-" and not any(c in "123456789" for c in text):
        return "+" + text[1:]
    return text


def pack_values(values: list[str], limit: int) -> list[str]:
    """Group values greedily into ``<values>`` strings of at most ``limit`` characters.

    This is how a conforming sensor fills D0, D1, ...: as many whole values per reply as fit
    (R-4.4.8.3-03), never splitting one (R-4.4.8.3-01). Raises ValueError if a single value is
    longer than the limit, because no conforming grouping exists then.
    """
    groups: list[str] = []
    current = ""
    for value in values:
        if len(value) > limit:
            raise ValueError(f"value {value!r} is longer than the {limit}-character limit")
        if len(current) + len(value) > limit:
            groups.append(current)
            current = ""
        current += value
    if current:
        groups.append(current)
    return groups
