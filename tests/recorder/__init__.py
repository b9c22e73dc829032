"""Tests of conformance/recorder/."""
