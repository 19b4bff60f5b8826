"""Reading a rule file while remembering where each value stands, so that bad rule data is reported as
``FILE:LINE:COLUMN: error: message``, the way station files are (``stations/source.py``; this layer is below
``stations`` and cannot borrow its reader)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

Loc = tuple[str | int, ...]
M = TypeVar("M", bound=BaseModel)

_scalars = yaml.SafeLoader(stream="")


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
    marks: dict[Loc, tuple[int, int]] = field(default_factory=dict)

    def problem(self, loc: Loc, message: str) -> Problem:
        """A problem at ``loc``, placed at the nearest enclosing value the file has."""
        loc = tuple(loc)
        while loc and loc not in self.marks:
            loc = loc[:-1]
        line, column = self.marks.get(loc, (1, 1))
        return Problem(self.file, line, column, message)


def _build(node: yaml.Node, loc: Loc, rf: RuleFile, problems: list[Problem]) -> Any:
    rf.marks[loc] = (node.start_mark.line + 1, node.start_mark.column + 1)
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            # keys as written: an aspect or lamp named Y or N stays a name, not a YAML 1.1 boolean
            key = str(key_node.value) if isinstance(key_node, yaml.ScalarNode) else None
            where = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
            if key is None or key in out:
                problems.append(Problem(rf.file, *where, "a key must be a plain name" if key is None
                                        else f"key '{key}' appears twice in the same mapping"))
                continue
            out[key] = _build(value_node, (*loc, key), rf, problems)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_build(item, (*loc, i), rf, problems) for i, item in enumerate(node.value)]
    return _scalars.construct_object(node, deep=True)


def read(path: Path) -> RuleFile:
    """Parse one rule file; raise :class:`RuleError` if it is missing or is not readable YAML."""
    rf = RuleFile(str(path))
    try:
        root = yaml.compose(path.read_text(encoding="utf-8"), Loader=yaml.SafeLoader)
    except FileNotFoundError:
        raise RuleError([Problem(rf.file, 1, 1, "no such file: every rule set has this file (see docs/rules.md)")]
                        ) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise RuleError([Problem(rf.file, 1, 1, f"cannot read the file: {exc}")]) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise RuleError([Problem(rf.file, line, col, f"YAML syntax error: {exc.problem or exc.context}")]) from None
    except yaml.YAMLError as exc:
        raise RuleError([Problem(rf.file, 1, 1, f"YAML error: {exc}")]) from None
    if not isinstance(root, yaml.MappingNode):
        raise RuleError([Problem(rf.file, 1, 1, "a rule file is a mapping of 'key: value' lines")])
    problems: list[Problem] = []
    rf.data = _build(root, (), rf, problems)
    if problems:
        raise RuleError(problems)
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
    return f"{where}: {err['msg']} (got {shown[:40]})"


def validate(model: type[M], rf: RuleFile) -> M:
    """The file's data as ``model``; every schema error is reported at its line."""
    try:
        return model.model_validate(rf.data)
    except ValidationError as exc:
        raise RuleError([rf.problem(tuple(e["loc"]), _describe(e)) for e in exc.errors()]) from None
