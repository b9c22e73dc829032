"""The emulator's fault-detection matrix run through ``--port exec:`` instead of ``sim``.

Each fault of the reference sensor is served by ``examples/python/sensor_harness.py`` in a child
process, so every character crosses the harness protocol (microsecond times, lock-step lines).
A row is exact when the run flags exactly the requirements the fault declares, as on ``sim``:
the harness link must not change a verdict. The one exception is what the link cannot see (the
bit rate, R-4.1-01: INCONCLUSIVE there), which is listed apart.

Usage: ``python benchmarks/harness_fault_matrix.py [FAULT ...]`` (all v1.4 faults by default;
about 4 s per fault).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from conformance.conduct import run_once
from conformance.emulator import FAULTS, SensorEmulator, default_profile
from conformance.matrices.sensor_matrix import row_from

ROOT = Path(__file__).resolve().parents[1]
HARNESS = ROOT / "examples" / "python" / "sensor_harness.py"


#: What a harness link cannot observe: the tool makes the frames of the bytes a harness names.
UNOBSERVABLE = {"R-4.1-01"}


def declaration(folder: Path, fault: str) -> Path:
    """What ``--port sim`` declares for the (faulty) reference sensor (ports.sim_declaration)."""
    profile = SensorEmulator(default_profile("14"), (fault,)).profile
    extended = ", ".join(f'"{name}"' for name in profile.extended)
    path = folder / f"{fault}.toml"
    settable = str(profile.address_settable).lower()
    path.write_text(
        f"factory_fresh = true\n[features]\naddress_change = {settable}\nextended = [{extended}]\n",
        encoding="utf-8",
    )
    return path


def main(names: list[str]) -> int:
    v14 = [
        n
        for n, f in FAULTS.items()
        if (getattr(f, "version", None) or "14") == "14" and not f.bus  # a bus fault needs a bus
    ]
    faults = names or sorted(v14)
    wrong = unseen_rows = 0
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        for name in faults:
            data = run_once(
                f"exec:{sys.executable} {HARNESS} {name}",
                declaration=str(declaration(Path(tmp), name)),
            )
            # what the link cannot see may be INCONCLUSIVE beside the fault's own collateral
            allowed = (*sorted(UNOBSERVABLE), *FAULTS[name].inconclusive)
            row = row_from(name, FAULTS[name].violates, data, allowed)
            unseen = set(row.missed) <= UNOBSERVABLE and not row.extra
            if unseen and row.missed:
                unseen_rows += 1
                print(f"{name}: {list(row.missed)} INCONCLUSIVE (not observable on exec:)")
            elif not row.exact:
                wrong += 1
                print(f"{name}: missed {list(row.missed)}, also {list(row.extra)} {row.other}")
    took = time.monotonic() - started
    exact = len(faults) - wrong - unseen_rows
    print(
        f"{exact}/{len(faults)} faults exact through exec:, {unseen_rows} caught only where "
        f"the link cannot see, {wrong} wrong ({took:.0f} s)"
    )
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
