"""Reading a rule file while remembering where each value stands, so that bad rule data is reported as
``FILE:LINE:COLUMN: error: message``, the way station files are: both are read by :mod:`~liansuo.kit.safeyaml`, within
the same limits."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from liansuo.kit.safeyaml import Loc, Mark, YamlProblem, build, compose, read_file

M = TypeVar("M", bound=BaseModel)
__all__ = ["Loc", "Problem", "RuleError", "RuleFile", "read", "validate"]


@dataclass(frozen=True)
class Problem:
    """One thing wrong in a rule file, printable as ``FILE:LINE:COLUMN: error: message``."""

    file: str
    line: int
    column: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: error: {self.message}"


class RuleError(Exception):
    """A rule set could not be loaded; ``problems`` says where and why."""

    def __init__(self, problems: Iterable[Problem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


@dataclass
class RuleFile:
    """The plain data of one rule file and the line and column of each value in it."""

    file: str
    data: Any = None
    marks: dict[Loc, Mark] = field(default_factory=dict)

    def problem(self, loc: Loc, message: str) -> Problem:
        """A problem at ``loc``, placed at the nearest enclosing value the file has."""
        loc = tuple(loc)
        while loc and loc not in self.marks:
            loc = loc[:-1]
        mark = self.marks.get(loc, Mark(1, 1))
        return Problem(self.file, mark.line, mark.column, message)


def read(path: Path) -> RuleFile:
    """Parse one rule file; raise :class:`RuleError` if it is missing or is not readable YAML."""
    rf = RuleFile(str(path))
    try:
        root = compose(read_file(path))
    except YamlProblem as exc:
        message = ("no such file: every rule set has this file ('liansuo docs rules')" if exc.what == "missing"
                   else exc.message)
        raise RuleError([Problem(rf.file, exc.line, exc.column, message)]) from None
    if root is None or root.tag != "tag:yaml.org,2002:map":
        raise RuleError([Problem(rf.file, 1, 1, "a rule file is a mapping of 'key: value' lines")])
    # keys as written: an aspect or lamp named Y or N stays a name, not a YAML 1.1 boolean
    tree = build(root, keys_as_written=True)
    if tree.problems:
        raise RuleError([Problem(rf.file, p.line, p.column, p.message) for p in tree.problems])
    rf.data, rf.marks = tree.data, tree.marks
    return rf


def _describe(err: Any) -> str:
    loc = err["loc"]
    where = ".".join(str(p) for p in loc)
    if err["type"] == "extra_forbidden":
        return f"unknown key '{loc[-1]}'"
    if err["type"] == "missing":
        return f"missing key '{where}'"
    value = err.get("input")
    shown = repr(value) if not isinstance(value, dict | list) else type(value).__name__
    msg = err["msg"]
    if err["type"] in ("finite_number", "float_type") and type(value) is int:  # past 1e308: no float holds it
        msg = "a number this large is out of every range (beyond 1e308)"
    return f"{where}: {msg} (got {shown[:40]})"


def validate(model: type[M], rf: RuleFile) -> M:
    """The file's data as ``model``; every schema error is reported at its line."""
    try:
        return model.model_validate(rf.data)
    except ValidationError as exc:
        raise RuleError([rf.problem(tuple(e["loc"]), _describe(e)) for e in exc.errors()]) from None
