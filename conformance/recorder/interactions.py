"""Declared interactions between golden-recorder faults (the recorder combination matrix).

As for the emulator's faults (:mod:`conformance.emulator.faults.interactions`, whose
:class:`Interaction` this reuses): an entry records only where a combination genuinely changes
what a correct tool must say on the wire (one member hides another's deviation, or the two
together break a further rule), with its reason; never to make a row pass.
"""

from __future__ import annotations

from ..emulator.faults.interactions import Interaction

RECORDER_INTERACTIONS: tuple[Interaction, ...] = ()
