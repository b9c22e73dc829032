"""What the view calls the two sides of the bus, and the protocol facts direction rests on.

Shared by the segmenter and the direction inference, which reads these before a view exists.
"""

from __future__ import annotations

from ..transcript import BUS  # noqa: F401 - re-exported: the view names the sides here

#: The two sides of an SDI-12 bus, as the view names them (independent of which program the
#: tool plays: transcript origins ``tool``/``dut`` say who was on the tool's link, not that).
RECORDER, SENSOR = "recorder", "sensor"


def expected_reply_address(text: str) -> str | None:
    """The address a reply to the command ``text`` must start with (None: any address: the
    wildcard ``?!``, or ``aAb!`` whose reply carries the new address, or the old one)."""
    if text.startswith("?") or len(text) < 2:
        return None
    if len(text) == 4 and text[1] == "A" and text.endswith("!"):
        return None
    return text[0]
