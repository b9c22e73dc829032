"""A rack: many devices under test in one run (issue 23, item 4).

``sdi12-conform --port A --port B ...`` or ``sdi12-conform --rack FILE`` (alias
``sdi12-conform rack FILE``) runs the usual single-port run once per port, each in a worker
process of its own started through execnet (the engine pytest-xdist runs its workers on, with
the same ``--tx`` specs: ``popen``, ``ssh=HOST//python=...``), all at once. Each DUT gets its
own report folder inside the rack's folder; the rack adds a summary over them
(``index.html``, ``rack.json``, ``junit.xml`` with one ``<testsuite>`` per DUT) and exits with
the worst DUT's status.

Modules: :mod:`.spec` (what the rack holds: its DUTs, read from the command line or a TOML
rack file), :mod:`.worker` (the code a worker runs: one DUT's run), :mod:`.pool` (workers
started, fed, heard and stopped), :mod:`.summary` (the rack's exit status and files),
:mod:`.command` (the command line).
"""
