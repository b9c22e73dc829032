"""``segments.collided`` answers "nothing met the transmission" without its loop per
character when every character started after it ended and none is a collision: the same
list the loop gives, for characters before, across and after the end, collisions among
them, in or out of time order."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.transcript import COLLISION, DUT, Event, EventKind, to_wire_7e1
from conformance.view.segments import _collided_each, collided

END = 0.1


@st.composite
def heard(draw):
    out = []
    for _ in range(draw(st.integers(0, 12))):
        start = draw(st.sampled_from([0.09, 0.095, END, 0.1001, 0.105, 0.11, 0.2]))
        start += draw(st.sampled_from([0.0, 0.0, 1e-4, 8.3e-3]))
        text = draw(st.sampled_from(["", "", "", COLLISION]))
        char = draw(st.sampled_from("0+\r\n"))
        u = draw(st.sampled_from([0.0, 0.0, 2e-4]))
        out.append(
            Event(EventKind.CHAR, DUT, start, start + 8.33e-3, to_wire_7e1(ord(char)), text, u)
        )
    if draw(st.booleans()):
        out.sort(key=lambda e: e.start)
    return out


@given(heard())
def test_quick_answer_is_the_loops(events):
    assert collided(events, END) == _collided_each(events, END)


@given(heard(), st.sampled_from(["0", "\n"]), st.sampled_from([0.08, END - 8.33e-3, END]))
def test_quick_answer_is_the_loops_after_a_cut_frame(events, char, at):
    """With a frame the transmission cut into (its last character before it), the loop runs
    whatever the characters' times: a tail right after the transmission is that frame's."""
    cut = Event(EventKind.CHAR, DUT, at - 8.33e-3, at, to_wire_7e1(ord(char)))
    assert collided(events, END, cut) == _collided_each(events, END, cut)


def test_nothing_met():
    late = [
        Event(EventKind.CHAR, DUT, END + 0.01 * i, END + 0.01 * i + 8.3e-3, 0x30) for i in range(3)
    ]
    assert collided(late, END) == [] == _collided_each(late, END)
    met = [Event(EventKind.CHAR, DUT, END - 1e-3, END + 7e-3, 0x30), *late]
    assert collided(met, END) == _collided_each(met, END) != []
