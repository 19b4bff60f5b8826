"""``liansuo test -k EXPRESSION``: pytest's ``-k`` expressions, for the tests of YAML scripts.

The grammar is pytest's (``_pytest/mark/expression.py``; pytest is not needed to run ``liansuo test``, so it is
written out here)::

    expression: expr? EOF
    expr:       and_expr ('or' and_expr)*
    and_expr:   not_expr ('and' not_expr)*
    not_expr:   'not' not_expr | '(' expr ')' | words
    words:      word+
    word:       (\\w|:|\\+|-|\\.|\\[|\\]|\\\\|/)+

A word is true when it is part of one of a test's names, ignoring case: the test's own name or its script's file
name, as pytest matches an item's name and its file's. ``and``, ``or``, ``not`` and parentheses mean what they mean
in Python. One liberty beyond pytest: words that follow each other with no operator between are one phrase, so
``-k "guide signal"`` selects the tests whose name contains ``guide signal`` (pytest would refuse it, since its names
have no spaces). An empty expression selects every test.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import NoReturn

WORD = re.compile(r"(?:\w|:|\+|-|\.|\[|\]|\\|/)+")
KEYWORDS = ("and", "or", "not")
Match = Callable[[str], bool]  # is this word (lower case) part of one of the names?


class ExpressionError(ValueError):
    """A ``-k`` expression that does not parse: where and what was expected."""

    def __init__(self, text: str, column: int, message: str) -> None:
        super().__init__(f"{text!r}: at column {column}: {message}")


@dataclass(frozen=True)
class Token:
    kind: str  # "(", ")", "and", "or", "not", "word", "end"
    text: str
    column: int  # 1-based


def tokens(text: str) -> list[Token]:
    out: list[Token] = []
    i = 0
    while i < len(text):
        if text[i].isspace():
            i += 1
        elif text[i] in "()":
            out.append(Token(text[i], text[i], i + 1))
            i += 1
        elif m := WORD.match(text, i):
            word = m.group()
            out.append(Token(word if word in KEYWORDS else "word", word, i + 1))
            i = m.end()
        else:
            raise ExpressionError(text, i + 1, f"unexpected character {text[i]!r}")
    out.append(Token("end", "", len(text) + 1))
    return out


def expression(text: str) -> str:
    """An argparse type: ``text`` when it parses as an expression (argparse's own refusal, exit status 2, when it
    does not)."""
    import argparse

    try:
        Expression(text)
    except ExpressionError as exc:
        raise argparse.ArgumentTypeError(f"{exc}; see 'liansuo test --help'") from None
    return text


class Expression:
    """A compiled ``-k`` expression: :meth:`matches` the names of one test."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._tokens = tokens(text)
        self._at = 0
        if self._peek().kind == "end":
            self._root: Callable[[Match], bool] = lambda match: True
            return
        self._root = self._or()
        if self._peek().kind != "end":
            self._fail("end of input")

    def matches(self, names: Iterable[str]) -> bool:
        low = [n.lower() for n in names]
        return self._root(lambda word: any(word in n for n in low))

    def _peek(self) -> Token:
        return self._tokens[self._at]

    def _take(self, kind: str) -> Token | None:
        tok = self._peek()
        if tok.kind != kind:
            return None
        self._at += 1
        return tok

    def _fail(self, expected: str) -> NoReturn:
        tok = self._peek()
        got = "end of input" if tok.kind == "end" else repr(tok.text)
        raise ExpressionError(self.text, tok.column, f"expected {expected}; got {got}")

    def _or(self) -> Callable[[Match], bool]:
        parts = [self._and()]
        while self._take("or"):
            parts.append(self._and())
        return parts[0] if len(parts) == 1 else lambda match: any(p(match) for p in parts)

    def _and(self) -> Callable[[Match], bool]:
        parts = [self._not()]
        while self._take("and"):
            parts.append(self._not())
        return parts[0] if len(parts) == 1 else lambda match: all(p(match) for p in parts)

    def _not(self) -> Callable[[Match], bool]:
        if self._take("not"):
            inner = self._not()
            return lambda match: not inner(match)
        if self._take("("):
            inner = self._or()
            if not self._take(")"):
                self._fail("')'")
            return inner
        words = []
        while tok := self._take("word"):
            words.append(tok.text)
        if not words:
            self._fail("a word, 'not' or '('")
        phrase = " ".join(words).lower()
        return lambda match: match(phrase)
