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

from ...view.segments import TranscriptView, merge_views, read_view

# Re-exported under their old names for conformance/recorder/session.py (outside this
# package's owner's remit): the scenario's wire is now the shared TranscriptView.
Line = TranscriptView
read_line = read_view
merge_lines = merge_views

__all__ = ["Line", "merge_lines", "read_line"]
