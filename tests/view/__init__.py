"""Tests of conformance/view/."""
