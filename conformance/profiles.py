"""Named selections of the sensor suite for a purpose other than certification.

``production``: an end-of-line test (issue 23, item 5). A factory tests every unit it
builds, so the run must be short on a real link; it checks what a unit that left the line
broken would get wrong (it answers at its address and identifies itself, a measurement of
each kind gives its values with a right CRC, its replies keep the timing windows), not
everything a certification run checks. Where a case tries every measurement group
(``aM1!``..``aM9!``, ``aC1!``..) the profile tries only the base ones (``aM!``, ``aMC!``,
``aC!``, ``aCC!``), and the report says so: its PASSes rest on those. The run is a partial
one: the requirements its cases do not judge are "not selected", never INCONCLUSIVE, and
the verdict says it covers the profile only.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Profile:
    """A named selection: the cases it runs (by function name), the measurement command
    codes that cases trying a whole family may try, and one line on what it is for."""

    name: str
    about: str
    cases: tuple[str, ...]
    groups: frozenset[str]
    #: a run's own folder is named by the sensor's serial number (a unit's report found)
    folder_by_serial: bool = False

    def note(self) -> str:
        """What the report says about the profile's stimuli."""
        codes = ", ".join(f"a{c}!" for c in sorted(self.groups))
        return (
            f"--profile {self.name}: {self.about}; cases that try every measurement group "
            f"tried {codes} only"
        )


PRODUCTION = Profile(
    name="production",
    about="an end-of-line test: identification, address, one measurement of each kind with "
    "its CRC, the timing windows",
    cases=(
        "test_acknowledge_active",
        "test_identification",
        "test_query_address",
        "test_measurement_reply",
        "test_service_request",
        "test_data_replies",
        "test_announced_values_delivered",
        "test_crc_value_and_encoding",
        "test_concurrent_reply",
        "test_break_just_over_12ms_wakes",
        "test_response_start_window",
        "test_character_gaps",
        "test_reply_framing",
    ),
    groups=frozenset(("M", "MC", "C", "CC")),
    folder_by_serial=True,
)

PROFILES: dict[str, Profile] = {p.name: p for p in (PRODUCTION,)}
