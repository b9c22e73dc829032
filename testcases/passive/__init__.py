"""Passive cases: every rule that traffic alone can show, judged on a recording (a capture,
a transcript) by the same judges the live cases call, on records rebuilt from the shared view.

Sensor-rule cases ask for ``heard_sensors``, recorder-rule cases for ``heard_recorder``; a
rule whose stimulus the recording does not hold is INCONCLUSIVE "not seen in the recording".
"""
