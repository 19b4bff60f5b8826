"""A command line is split into words exactly as :func:`shlex.split` splits it, with or without its fast path."""

from __future__ import annotations

import shlex

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liansuo.simulation.language import split_words
from liansuo.simulation.sim import Simulation

_TEXT = st.text(alphabet=st.sampled_from(list("aX1-_ .\t\r\n'\"\\#\x0b\x0c\u3000\u00a0联锁")), max_size=30)


@settings(max_examples=400, deadline=None)
@given(_TEXT)
def test_words_as_shlex_gives_them(text: str) -> None:
    try:
        expected = shlex.split(text)
    except ValueError:
        with pytest.raises(ValueError):
            split_words(text)
        return
    assert split_words(text) == expected


@pytest.mark.parametrize("line, words", [
    ("route X  XI", ["route", "X", "XI"]),
    ("route\tX XI\r\n", ["route", "X", "XI"]),
    ("route X\u3000XI", ["route", "X\u3000XI"]),  # an ideographic space is not shlex's whitespace
    ("say 'two words'", ["say", "two words"]),
    ('say "a\\"b"', ["say", 'a"b']),
])
def test_words(line: str, words: list[str]) -> None:
    assert split_words(line) == words


def test_an_unclosed_quote_is_refused_in_words() -> None:
    sim = Simulation("jiaopei")
    result = sim.command("route 'X XI")
    assert not result.ok and "cannot read the command" in result.message
