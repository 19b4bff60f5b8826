"""Reading YAML while remembering where every value stood, for ``FILE:LINE:COLUMN`` messages."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from liansuo.kit.fit import fit
from liansuo.kit.printable import printable
from liansuo.kit.safeyaml import Loc, Mark, YamlProblem, build, compose, read_file

__all__ = ["Diagnostic", "Loc", "Mark", "Source", "StationError", "read_text", "read_yaml"]


@dataclass(frozen=True)
class Diagnostic:
    """One error or warning about a station file, printable as ``FILE:LINE:COLUMN: message``."""

    file: str
    line: int
    column: int
    message: str
    hint: str = ""
    severity: str = "error"

    def __str__(self) -> str:
        """One line, as compilers write it (``FILE:LINE:COLUMN: error: ...``), for stderr and the tools that read
        it; the hint on a line of its own."""
        text = f"{printable(self.file)}:{self.line}:{self.column}: {self.severity}: {printable(self.message)}"
        return text + (f"\n    hint: {printable(self.hint)}" if self.hint else "")

    def text(self, lead: str = "") -> str:
        """The diagnostic in a report on stdout (``liansuo check``): each line starting with ``lead``, folded to
        fit a terminal, the location and the message's start on the first line."""
        text = fit(f"{lead}{self.file}:{self.line}:{self.column}: {self.severity}: {self.message}", keep=3)
        if self.hint:
            text += "\n" + fit(f"{lead}    hint: {self.hint}")
        return text

    def as_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "line": self.line,
            "column": self.column,
            "severity": self.severity,
            "message": self.message,
            "hint": self.hint,
        }


class StationError(Exception):
    """A station file could not be loaded; ``diagnostics`` says where and why."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diagnostics = list(diagnostics)
        super().__init__("\n".join(str(d) for d in self.diagnostics))


@dataclass
class Source:
    """The plain data of a YAML document and the marks of its values and keys."""

    file: str
    data: Any
    marks: dict[Loc, Mark] = field(default_factory=dict)
    key_marks: dict[Loc, Mark] = field(default_factory=dict)

    def mark(self, loc: Loc) -> Mark:
        """The mark of the value at ``loc``, or of the nearest enclosing value that has one."""
        loc = tuple(loc)
        while loc:
            if loc in self.marks:
                return self.marks[loc]
            loc = loc[:-1]
        return self.marks.get((), Mark(1, 1))

    def key_mark(self, loc: Loc) -> Mark:
        return self.key_marks.get(tuple(loc)) or self.mark(loc)

    def diagnostic(self, loc: Loc, message: str, hint: str = "", *, severity: str = "error",
                   at_key: bool = False) -> Diagnostic:
        m = self.key_mark(loc) if at_key else self.mark(loc)
        return Diagnostic(self.file, m.line, m.column, message, hint, severity)


def _diagnostic(file: str, problem: YamlProblem) -> Diagnostic:
    return Diagnostic(file, problem.line, problem.column, problem.message, problem.hint)


def read_yaml(text: str, file: str) -> Source:
    """Parse ``text`` within the input limits (:mod:`liansuo.kit.safeyaml`); raise :class:`StationError` with the
    place of anything that cannot be read: a syntax error, a control character, an alias that repeats too much ..."""
    try:
        root = compose(text)
    except YamlProblem as exc:
        raise StationError([_diagnostic(file, exc)]) from None
    if root is None:
        raise StationError([Diagnostic(file, 1, 1, "the file is empty",
                                       "a station file starts with 'id:', 'name:' and 'tracks:'")])
    tree = build(root)
    if tree.problems:
        raise StationError([_diagnostic(file, p) for p in tree.problems])
    return Source(file, tree.data, tree.marks, tree.key_marks)


def read_text(path: Path, missing_hint: str = "give a bundled station name (see 'liansuo stations') or a path"
              ) -> str:
    """The file's text, read within the input limits; :class:`StationError` at ``FILE:LINE:COLUMN`` when it is
    missing, a folder, a device or a pipe, too large, unreadable or not UTF-8."""
    try:
        return read_file(path)
    except YamlProblem as exc:
        if exc.what:  # a path that names no file: say how to name one
            exc = YamlProblem(exc.line, exc.column, f"{exc.message}; {missing_hint}")
        raise StationError([_diagnostic(str(path), exc)]) from None
