"""pytest plugin for sdi12-conform (options, fixtures, markers, report hooks)."""
