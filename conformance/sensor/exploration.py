"""Property-based exploration of a sensor: random sequences of valid commands, foreign
addresses, malformed commands, breaks and pauses, with invariants checked after every step.

A hypothesis state machine (:mod:`.exploration_machine`, loaded when an exploration runs)
drives the tool recorder. It is derandomised, so every run sends
the same sequences (a certificate must be reproducible), and it never shrinks: a sensor keeps
state between examples (its data buffer, its address), so replaying a shorter sequence is not
the same experiment, and on real hardware a shrinking storm costs minutes of bus time. Each
invariant names the requirement it protects; the first broken one ends the exploration and
its step log becomes the evidence.
"""

from __future__ import annotations

import getpass
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

from ..judges.exploration import IDS as IDS  # the cases import it from here
from .exploration_record import Exploration
from .session import SensorSession

__all__ = ["IDS", "Exploration", "explore"]


def __getattr__(name: str) -> object:
    """``JUNK``, the strategy of the malformed commands, on first use: hypothesis is loaded
    when an exploration runs (or a caller asks for its strategy), not by every run that
    imports the cases (a ``-k`` run, a run without the exploration case). A caller may
    replace it (``monkeypatch.setattr(exploration, "JUNK", ...)``): the machine reads it
    from here when the run starts."""
    if name != "JUNK":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from .exploration_machine import junk_strategy

    globals()["JUNK"] = junk = junk_strategy()
    return junk


def explore(sensor: SensorSession, *, examples: int = 10, steps: int = 25) -> Exploration:
    """Explore ``sensor`` with derandomised random sequences and record what happened; the
    first broken invariant ends the exploration (the sensor is left as the breach left it)."""
    from .exploration_machine import machine_class, run_machine  # hypothesis: loaded here

    record = Exploration()
    junk = globals()["JUNK"] if "JUNK" in globals() else __getattr__("JUNK")  # or a caller's
    # foreign commands go out the way the sensor was shown to hear a one-shot a! (found
    # before the machine starts, so finding it disturbs no sequence); a sensor shown to hear
    # none leaves their silence uncounted
    machine = machine_class(sensor, record, sensor.hearing_marking(), junk)
    keep_hypothesis_out_of_the_working_folder()
    try:
        with no_local_constants(), digests_kept():
            run_machine(machine, examples, steps)
    except BaseException as exc:  # hypothesis may wrap the failure; a breach recorded stands
        if record.broken is None or isinstance(exc, KeyboardInterrupt):
            raise
    return record


@contextmanager
def no_local_constants() -> Iterator[None]:
    """Hypothesis draws now and then from the constants of the non-library modules loaded
    in the process (its "local constants"), so a derandomised exploration sent other
    sequences in a pytest process that had loaded other test modules than the CLI does: the
    same sensor got other stimuli, and other whole-run counts. A certificate's stimuli must
    not depend on what else the process imported: the exploration sees none of them (an
    internal of hypothesis; without it, the library's own behaviour stays)."""
    try:
        from hypothesis.internal.conjecture import providers

        original = providers._get_local_constants
        empty = providers.Constants()
        cache = providers.CONSTANTS_CACHE.cache
    except (ImportError, AttributeError):  # another hypothesis: nothing to hold still
        yield
        return
    cache.clear()  # it holds the local constants allowed per kind of draw
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = original
        cache.clear()


#: hypothesis's own digest of each object the exploration's runs have had digested
_DIGESTS: dict[tuple[object, ...], bytes] = {}


@contextmanager
def digests_kept() -> Iterator[None]:
    """Hypothesis digests the state machine class and its test function on every run (from
    their source text: ``inspect.getsource``, a parse of the module for a class, a tokenize
    of the function), about 11 ms of CPU a run, for its example database only. An
    exploration runs without one (``database=None``) and draws from :data:`SEED`, so nothing
    it sends depends on the digests, but the machine class is made anew per run: the
    digests are kept here per process by what they are a digest of (the class's module,
    name and ``__init__``; the function's code and defaults), each computed once by
    hypothesis itself (``tests/sensor/test_exploration.py`` compares them with its own)."""
    try:
        from hypothesis import core, stateful

        original = stateful.function_digest
    except (ImportError, AttributeError):  # another hypothesis: its own digests, as they are
        yield
        return
    if core.function_digest is not original:  # someone else's stands in: leave it be
        yield
        return

    def kept(function: object) -> bytes:
        key = digest_key(function)
        if key is None:
            return original(function)
        digest = _DIGESTS.get(key)
        if digest is None:
            digest = _DIGESTS[key] = original(function)
        return digest

    stateful.function_digest = core.function_digest = kept
    try:
        yield
    finally:
        stateful.function_digest = core.function_digest = original


def digest_key(function: object) -> tuple[object, ...] | None:
    """What hypothesis's ``function_digest`` of ``function`` rests on: its source (a class's
    found by module and qualified name, a function's by its code), its signature (a class's
    from ``__init__``; a function's from its code, defaults and any ``__signature__`` or
    ``__wrapped__``, annotations) and the ``_hypothesis_internal_add_digest`` it carries. None: an
    object of another kind, or a key that cannot be hashed (digested each time)."""
    add = getattr(function, "_hypothesis_internal_add_digest", None)
    if isinstance(function, type):
        key: tuple[object, ...] = (
            "class",
            function.__module__,
            function.__qualname__,
            function.__init__,
            function.__dict__.get("__signature__"),
            add,
        )
    else:
        code = getattr(function, "__code__", None)
        if code is None:
            return None
        key = (
            "function",
            code,
            getattr(function, "__defaults__", None),
            getattr(function, "__kwdefaults__", None),
            getattr(function, "__signature__", None),
            getattr(function, "__wrapped__", None),
            tuple(getattr(function, "__annotations__", {}).items()),
            add,
        )
    try:
        hash(key)
    except TypeError:
        return None
    return key


def keep_hypothesis_out_of_the_working_folder() -> None:
    """Hypothesis caches (constants, unicode data) in ``./.hypothesis`` even with no example
    database; a conformance run must leave nothing in the user's folder but its reports.
    The cache goes to the user's cache folder unless HYPOTHESIS_STORAGE_DIRECTORY says where."""
    if os.environ.get("HYPOTHESIS_STORAGE_DIRECTORY"):
        return
    from hypothesis.configuration import set_hypothesis_home_dir

    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    home = os.path.join(base, "sdi12-conform", "hypothesis")
    try:
        os.makedirs(home, exist_ok=True)
    except OSError:  # no writable home: a per-user folder under the system's temp folder
        home = os.path.join(tempfile.gettempdir(), f"sdi12-conform-hypothesis-{getpass.getuser()}")
    set_hypothesis_home_dir(home)
