"""The start every recorder-harness script of the tests shares (docs/harness-protocol.md): a
line told to the tool at once, and a character's 7E1 wire byte (even parity in bit 7). The
scripts run as their own processes through ``exec:``, so this is text they begin with."""

PRELUDE = r"""
import sys

def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()

def wire(c):
    b = ord(c)
    return b | (0x80 if bin(b).count("1") % 2 else 0)
"""
