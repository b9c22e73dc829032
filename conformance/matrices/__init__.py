"""The fault-detection matrices, the suite's own proof (design.md 5): every emulator fault
(``sensor_matrix``) and every golden-recorder fault (``recorder_matrix``) makes exactly its
requirements fail; pairs and triples of faults (``combinations``) give no false FAIL and miss
none; and each fault's run judged again through a capture of itself (``roundtrip``)."""
