"""The simulated sensor a declaration describes: what ``sdi12-conform plan`` runs the suite
against to say, before the bus is touched, what each case will send and how long the run
will take on the bus (issue 24).

The reference sensor's profile, changed where the declaration speaks: its address, version,
whether its address can be set, which optional families it has (continuous R, high-volume
HA/HB), each declared measurement's value count and ttt, its extended commands. What the
declaration leaves unsaid stays as the reference sensor has it, and :func:`assumptions` says
so (the plan shows those lines), so a plan never passes a guess off as the maker's claim.
"""

from __future__ import annotations

from dataclasses import replace

from ..declaration import Declaration
from ..protocol.values import format_value
from ..protocol.version import V14
from .profile import MeasurementSpec, Profile, default_profile

#: families a declared feature removes when it is false
_FAMILIES = {
    "continuous": tuple(f"R{i}" for i in range(10)),
    "high_volume_ascii": ("HA",),
    "high_volume_binary": ("HB",),
}


def _values(count: int, template: MeasurementSpec | None) -> tuple[str, ...]:
    """``count`` plausible values: the reference sensor's own, repeated, when it has some
    (their widths decide how many D replies the data take), else a short series."""
    source = template.values if template and template.values else ()
    if source:
        return tuple(source[i % len(source)] for i in range(count))
    return tuple(format_value(round(1.0 + i * 0.25, 2), 2) for i in range(count))


def _ready(ttt: int) -> float | None:
    """When the declared sensor's data are ready: half a second before ttt (the reference
    sensor's habit), so the plan's wait per measurement is close to the declared worst."""
    return None if ttt == 0 else max(0.0, ttt - 0.5)


def declared_profile(declaration: Declaration, version: str | None = None) -> Profile:
    """The reference profile as ``declaration`` describes it (``version`` overrides it)."""
    chosen = version or declaration.sdi12_version or V14
    base = default_profile(chosen)
    measurements = dict(base.measurements)
    for feature, codes in _FAMILIES.items():
        if declaration.feature(feature) is False:
            for code in codes:
                measurements.pop(code, None)
    for code in sorted(set(declaration.measurements) | set(declaration.ttt)):
        template = measurements.get(code) or measurements.get(code.rstrip("0123456789"))
        ttt = declaration.ttt.get(code, template.ttt if template else 1)
        count = declaration.measurements.get(code, template.count if template else 1)
        if template is not None and (code == "HB" or count == template.count):
            # the reference's own values (HB: its binary packets), at the declared ttt
            measurements[code] = replace(template, ttt=ttt, ready_after=_ready(ttt))
            continue
        measurements[code] = MeasurementSpec(
            _values(count, template),
            ttt=ttt,
            ready_after=_ready(ttt),
            metadata=tuple(("XV", " ", f"value {i}") for i in range(1, count + 1)),
        )
    extended = {name: base.extended.get(name, "") for name in declaration.extended}
    address_settable = declaration.feature("address_change")
    return replace(
        base,
        address=declaration.address or base.address,
        measurements=measurements,
        extended=extended,  # the suite sends only the declared ones (opt-in)
        address_settable=base.address_settable if address_settable is None else address_settable,
    )


def assumptions(declaration: Declaration) -> list[str]:
    """What the declared sensor plays that the declaration did not say."""
    said = []
    undeclared = [f for f in _FAMILIES if declaration.feature(f) is None]
    if undeclared:
        said.append(
            f"not declared, played as the reference sensor has them: {', '.join(undeclared)}"
        )
    if declaration.feature("address_change") is None:
        said.append("address change not declared: played as settable")
    counts = sorted(set(declaration.ttt) - set(declaration.measurements))
    if counts:
        said.append(f"value counts not declared for {', '.join(counts)}: the reference sensor's")
    times = sorted(set(declaration.measurements) - set(declaration.ttt))
    if times:
        said.append(f"ttt not declared for {', '.join(times)}: the reference sensor's")
    said.append("measurement commands the declaration does not list: the reference sensor's")
    return said
