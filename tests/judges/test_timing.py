"""Counted phrases in findings read as English: "6 retries after no reply", not "6 retry after
no replies" (the head noun takes the plural, a command such as aD0! stays as written)."""

import pytest

from conformance.judges.timing import plural


@pytest.mark.parametrize(
    ("phrase", "many"),
    [
        ("break", "breaks"),
        ("reply", "replies"),
        ("delay", "delays"),
        ("character gap", "character gaps"),
        ("retry after no reply", "retries after no reply"),
        ("retry after an invalid reply", "retries after an invalid reply"),
        ("command without a break", "commands without a break"),
        ("wait for data", "waits for data"),
        ("aD0! after a service request", "aD0! after a service request"),
        ("multi-line text without ETX", "multi-line texts without ETX"),
    ],
)
def test_the_head_noun_takes_the_plural(phrase, many):
    assert plural(phrase) == many
