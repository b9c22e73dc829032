"""The harness protocol's ``batch`` feature (``hello V+batch``, docs/harness-protocol.md,
"Batches"): a write's characters in one ``chars`` message, and a QUIET field on every message,
so that a harness wakes itself for its waits until then. The point is fewer round trips with
the same device behaviour: every test here runs one device both ways and finds the same line,
instant for instant, in fewer messages."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from conformance.harness import protocol as proto
from conformance.harness.device import open_sensor_harness
from conformance.harness.protocol import HarnessProtocolError

# -- the protocol's new words ------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "parsed"),
    [
        ("hello 1 plain", ("plain", 1, frozenset())),
        ("hello 2+batch kit sketch", ("kit sketch", 2, frozenset({"batch"}))),
        ("hello 1+batch", ("", 1, frozenset({"batch"}))),
    ],
)
def test_a_hello_names_its_features_after_its_version(text, parsed):
    assert proto.parse_hello_features(text) == parsed
    assert proto.parse_hello_version(text) == parsed[:2]


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("hello 2+fast kit", "unknown or repeated feature 'fast'"),
        ("hello 2+batch+batch kit", "unknown or repeated feature"),
        ("hello 3+batch kit", "another protocol version"),
        ("hello +batch kit", "another protocol version"),
    ],
)
def test_an_unknown_feature_or_version_is_refused(text, reason):
    with pytest.raises(HarnessProtocolError, match=reason):
        proto.parse_hello_features(text)


def test_a_batch_lists_each_character_with_its_frame():
    frames = [(0x30, 0.022, 0.0303333333), (0x21, 0.0303333333, 0.0386666667)]
    assert proto.heard_chars(frames) == "chars 22000 30333 30 30333 38667 21"


@pytest.mark.parametrize(
    ("text", "count", "parsed"),
    [("heard 3 idle", 3, (3, "idle")), ("heard 1 tx 5000 30", 4, (1, "tx 5000 30"))],
)
def test_a_batch_is_answered_with_how_many_were_heard_and_the_plan(text, count, parsed):
    assert proto.parse_heard(text, count) == parsed


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("idle", "answered 'heard K PLAN'"),
        ("heard 3", "answered 'heard K PLAN'"),
        ("heard 0 idle", "count from 1 to 3"),
        ("heard 4 idle", "count from 1 to 3"),
        ("heard x idle", "count from 1 to 3"),
    ],
)
def test_a_wrong_batch_answer_is_refused(text, reason):
    with pytest.raises(HarnessProtocolError, match=reason):
        proto.parse_heard(text, 3)


def test_quiet_is_rounded_down_so_a_harness_never_wakes_itself_where_the_tool_would_not():
    """A harness takes ``wait T`` with T < QUIET as answered: every such T must be before
    the tool's limit in seconds, which rounding to the nearest microsecond would break."""
    for limit in (0.0123333333, 0.0386666667, 1.0000004999, 2.5):
        quiet = proto.quiet_until(limit)
        assert quiet is not None and proto.seconds(quiet - 1) < limit <= proto.seconds(quiet + 1)
    assert proto.quiet_until(float("inf")) is None


# -- one device, told both ways ----------------------------------------------------------

