"""Tests of conformance/harness/."""
