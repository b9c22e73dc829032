"""Where a conformance case's record is kept on its pytest item.

The plugin puts a :class:`~conformance.results.CaseRecord` there when it collects a case; the
report plugins (console progress, HTML) read it back. The key lives below all of them so the
reports need not import the plugin that registers them.
"""

from __future__ import annotations

import pytest

from .results import CaseRecord

CASE = pytest.StashKey[CaseRecord]()
