"""Judging a saved run again: its transcript played back through the same cases.

``--port replay:PATH`` (PATH: a run folder or its ``transcript.jsonl``) puts the recorded
device under test on the simulated bus: :class:`~conformance.replay.sensor.RecordedSensor` in
the sensor role, :class:`~conformance.recorder.replay_driver.RecordedRecorder` in the recorder role.
The cases ask what they asked; the recording answers. Only recordings of virtual-time runs
(sim, harness) replay exactly; a recording of a real link is judged passively instead.
"""
