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

#: ``ask(line)`` for a recorder script: say a plan, read the tool's answer and move the
#: script's global ``now`` to the time the answer gives (a line event's end, ``time T``, the
#: job's start); the answer's word and fields back.
ASK = r"""
def ask(line):
    global now
    say(line)
    word, *f = sys.stdin.readline().split()
    if word in ("break", "sent", "char", "time", "job"):
        now = int(f[0] if word in ("time", "job") else f[1])
    return word, f
"""
