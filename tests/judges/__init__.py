"""Tests of conformance/judges/."""
