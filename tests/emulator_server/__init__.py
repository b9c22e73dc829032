"""Tests of conformance/emulator_server/."""
