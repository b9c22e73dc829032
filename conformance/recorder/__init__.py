"""The recorder role: the tool plays sensors and judges the data recorder under test.

- :mod:`.played`: the sensors put on the bus (reference emulators and misbehaving adapters);
- :mod:`.scenarios`: what is on the bus and what the recorder is asked to do;
- :mod:`.request`: the request handed to the recorder and its own account of the job;
- :mod:`.golden`: the golden recorder (the tool recorder as a recorder under test);
- :mod:`.drivers`: how the recorder is made to act (in-process, trigger, interactive);
- :mod:`.session`: runs scenarios and keeps their transcripts;
- :mod:`.faults`: faulty golden recorders for the fault-detection matrix.
"""
