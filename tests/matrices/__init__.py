"""Tests of conformance/matrices/."""
