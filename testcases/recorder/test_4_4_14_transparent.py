"""Sections 4.4.13, 4.4.13.1, 4.4.14 and 6.3: transparent mode and extended commands."""

from __future__ import annotations

import pytest

from conformance.judges.recorder.capabilities import judge_multiline_end, judge_transparent

from ._helpers import line_of, relayed

requirements = pytest.mark.requirements


@requirements("R-4.4.14-01", "R-4.4.14-02", "R-4.4.13-03", "R-6.3-01")
@pytest.mark.preconditions("recorder")
def test_transparent_mode(recorder, case):
    """Host commands (basic, extended, identify, metadata) go out unchanged after a break and
    their replies are relayed unchanged."""
    case.expect("each host command on the wire exactly as typed, after a break; replies relayed")
    names = [
        n for n in ("transparent", "transparent-v14", "multiline-no-etx") if recorder.applies(n)
    ]
    line = line_of(recorder, case, *names)
    if line is None:
        return
    asked = [c for n in names for c in recorder.run(n).asked]
    reported = {}
    for n in names:
        reported.update(relayed(recorder, n) or {})
    case.extend(judge_transparent(line, asked, recorder.uncertainty, reported or None))


@requirements("R-4.4.13.1-04")
@pytest.mark.preconditions("recorder")
def test_multiline_text_without_etx(recorder, case):
    """Multi-line text that ends without ETX is complete once 150 ms pass with no new line."""
    case.expect("the recorder waits 150 ms after the last line, then goes on; all lines relayed")
    line = line_of(recorder, case, "multiline-no-etx")
    if line is None:
        return
    reported = relayed(recorder, "multiline-no-etx")
    case.extend(judge_multiline_end(line, reported, recorder.uncertainty))
