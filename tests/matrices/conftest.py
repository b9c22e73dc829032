"""The sensor fault matrix's rows, made once per module that holds some
(``test_sensor_matrix_rows_<n>.py``), for that module's selected faults only."""

from __future__ import annotations

import os

import pytest

from conformance.matrices.roundtrip import row_through_sampled_capture
from conformance.matrices.sensor_matrix import MatrixRow, fault_matrix


def selected_params(request: pytest.FixtureRequest, name: str) -> list[str]:
    """The values of parameter ``name`` among this module's selected tests."""
    return sorted(
        {
            item.callspec.params[name]
            for item in request.session.items
            if item.module is request.module
            and name in getattr(getattr(item, "callspec", None), "params", {})
        }
    )


def row_processes() -> int:
    """Processes a module's rows run in: under pytest-xdist the workers already share the
    cores (each rows module on one of them), so the rows run in the worker itself; a session
    without it runs them two at a time, as ``sdi12-conform matrix`` does."""
    return 1 if os.environ.get("PYTEST_XDIST_WORKER") else 2


@pytest.fixture(scope="module")
def sensor_rows(request: pytest.FixtureRequest) -> dict[str, MatrixRow]:
    wanted = selected_params(request, "fault")
    made = fault_matrix(wanted, processes=row_processes(), row=row_through_sampled_capture)
    return {r.fault: r for r in made}
