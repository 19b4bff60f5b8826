"""The command language as a value: each command's name, usage line and handler, and how one line is run.

A :class:`Language` is built from explicit lists of commands (the Simulation's is the world's commands, the scripts'
``expect`` and the trains' commands: :data:`~simulation.sim.LANGUAGE`); nothing is added to it at import or later.
The console, scripts, scenarios and the API all send their lines through the same one (docs/architecture.md,
principle 4).

A language knows nothing of what it drives: it is generic in the thing its handlers are given (``W``). A command
written for a :class:`~simulation.world.World` serves any world built on it, such as the Simulation.
"""

from __future__ import annotations

import re
import shlex
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Generic, TypeVar

from liansuo.interlocking.io import Result
from liansuo.kit.source import Diagnostic, Source
from liansuo.simulation.unknown import UnknownId

W = TypeVar("W")
W_contra = TypeVar("W_contra", contravariant=True)
_PLAIN = re.compile(r"[^'\"\\]*")  # no quote and no backslash: shlex would only split at its whitespace
_GAPS = re.compile(r"[ \t\r\n]+")  # shlex's whitespace (not every Unicode space: an ideographic space is a word)


def split_words(text: str) -> list[str]:
    """The words of a command line as :func:`shlex.split` gives them (quotes group, a backslash escapes;
    ``ValueError`` for an unclosed quote). A line with no quote or backslash, nearly every line, is split without
    the tokenizer: verify sends hundreds of thousands."""
    if _PLAIN.fullmatch(text):
        return [w for w in _GAPS.split(text) if w]
    return shlex.split(text)


@dataclass(frozen=True)
class Command(Generic[W_contra]):
    """One command: a handler for any ``W_contra`` serves everything built on it."""

    name: str
    usage: str  # 'route START END [VIA ...]': what each argument is (the console completes from it)
    handler: Callable[[W_contra, list[str]], Result]


class Language(Generic[W]):
    """Commands by name; a name given twice is an error, not an override."""

    def __init__(self, *groups: Iterable[Command[W]]) -> None:
        self._commands: dict[str, Command[W]] = {}
        for group in groups:
            for c in group:
                if c.name in self._commands:
                    raise ValueError(f"the command '{c.name}' is defined twice")
                self._commands[c.name] = c

    def __contains__(self, name: object) -> bool:
        return name in self._commands

    def __iter__(self) -> Iterator[str]:
        return iter(self._commands)

    def usage(self, name: str) -> str:
        c = self._commands.get(name)
        return c.usage if c is not None else ""

    def execute(self, world: W, line: str) -> Result:
        """Run one line (a ``#`` starts a comment); an unknown command is refused with the list of commands, and a
        command naming an element the station does not have with the closest ids."""
        text = line.split("#", 1)[0].strip()
        if not text:
            return Result.accept("")
        try:
            words = split_words(text)
        except ValueError as exc:
            return Result.refuse(f"cannot read the command: {exc}")
        c = self._commands.get(words[0])
        if c is None:
            return Result.refuse(f"unknown command '{words[0]}'; commands: {', '.join(sorted(self._commands))}")
        try:
            return c.handler(world, words[1:])
        except UnknownId as exc:  # the command names an element the station does not have
            return Result.refuse(str(exc))

    def read_steps(self, src: Source, loc: tuple[str | int, ...], raw: object,
                   errors: list[Diagnostic]) -> list[tuple[str, int]]:
        """The commands of a YAML list at ``loc`` in a script, scenario or exercise, with their lines; a step that is
        not text or names no known command becomes a diagnostic at its position."""
        steps: list[tuple[str, int]] = []
        if not isinstance(raw, list):
            return steps
        for i, s in enumerate(raw):
            at = (*loc, i)
            if not isinstance(s, str):
                errors.append(src.diagnostic(at, "a step is one command as text", "quote it if it contains ':'"))
                continue
            word = s.split("#", 1)[0].split()[:1]
            if word and word[0] not in self._commands:
                errors.append(src.diagnostic(at, f"unknown command '{word[0]}'",
                                             f"commands: {', '.join(sorted(self._commands))}"))
            steps.append((s, src.mark(at).line))
        return steps
