"""Tests of conformance/monitor/."""
