"""The tables ``sdi12-conform faults`` prints beyond the sensor's: the golden recorder's
faults, which a user had found only in the error message of a mistyped one."""

from __future__ import annotations

from rich.table import Table


def recorder_faults_table() -> Table:
    from ..recorder.faults import RECORDER_FAULTS

    table = Table(
        title=f"{len(RECORDER_FAULTS)} recorder faults (use --role recorder with "
        "sim://?recorder-faults=NAME[,NAME]; they compose where independent)"
    )
    table.add_column("fault", no_wrap=True, min_width=max(len(n) for n in RECORDER_FAULTS))
    table.add_column("violates", overflow="fold")
    table.add_column("what it does", overflow="fold")
    for name, fault in sorted(RECORDER_FAULTS.items()):
        # a fault no requirement verdict sees (short-reply-timeout): only --sweep shows it
        table.add_row(name, " ".join(fault.violates) or "(none; --sweep)", fault.description)
    return table
