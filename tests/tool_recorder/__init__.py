"""Tests of conformance/tool_recorder/."""
