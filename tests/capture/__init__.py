"""Tests of conformance/capture/."""
