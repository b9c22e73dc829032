"""Tests of conformance/judges/recorder/."""
