"""Recorder-role conformance cases: the tool plays sensors and judges the data recorder.

Named after the sections of the standard, like ``testcases/sensor``. Each case asks the
``recorder`` session for the scenarios its requirements are judged on; a scenario runs once
per run and every case that needs it judges the same transcript.
"""
