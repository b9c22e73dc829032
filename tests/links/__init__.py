"""Tests of conformance/links/."""
