"""Tests of conformance/emulator/."""
