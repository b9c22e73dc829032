"""The exploration's observations judged once (issue 22, matrix23): the machine judges each
as it is made (the first breach ends the run), then the case asked ``Exploration.broken``
(every observation judged again) up to three times and ``held_findings`` twice more
(``first_breach`` and ``checks``): some 250 observations a run, six judgements each, a CRC
parsed in each D reply's. :func:`~conformance.judges.exploration.judge` is pure, so it keeps
what it judged (a bounded table, as ``parse_command`` keeps its commands): an equal record
judges alike, once, here and in the replay of the same run. It must give what judging afresh
gives, for every kind of check, breach or not."""

from __future__ import annotations

import random

import pytest

from conformance.judges import exploration
from conformance.judges.exploration import (
    Observation,
    checks,
    first_breach,
    held_findings,
    judge,
)
from conformance.protocol.crc import ascii_crc


def _observations(n: int, rng: random.Random) -> list[Observation]:
    """Drawn observations of every check, each kind with and without its breach."""
    out = []
    for _ in range(n):
        body = rng.choice(["0+1.5-2", "0", "0+3", "1+1.5", "0+12.25+7"])
        crc = ascii_crc(body)
        if rng.random() < 0.2:
            crc = "".join(chr(ord(c) | 0x60) for c in crc)  # encoded as no CRC-16's
        reply = rng.choice([f"{body}\r\n", f"{body}{crc}\r\n", body, f"{body}{crc}"])
        kind = rng.choice(["foreign", "framing", "crc", "repeat"])
        if kind == "foreign":
            answered = rng.random() < 0.2
            out.append(
                Observation(
                    "foreign",
                    "1M!",
                    reply if answered else "",
                    "1",
                    answered=answered,
                    marked=rng.random() < 0.8,
                    collided=rng.random() < 0.1,
                )
            )
        elif kind == "framing":
            out.append(Observation("framing", "0M!", reply, "0"))
        elif kind == "crc":
            out.append(Observation("crc", rng.choice(["0D0!", "0RC0!"]), reply))
        else:
            previous = rng.choice([None, "0\r\n", "0+1.5-2\r\n", reply])
            out.append(Observation("repeat", "0D0!", reply, previous=previous))
    return out


def _afresh(obs: Observation) -> exploration.Judgement:
    return exploration._JUDGES[obs.check](obs)


@pytest.mark.parametrize("seed", range(8))
def test_kept_judgements_are_what_judging_afresh_gives(seed) -> None:
    observations = _observations(400, random.Random(seed))
    assert any(_afresh(o).breach is not None for o in observations)
    assert any(_afresh(o).breach is None and _afresh(o).checked for o in observations)
    for _ in range(2):  # kept the second time round
        assert [judge(o) for o in observations] == [_afresh(o) for o in observations]
    clean = [o for o in observations if _afresh(o).breach is None]
    for obs in (observations, clean):
        breach = next((b for b in map(lambda o: _afresh(o).breach, obs) if b), None)
        assert first_breach(obs) == breach
        counted = {rid: 0 for rid in exploration.IDS}
        for o in obs:
            for rid in _afresh(o).checked:
                counted[rid] += 1
        assert checks(obs) == counted


def test_an_observation_is_judged_once_however_often_asked(monkeypatch) -> None:
    """What the case asks of one run (each step's judgement, ``broken`` three times, the
    held findings) judges each distinct observation once."""
    calls: list[Observation] = []
    for check, inner in list(exploration._JUDGES.items()):

        def counted(obs, inner=inner):
            calls.append(obs)
            return inner(obs)

        monkeypatch.setitem(exploration._JUDGES, check, counted)
    monkeypatch.setattr(exploration, "_JUDGED", {})
    observations = _observations(300, random.Random(11))
    for o in observations:
        judge(o)
    for _ in range(3):
        first_breach(observations)
    held_findings(observations, len(observations))
    assert len(calls) == len(set(observations))


def test_the_kept_judgements_are_bounded(monkeypatch) -> None:
    monkeypatch.setattr(exploration, "_JUDGED", {})
    monkeypatch.setattr(exploration, "JUDGED_MAX", 50)
    observations = _observations(400, random.Random(5))
    for o in observations:
        assert judge(o) == _afresh(o)
        assert len(exploration._JUDGED) <= 50
