"""Faulty golden recorders that compose: each fault declares its parts, a composer merges them.

A recorder fault is the golden recorder with deviations at four places: the engine's
:class:`~conformance.tool_recorder.Policy` (values), its
:class:`~conformance.tool_recorder.hooks.Hooks` (decisions), the
:class:`~conformance.tool_recorder.ToolRecorder` itself (public methods) and the recorder
program (:class:`~conformance.recorder.golden.GoldenRecorder` subclass and knobs). Real loggers
have several deviations at once, so :func:`compose` builds one recorder from several faults'
:class:`Parts`:

- policy values are applied in turn; two faults that set one value apart are refused;
- hooks, engine and recorder classes are combined by generated multiple inheritance. Where two
  override the same method, all but one must declare it in their ``CHAINS`` (their override
  changes one thing and passes the call on with ``super()``); those come first in the
  method resolution order, the one that does the job its own way last. Two that do it their
  own way are refused: neither deviation would survive whole;
- knobs (recorder fields) merge when equal, or by union for sets; otherwise refused.

One fault's parts build exactly the recorder it always was (no generated class), so a single
fault's runs are unchanged. :func:`conflict` gives the reason a set is refused, or None; the
combination sampler never draws a refused set.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from dataclasses import dataclass as make_dataclass
from typing import Any

from ..tool_recorder import Policy, ToolRecorder
from ..tool_recorder.hooks import Hooks
from .golden import GoldenHooks, GoldenRecorder, GoldenToolRecorder


class Refused(ValueError):
    """Faults whose deviations cannot be one recorder (the reason says which parts clash)."""


@dataclass(frozen=True)
class Parts:
    """Where one fault departs from the golden recorder (the defaults are the golden one's)."""

    #: Policy fields the fault changes (``Policy.golden().but(**policy)``)
    policy: Mapping[str, Any] = field(default_factory=dict)
    #: engine hooks built on :class:`GoldenHooks` (a fresh instance per engine)
    hooks: type[Hooks] | None = None
    #: engine subclass of :class:`GoldenToolRecorder`, built with the (composed) hooks
    master: type[ToolRecorder] | None = None
    #: recorder program subclass of :class:`GoldenRecorder`
    recorder: type[GoldenRecorder] | None = None
    #: recorder fields the fault sets (``wait``, ``lacks``, ``spoil``...)
    knobs: Mapping[str, Any] = field(default_factory=dict)


def _merge_values(kind: str, named: Sequence[tuple[str, Mapping[str, Any]]]) -> dict[str, Any]:
    """One mapping from several faults' values: equal values agree, sets unite, else refused."""
    merged: dict[str, Any] = {}
    owner: dict[str, str] = {}
    for name, values in named:
        for key, value in values.items():
            if key not in merged or merged[key] == value:
                merged[key] = value
            elif isinstance(value, frozenset) and isinstance(merged[key], frozenset):
                merged[key] = merged[key] | value
            else:
                raise Refused(
                    f"{owner[key]} and {name} both set the {kind} {key} "
                    f"({_shown(merged[key])} and {_shown(value)})"
                )
            owner.setdefault(key, name)
    return merged


def _shown(value: object) -> str:
    return getattr(value, "__name__", None) or repr(value)


def _overrides(cls: type, base: type) -> dict[str, type]:
    """Each attribute ``cls`` gives that ``base`` does not, with the class that defines it."""
    found: dict[str, type] = {}
    for klass in cls.__mro__:
        if klass in base.__mro__:
            break
        for attr in vars(klass):
            if attr == "CHAINS" or (attr.startswith("__") and attr != "__call__"):
                continue  # dataclass and class machinery: not a deviation
            found.setdefault(attr, klass)
    return found


def _combine(layer: str, named: Sequence[tuple[str, type]], base: type) -> type | None:
    """One class from several faults' classes of one layer (hooks, engine, recorder)."""
    unique: dict[type, str] = {}
    for name, cls in named:
        unique.setdefault(cls, name)
    if not unique:
        return None
    for cls in list(unique):  # a fault's class that another's extends is in that one already
        wider = [o for o in unique if o is not cls and issubclass(o, cls)]
        if not wider:
            continue
        mine = set(_overrides(cls, base))
        for other in wider:
            redone = mine & set(vars(other))
            if redone:
                raise Refused(
                    f"{unique[cls]} and {unique[other]} both set the {layer} class's "
                    f"{', '.join(sorted(redone))}"
                )
        del unique[cls]
    if len(unique) == 1:
        return next(iter(unique))
    defined: dict[str, dict[type, str]] = {}  # attribute -> defining class -> fault
    for cls, name in unique.items():
        for attr, klass in _overrides(cls, base).items():
            defined.setdefault(attr, {}).setdefault(klass, name)
    owners: set[type] = set()
    for attr, by in defined.items():
        if len(by) < 2:
            continue
        own = [k for k in by if attr not in getattr(k, "CHAINS", ())]
        if len(own) > 1:
            a, b = (by[k] for k in own[:2])
            raise Refused(f"{a} and {b} both change the {layer} class's {attr} their own way")
        owners.update(own)
    # the classes that only pass shared calls on go first; the one that does the job last
    ordered = sorted(unique, key=lambda c: any(issubclass(c, o) for o in owners))
    label = "+".join(unique[c] for c in ordered)
    try:
        made = type(f"Composed[{label}]", tuple(ordered), {"__module__": __name__})
    except TypeError as exc:
        raise Refused(f"{label}: the {layer} classes do not combine ({exc})") from exc
    return make_dataclass(made) if issubclass(made, GoldenRecorder) else made


@dataclass(frozen=True)
class _MasterFactory:
    """Builds the (composed) engine with fresh (composed) hooks: what a stateful hook
    remembers belongs to one engine, and a recorder may build several."""

    master: type[ToolRecorder]
    hooks: type[Hooks]

    def __call__(self, link: Any, policy: Policy) -> ToolRecorder:
        return self.master(link, policy, hooks=self.hooks())  # type: ignore[call-arg]


def compose(named: Sequence[tuple[str, Parts]]) -> GoldenRecorder:
    """The golden recorder with every named fault's parts (:class:`Refused` if they clash)."""
    policy = Policy.golden().but(**_merge_values("policy value", [(n, p.policy) for n, p in named]))
    knobs = _merge_values("recorder knob", [(n, p.knobs) for n, p in named])
    hooks = _combine("hooks", [(n, p.hooks) for n, p in named if p.hooks], GoldenHooks)
    master = _combine("engine", [(n, p.master) for n, p in named if p.master], GoldenToolRecorder)
    programs = [(n, p.recorder) for n, p in named if p.recorder]
    recorder = _combine("recorder", programs, GoldenRecorder) or GoldenRecorder
    unknown = set(knobs) - {f.name for f in fields(recorder)}
    if unknown:
        raise Refused(f"no recorder of {[n for n, _ in named]} has the knob(s) {sorted(unknown)}")
    factory: Any = GoldenToolRecorder
    if hooks is not None or master is not None:
        factory = _MasterFactory(master or GoldenToolRecorder, hooks or GoldenHooks)
    return recorder(policy=policy, master_factory=factory, **knobs)


def conflict(named: Sequence[tuple[str, Parts]]) -> str | None:
    """Why these faults cannot be one recorder, or None when they compose."""
    try:
        compose(named)
    except Refused as exc:
        return str(exc)
    return None
