"""Tests of conformance/sensor/."""
