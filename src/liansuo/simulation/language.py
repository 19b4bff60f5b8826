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
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Generic, TypeVar

from liansuo.interlocking.io import Result
from liansuo.kit.source import Diagnostic, Source
from liansuo.simulation.unknown import UnknownId
from liansuo.simulation.words import split as shell_split

W = TypeVar("W")
W_contra = TypeVar("W_contra", contravariant=True)
_PLAIN = re.compile(r"[^'\"\\]*")  # no quote and no backslash: shlex would only split at its whitespace
_GAPS = re.compile(r"[ \t\r\n]+")  # shlex's whitespace (not every Unicode space: an ideographic space is a word)


# The longest command line the language reads: a route with all its variant buttons or an expect line listing a
# station's relays is some hundreds of characters; a recording keeps each line whole (simulation/recording).
MAX_LINE_CHARS = 10_000


def split_words(text: str) -> list[str]:
    """The words of a command line as :func:`shlex.split` gives them (quotes group, a backslash escapes;
    ``ValueError`` for an unclosed quote), in time linear in its length (:mod:`.words`). A line with no quote or
    backslash, nearly every line, is split on its whitespace alone: verify sends hundreds of thousands."""
    if _PLAIN.fullmatch(text):
        return [w for w in _GAPS.split(text) if w]
    return shell_split(text)


def parse_line(line: str) -> list[str]:
    """The words of one command line as the language reads it, the command's name first: a ``#`` starts a comment,
    quotes group and a backslash escapes as in a POSIX shell; ``[]`` for an empty line. ``ValueError`` with the
    refusal's words for a line past :data:`MAX_LINE_CHARS` or one that cannot be split (an unclosed quote). Every
    reader of a command line's name (the role filter, the classroom's clock) uses this, so that none reads a word
    the language would read otherwise."""
    if len(line) > MAX_LINE_CHARS:
        raise ValueError(f"a command line has at most {MAX_LINE_CHARS:,} characters, and this one has more: send "
                         "it as several commands")
    text = line.split("#", 1)[0].strip()
    if not text:
        return []
    try:
        return split_words(text)
    except ValueError as exc:
        raise ValueError(f"cannot read the command: {exc}") from None


def command_name(line: str) -> str:
    """The command a line names as the language reads it; '' for an empty line, a comment, or a line the language
    refuses before reading a name (too long, an unclosed quote)."""
    try:
        found = parse_line(line)
    except ValueError:
        return ""
    return found[0] if found else ""


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
        try:
            words = parse_line(line)
        except ValueError as exc:
            return Result.refuse(str(exc))
        if not words:
            return Result.accept("")
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
            word = command_name(s)  # a step the language cannot read is refused when it runs, as a console line
            if word and word not in self._commands:
                errors.append(src.diagnostic(at, f"unknown command '{word}'",
                                             f"commands: {', '.join(sorted(self._commands))}"))
            steps.append((s, src.mark(at).line))
        return steps