#: A sensor harness: it answers ``0!``-style commands ("0" CR LF) at its first poll at least
#: 10 ms after the ``!`` (it polls every 500 us while a reply is due), and it breaks into
#: the tool's third character of a command of four or more (a frame planned 1 ms before that
#: character's start: the bus delays it to the end of the second, as it does a device's
#: character planned on the tool's). MODE ``batch`` speaks the feature (a ``chars`` message
#: told in turn, stopped where its plan acts before the next start; waits before QUIET taken
#: as answered), ``plain`` answers ``hello 1``. Every message is appended to LOG.
SCRIPTED = textwrap.dedent(
    """
    import sys
    MODE, LOG = sys.argv[1], open(sys.argv[2], "a")
    state = {"due": None, "reply": [], "heard": 0, "barged": False}

    def heard(wire, start, end):
        state["heard"] += 1
        if wire == 0x21:
            state["due"], state["reply"], state["heard"] = end + 10000, [0x30, 0x8D, 0x0A], 0

    def plan(now):
        if state["heard"] == 2 and not state["barged"]:
            return f"tx {now - 1000} 30"
        if state["reply"] and state["due"] is None:
            return f"tx {now} {state['reply'][0]:02x}"
        if state["due"] is not None:
            return f"tx {now} 30" if now >= state["due"] else f"wait {now + 500}"
        return "idle"

    def settle(now, quiet):
        while True:
            answer = plan(now)
            if quiet is None or not answer.startswith("wait") or int(answer.split()[1]) >= quiet:
                return answer
            now = int(answer.split()[1])  # woken by itself: the tool promised nothing before

    def sent():
        if state["heard"] == 2 and not state["barged"]:
            state["barged"] = True
        elif state["due"] is not None:
            state["due"] = None
            state["reply"].pop(0)
        elif state["reply"]:
            state["reply"].pop(0)

    for line in sys.stdin:
        LOG.write(line)
        LOG.flush()
        word, *f = line.split()
        if word == "hello":
            print("hello 1+batch scripted" if MODE == "batch" else "hello 1 scripted", flush=True)
            continue
        if word == "bye":
            break
        if word == "chars":
            triples = [f[i:i + 3] for i in range(0, len(f), 3)]
            for k, (s, e, x) in enumerate(triples):
                heard(int(x, 16), int(s), int(e))
                nxt = int(triples[k + 1][0]) if k + 1 < len(triples) else None
                answer = settle(int(e), nxt)
                keep = nxt is not None and (answer == "idle" or (
                    answer.startswith("wait") and int(answer.split()[1]) > nxt))
                if not keep:
                    break
            print(f"heard {k + 1} {answer}", flush=True)
            continue
        quiet = None
        if word == "time":
            now, quiet = int(f[0]), (int(f[1]) if len(f) > 1 else None)
        else:
            now = int(f[1])
            quiet = int(f[-1]) if len(f) == (3 if word == "break" else 4) else None
        if word == "break":
            state["heard"], state["barged"] = 0, False
        elif word == "char":
            heard(int(f[2], 16), int(f[0]), now)
        elif word == "sent":
            sent()
        print(settle(now, quiet if MODE == "batch" else None), flush=True)
    """
)


MODES = ("plain", "batch")


def drive(script: Path, mode: str, log: Path) -> list[tuple]:
    """The same tool actions on the scripted harness in ``mode``: the line it made."""
    link = open_sensor_harness(f"exec:{sys.executable} {script} {mode} {log}")
    try:
        for command in (b"0!", b"0XAB!", b"1!"):
            link.send_break(0.0125)
            link.wait_until(link.now() + 0.009)
            link.write(command)
            link.receive(link.now() + 0.1, until=lambda got: got[-1].wire == 0x0A)
            link.wait_until(link.now() + 0.02)
        link.device.plan  # noqa: B018 - the last answer read
        link.device.channel.finish(proto.BYE)
    finally:
        link.close()
    return [(e.kind, e.origin, e.start, e.end, e.wire) for e in link.transcript.events]


def test_a_batch_harness_makes_the_same_line_in_fewer_messages(tmp_path: Path):
    script = tmp_path / "scripted.py"
    script.write_text(SCRIPTED)
    plain = drive(script, "plain", tmp_path / "plain.log")
    batch = drive(script, "batch", tmp_path / "batch.log")
    assert batch == plain
    told = {mode: (tmp_path / f"{mode}.log").read_text().splitlines() for mode in MODES}
    # each command in one message, up to where the device broke in (after 2 of "0XAB!")
    chars = [line for line in told["batch"] if line.startswith("chars")]
    assert [len(line.split()) // 3 for line in chars] == [2, 5, 3, 2]
    assert not [line for line in told["batch"] if line.startswith("char ")]
    # the device's barge-in went out between the tool's 2nd and 3rd characters, both ways
    bang = [e for e in plain if e[1] == "dut"]
    assert len(bang) == 3 * 3 + 1
    # its polls for the reply: a `time` each, told plainly; woken by itself in the batch
    polls = {mode: sum(line.startswith("time") for line in lines) for mode, lines in told.items()}
    assert polls["plain"] >= 3 * 20 and polls["batch"] <= 3
    assert len(told["batch"]) * 3 < len(told["plain"])
