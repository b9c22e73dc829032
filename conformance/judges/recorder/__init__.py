"""Judges of a data recorder, from the wire alone (pure functions over the transcript view).

In the recorder role the tool plays the sensors and watches what the recorder under test
does. Every judge reads the shared, role-neutral view (:mod:`conformance.view`): each
transmission of the recorder and what the sensors sent until it acted again. Timing is
measured with the link's uncertainty and judged with
:func:`~conformance.judges.timing.judge_window`; validity of the sensors' replies is the
judges' own (:mod:`conformance.judges.reply_validity`), never the golden recorder's.

Modules: ``replies`` (validity per transmission), ``retries`` (retry reconstruction and the
section 7.2 judges), ``measurements`` (measurement reconstruction), ``breaks``, ``commands``,
``waits``, ``collection``, ``capabilities`` (the judges, grouped by what they judge).
"""

from __future__ import annotations
