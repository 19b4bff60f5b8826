"""The words of a command line, as :func:`shlex.split` gives them, in time linear in the line's length.

The command language splits a line as a POSIX shell does (``shlex.split``): whitespace (space, tab, carriage return,
line feed) separates words, single quotes keep everything to the next single quote, double quotes keep everything to
the next unescaped double quote (a backslash in them escapes only ``"`` and ``\\``), a backslash outside quotes
escapes the next character, and quoted pieces join the word they touch (``a'b c'`` is ``ab c``). shlex builds each
word a character at a time (``token += char``), which is quadratic: a 300,000-character quoted word took seconds
(issue 45). Here regular expressions cut the line into pieces and each word is joined once;
``tests/test_command_words.py`` holds the two equal on generated lines.
"""

from __future__ import annotations

import re

_GAP = r"[ \t\r\n]"
# one piece of a word: plain characters, a single-quoted run, a double-quoted run, or a backslash and what it escapes
_PIECE = re.compile(r"""[^ \t\r\n'"\\]+|'([^']*)'|"((?:[^"\\]|\\[\s\S])*)"|\\([\s\S])""")
_GAPS = re.compile(f"{_GAP}+")
_IN_DOUBLE = re.compile(r'\\(["\\])')  # in double quotes a backslash escapes only these; before others it stays


def split(text: str) -> list[str]:
    """``shlex.split(text)``: the words of ``text``; ``ValueError`` with shlex's words for an unclosed quote or a
    backslash at the very end."""
    words: list[str] = []
    pos, end = 0, len(text)
    gaps = _GAPS
    while True:
        gap = gaps.match(text, pos)
        if gap is not None:
            pos = gap.end()
        if pos >= end:
            return words
        parts: list[str] = []
        while pos < end and text[pos] not in " \t\r\n":
            piece = _PIECE.match(text, pos)
            if piece is None:  # an opening quote without its closing one, or a backslash with nothing after it
                raise ValueError("No escaped character" if text[pos] == "\\" else "No closing quotation")
            single, double, escaped = piece.groups()
            if single is not None:
                parts.append(single)
            elif double is not None:
                parts.append(_IN_DOUBLE.sub(r"\1", double) if "\\" in double else double)
            elif escaped is not None:
                parts.append(escaped)
            else:
                parts.append(piece.group())
            pos = piece.end()
        words.append("".join(parts))
