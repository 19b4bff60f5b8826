"""A command line is split into words exactly as :func:`shlex.split` splits it, with or without its fast path, in
time linear in its length; a line is at most :data:`MAX_LINE_CHARS` long; and every reader of a line's command name
uses the language's parser (issue 45, item 8)."""

from __future__ import annotations

import shlex

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liansuo.classroom.roles import command_word, refusal
from liansuo.simulation.language import MAX_LINE_CHARS, parse_line, split_words
from liansuo.simulation.sim import Simulation
from liansuo.simulation.words import split

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
    (r'''say a'b c'\ d "e\f\\\""''', ["say", "ab c d", 'e\\f\\"']),
    ("say '' x", ["say", "", "x"]),
])
def test_words(line: str, words: list[str]) -> None:
    assert split_words(line) == words


def test_an_unclosed_quote_is_refused_in_words() -> None:
    sim = Simulation("jiaopei")
    result = sim.command("route 'X XI")
    assert not result.ok and "cannot read the command" in result.message


@settings(max_examples=400, deadline=None)
@given(_TEXT)
def test_the_linear_splitter_is_shlex(text: str) -> None:
    """Without the fast path: every line with quotes and backslashes goes through it."""
    try:
        expected = shlex.split(text)
    except ValueError:
        with pytest.raises(ValueError):
            split(text)
        return
    assert split(text) == expected


@pytest.mark.parametrize("make", [
    lambda n: "'" + "a" * n + "'",  # one quoted word: shlex built it a character at a time
    lambda n: '"' + "a\\\"" * (n // 3) + '"',
    lambda n: "\\a" * (n // 2),
    lambda n: "a'b' " * (n // 5),
], ids=["single-quoted", "double-quoted", "escapes", "many-words"])
def test_a_line_of_millions_of_characters_is_split(make: object) -> None:
    """A 300,000-character quoted line took 5.8 s in shlex, which is quadratic; the splitter is linear, so a line ten
    times that is split in about a second (a quadratic one would take hours and hang the suite); the time itself is
    not asserted, as no test here asserts one."""
    assert callable(make)
    line = make(3_000_000)
    words = split(line)
    assert words and len("".join(words)) >= len(line) // 3


def test_a_line_past_the_limit_is_refused_at_once_and_changes_nothing() -> None:
    sim = Simulation("jiaopei")
    before = sim.t, sim.aspect("X")
    for line in ("route X XI '" + "a" * 300_000 + "'", "run " + " " * MAX_LINE_CHARS + "10s"):
        result = sim.command(line)
        assert not result.ok and f"at most {MAX_LINE_CHARS:,} characters" in result.message, result.message
    assert (sim.t, sim.aspect("X")) == before
    assert sim.command("route X XI " + " " * (MAX_LINE_CHARS - 20)).ok  # the limit itself is a line


@pytest.mark.parametrize("line", ["'run' 60s", '"run" 60s', "r\\un 60s", "ru'n' 60s", "run\t60s # a minute"])
def test_the_role_filter_reads_the_name_the_language_reads(line: str) -> None:
    assert parse_line(line)[0] == "run" == command_word(line)
    refused = refusal("trainee", line)
    assert refused is not None and "instructor" in refused.message


def test_a_line_the_language_cannot_read_names_no_command() -> None:
    for line in ("'run 60s", "x" * (MAX_LINE_CHARS + 1), "# run 60s", ""):
        assert command_word(line) == ""
    with pytest.raises(ValueError, match="cannot read the command: No closing quotation"):
        parse_line("'run 60s")
