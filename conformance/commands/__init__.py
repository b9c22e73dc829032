"""The subcommands of ``sdi12-conform`` beside the main one (``cli.py``): ``diff``, ``verify``,
``plan``, passive judging of a recording (``judge`` on a capture or transcript), and the fault
tables ``faults`` prints. The command-line layer: these render as they go, so they may import
the reports."""
