"""Issue 22, matrix round 12: the emulator's profile key of a command (asked on every
exchange it answers) is worked out from the command's kind, CRC flag and group
(``commands.measurement_code_of``) instead of a copy of the command made to ask it: the
same key as ``replace(target, crc=crc and target.crc).measurement_code`` for every command
the suite sends, and the same ValueError where a command names no measurement."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.emulator import profile as profile_module
from conformance.emulator.profile import measurement_key
from conformance.protocol.commands import Command, parse_command

TEXTS = [
    *(f"0{c}{g}!" for c in ("M", "MC", "C", "CC") for g in ("", *"123456789")),
    "0V!", "0HA!", "0HB!", *(f"0R{i}!" for i in range(10)), *(f"0RC{i}!" for i in range(10)),
    *(f"0I{c}!" for c in ("M", "MC", "C", "CC", "M1", "CC9", "V", "HA", "HB")),
    *(f"0I{c}_{k:03d}!" for c in ("M", "MC", "C2", "CC", "V", "HA", "HB") for k in (0, 1, 7)),
    "0D0!", "0DB3!", "0!", "0I!", "?!", "0A1!", "0XSET!",
]  # fmt: skip


def _by_copy(command: Command, crc: bool) -> str:
    target = command.target if command.target is not None else command
    return replace(target, crc=crc and target.crc).measurement_code


@pytest.mark.parametrize("text", TEXTS)
def test_the_key_is_the_copy_s_code(text: str) -> None:
    command = parse_command(text)
    for crc in (False, True):
        try:
            want: str | type[ValueError] = _by_copy(command, crc)
        except ValueError:
            want = ValueError
        if want is ValueError:
            with pytest.raises(ValueError, match="has no measurement code"):
                measurement_key(command, crc=crc)
        else:
            assert measurement_key(command, crc=crc) == want


def test_no_command_is_made_to_ask_the_key(monkeypatch: pytest.MonkeyPatch) -> None:
    command = parse_command("0IMC2_003!")
    made = []
    init = Command.__init__

    def counted(self, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        made.append(args)
        init(self, *args, **kwargs)

    monkeypatch.setattr(Command, "__init__", counted)
    assert measurement_key(command, crc=True) == "MC2"
    assert measurement_key(command) == "M2"
    assert profile_module.default_profile().spec_for(command) is not None
    assert made == []
