"""Devices in another process on the virtual-time bus: ``--port exec:...`` and ``unix:...``.

The line protocol is specified in ``docs/harness-protocol.md``; :mod:`.protocol` parses and
checks it (sans-I/O), :mod:`.channel` moves its lines to and from a child process or a Unix
socket, :mod:`.device` puts a sensor harness on the sim bus, :mod:`.recorder` drives a recorder
harness through the tool's link, and :mod:`.client` is the harness side for Python harnesses.
"""
