"""A sensor that took '$' from ``0A$!`` and said so late is moved back, and judged so.

Seed 7900 (accepts-invalid-address + answers-foreign-address + replies-after-retry): the
sensor took '$', its '$<CR><LF>' came 80 ms late, into the ``0!`` after it; the next ``0!``
was answered (answers-foreign-address answers ``a!`` anywhere), so the restore found it
"at '0'" and every later case spoke to an address it had left: R-6.1-01, R-6.2-01/-05/-06/
-07 and R-7.0-16 FAILed on its silence, and R-7.0-09 FAILed "0.00 ms" on the ``0!``'s own
'0<CR><LF>', held behind the '$' reply until the next ``0!`` ended. Now a reply naming '$'
after the probe, however late, says it moved: the restore asks '$' to move back, R-4.3-04
is judged on it (WARN: a MAY rule), and a reply naming another address than its command
asks is no answer to it, so the one after the next command may be its late one.
"""

from __future__ import annotations

from conformance.conduct import run_once
from conformance.emulator import sim_sensor
from conformance.sensor.session import SensorSession

TRIPLE = "accepts-invalid-address,answers-foreign-address,replies-after-retry"
KEYWORD = "test_address_range or test_response_start_window or "
KEYWORD += "test_identify_measurement_answered"


def test_the_late_reply_says_it_took_the_address_and_the_restore_moves_it_back():
    _, link, emulator = sim_sensor(faults=TRIPLE.split(","))
    sensor = SensorSession(link, address="0")
    bad = sensor.try_invalid_address("$")
    assert bad.accepted and bad.late
    assert emulator.address == "0"  # '$' before: the restore took a! answered anywhere


def test_the_clean_sensor_refuses_with_no_late_reply_and_no_move_back():
    _, link, emulator = sim_sensor()
    sensor = SensorSession(link, address="0")
    bad = sensor.try_invalid_address("$")
    assert not bad.accepted and not bad.late and bad.listening
    assert not any(ex.text.startswith("$A") for ex in bad.exchanges)
    assert emulator.address == "0"


def test_the_triple_judges_r_4_3_04_and_no_foreign_rule():
    data = run_once(
        f"sim://?faults={TRIPLE}",
        keyword=KEYWORD,
    )
    found = {r["id"]: r["verdict"] for r in data["requirements"]}
    assert found["R-4.3-04"] == "WARN"  # INCONCLUSIVE before (its probe's control was late)
    assert found["R-7.0-09"] != "FAIL"
    assert found["R-6.1-01"] != "FAIL"
