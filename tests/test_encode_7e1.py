"""``transcript.encode_7e1`` (one ``bytes.translate``) is the frames ``to_wire_7e1`` gives
character by character, for every character a text may hold (past Latin-1 too)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.transcript import encode_7e1, to_wire_7e1


def _one_by_one(text: str) -> bytes:
    return bytes(to_wire_7e1(ord(c)) for c in text)


def test_every_character_alone():
    for code in range(0x400):
        assert encode_7e1(chr(code)) == _one_by_one(chr(code)), hex(code)


@given(st.text())
def test_any_text(text):
    assert encode_7e1(text) == _one_by_one(text)


def test_a_reply():
    text = "0+3.14-2.5\r\n"
    assert encode_7e1(text) == _one_by_one(text)
    assert encode_7e1("") == b""
