"""Tests of conformance/offline/."""
