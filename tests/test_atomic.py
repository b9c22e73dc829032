"""An output that is whole or not there, wherever a Ctrl-C lands (conformance.atomic)."""

from __future__ import annotations

import os

import pytest

from conformance import atomic
from conformance.atomic import atomic_path


def test_a_whole_write_replaces_the_file_with_plain_permissions(tmp_path):
    target = tmp_path / "capture.vcd"
    target.write_text("earlier")
    with atomic_path(target) as partial:
        partial.write_text("new")
    assert target.read_text() == "new" and list(tmp_path.iterdir()) == [target]
    mask = os.umask(0)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask


def test_an_interrupt_while_writing_keeps_the_earlier_file_and_no_partial(tmp_path):
    target = tmp_path / "capture.vcd"
    target.write_text("earlier")
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as partial:
        partial.write_text("half")
        raise KeyboardInterrupt
    assert target.read_text() == "earlier" and list(tmp_path.iterdir()) == [target]


def test_an_interrupt_as_the_temporary_file_is_made_leaves_nothing(tmp_path, monkeypatch):
    """Seen with a Ctrl-C sent as soon as the file appeared: the interrupt came as the file
    was created (tempfile named it only once made) and a ``.partial`` stayed behind."""
    made = os.close

    def interrupted(fd: int) -> None:  # the file exists; the interrupt comes before the rest
        made(fd)
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic.os, "close", interrupted)
    with pytest.raises(KeyboardInterrupt), atomic_path(tmp_path / "capture.vcd"):
        pass
    assert list(tmp_path.iterdir()) == []
