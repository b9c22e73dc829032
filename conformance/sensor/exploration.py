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
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from types import ModuleType

from .. import gc_pace
from ..judges.exploration import IDS as IDS  # the cases import it from here
from . import exploration_plans
from .exploration_record import Exploration
from .exploration_steps import foreign_addresses, plain_machine, release_attributes, run_plan
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
    junk_strategy = _machine_module().junk_strategy
    globals()["JUNK"] = _MADE["JUNK"] = junk = junk_strategy()
    return junk


#: the junk strategy this module made (a caller may put another in ``JUNK``)
_MADE: dict[str, object] = {}


#: hypothesis's switch for its entry-point plugins (``hypothesis.entry_points.run``)
NO_PLUGINS = "HYPOTHESIS_NO_PLUGINS"


def _machine_module() -> ModuleType:
    """:mod:`.exploration_machine`, and hypothesis with it, loaded without the environment's
    hypothesis plugins: as the judged pytest session loads none of the environment's pytest
    plugins (``suite.suite_args``), a package registering a hypothesis entry point (a
    settings profile, another backend) must not change the exploration's stimuli; finding
    none also read every installed distribution's entry points (4 ms with 28 of them).
    Where hypothesis is already loaded (a pytest session with its plugin), nothing changes;
    the variable is the user's again once the import is done."""
    global _DRAWS_ALONE
    if "hypothesis" in sys.modules or NO_PLUGINS in os.environ:
        _DRAWS_ALONE = _DRAWS_ALONE or "hypothesis" not in sys.modules
        from . import exploration_machine

        return exploration_machine
    os.environ[NO_PLUGINS] = "1"
    try:
        from . import exploration_machine
    finally:
        os.environ.pop(NO_PLUGINS, None)
    _DRAWS_ALONE = True
    return exploration_machine


#: whether this process's hypothesis was loaded by :func:`_machine_module` without the
#: environment's plugins: only its draws are stored for later processes
#: (:mod:`.exploration_plans`)
_DRAWS_ALONE = False


def explore(
    sensor: SensorSession, *, examples: int = 10, steps: int = 25, planned: bool = True
) -> Exploration:
    """Explore ``sensor`` with derandomised random sequences and record what happened; the
    first broken invariant ends the exploration (the sensor is left as the breach left it).

    ``planned``: the steps hypothesis draws are drawn once a process (``plan_for``: they
    depend on no reply) and sent as hypothesis sends them (``run_plan``), not drawn again
    each run; issue 22, about three quarters of the case's CPU in a fault-matrix row. A plan
    an earlier process stored (:mod:`.exploration_plans`) is sent without hypothesis, which
    is then never loaded. ``planned=False`` runs hypothesis with the sending machine, as
    before (the tests prove the three alike on every fault)."""
    record = Exploration()
    key = _plan_key(sensor, examples, steps) if planned else None
    stored = exploration_plans.STORE.load(key) if key is not None else None
    if stored is not None:
        # foreign commands go out the way the sensor was shown to hear a one-shot a!
        plain = plain_machine(sensor, record, sensor.hearing_marking())
        machine, release = plain, release_attributes
        send: Callable[[], None] = partial(run_plan, plain, stored)
    else:
        machine, release, send = _with_hypothesis(sensor, record, examples, steps, planned, key)
    try:
        send()
    except BaseException as exc:  # hypothesis may wrap the failure; a breach recorded stands
        if record.broken is None or isinstance(exc, KeyboardInterrupt):
            raise
    finally:
        release(machine)  # hypothesis keeps the class for the process: not the run with it
    return record


def _plan_key(sensor: SensorSession, examples: int, steps: int) -> str | None:
    """The key of the plan this run may send from the store: None when the junk strategy is
    a caller's (only the exploration's own is stored)."""
    if "JUNK" in globals() and globals()["JUNK"] is not _MADE.get("JUNK"):
        return None
    return exploration_plans.plan_key(foreign_addresses(sensor), examples, steps)


def _with_hypothesis(
    sensor: SensorSession,
    record: Exploration,
    examples: int,
    steps: int,
    planned: bool,
    key: str | None,
) -> tuple[type, Callable[[type], None], Callable[[], None]]:
    """The machine of a run with hypothesis loaded, how to release it, and the run (a plan
    it draws under ``key`` is stored for later processes where :func:`_machine_module`
    loaded hypothesis without the environment's plugins)."""
    gc_pace.freeze_for_libraries()  # hypothesis's one gc.collect() walks only what it made
    machine_module = _machine_module()  # hypothesis: loaded here
    junk = globals()["JUNK"] if "JUNK" in globals() else __getattr__("JUNK")  # or a caller's
    # foreign commands go out the way the sensor was shown to hear a one-shot a! (found
    # before the machine starts, so finding it disturbs no sequence); a sensor shown to hear
    # none leaves their silence uncounted
    machine = machine_module.machine_class(sensor, record, sensor.hearing_marking(), junk)
    keep_hypothesis_out_of_the_working_folder()

    def send() -> None:
        with no_local_constants(), no_database_key():
            if not planned:
                machine_module.run_machine(machine, examples, steps)
                return
            foreign = machine_module.foreign_addresses(sensor)
            plan = machine_module.plan_for(foreign, junk, examples, steps)
            if key is not None and _DRAWS_ALONE:
                exploration_plans.quietly_store(key, plan)
            machine_module.run_plan(machine, plan)

    return machine, machine_module.release, send


def forget_plans() -> None:
    """Drop the exploration plans this process has drawn, and send no stored plan from now
    on (tests that want hypothesis to draw afresh); nothing to drop where no exploration
    ran."""
    exploration_plans.send_nothing_stored()
    if "conformance.sensor.exploration_machine" in sys.modules:
        sys.modules["conformance.sensor.exploration_machine"].forget_plans()


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


#: the example database's key the exploration's runs are given: it has no database
NO_DATABASE_KEY = b"sdi12-conform exploration: no example database"


@contextmanager
def no_database_key() -> Iterator[None]:
    """Hypothesis digests a test's source for its example database's key (the state machine
    class's and its own runner's: ``inspect.getsource`` with a parse of the module, about
    20 ms a run), even with ``database=None``, where the key is never read: the examples come
    from the machine's ``@seed``, not from the digest (``get_random_for_wrapped_test``). The
    run gets a fixed key instead (an internal of hypothesis; without it, the library's own
    behaviour stays). What is drawn, sent and judged is the same."""
    try:
        from hypothesis import core, stateful
        from hypothesis.internal.reflection import function_digest
    except ImportError:
        yield
        return
    if not (core.function_digest is function_digest is stateful.function_digest):
        yield  # another hypothesis, or someone else's digest: leave it
        return
    core.function_digest = stateful.function_digest = lambda function: NO_DATABASE_KEY
    try:
        yield
    finally:
        core.function_digest = stateful.function_digest = function_digest


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
