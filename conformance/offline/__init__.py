"""Judging what was recorded instead of what the tool drives now.

``judge`` re-judges a saved run exactly by replay (:mod:`conformance.replay`) or judges any
recording passively (a logic-analyzer capture, a monitor's transcript, a real link's run);
``export`` writes a run as a capture.
"""
