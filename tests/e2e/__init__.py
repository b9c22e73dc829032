"""End-to-end tests by theme."""
