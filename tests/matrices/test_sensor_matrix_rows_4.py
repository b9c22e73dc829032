"""The sensor fault matrix, rows of shard 4 of 4 (tests/matrices/sensor_rows.py says why the
rows are split): each fault caught by exactly the requirements it declares."""

from __future__ import annotations

import pytest

from tests.matrices.sensor_rows import check_row, shard_params


@pytest.mark.parametrize("fault", shard_params(4))
def test_fault_is_caught_by_exactly_its_requirements(fault, sensor_rows):
    check_row(fault, sensor_rows[fault])
