"""Reading YAML while remembering where every value stood, for ``FILE:LINE:COLUMN`` messages."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from .fit import fit

try:  # the C loader is much faster where libyaml is present
    from yaml import CSafeLoader as _Loader
except ImportError:  # pragma: no cover - depends on how PyYAML was built
    from yaml import SafeLoader as _Loader  # type: ignore[assignment]

Loc = tuple[str | int, ...]


@dataclass(frozen=True)
class Mark:
    """A 1-based line and column in a source file."""

    line: int
    column: int


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
        text = f"{self.file}:{self.line}:{self.column}: {self.severity}: {self.message}"
        return text + (f"\n    hint: {self.hint}" if self.hint else "")

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


_scalar_constructor = yaml.SafeLoader(stream="")


def _build(node: yaml.Node, loc: Loc, src: Source, errors: list[Diagnostic]) -> Any:
    src.marks[loc] = Mark(node.start_mark.line + 1, node.start_mark.column + 1)
    if isinstance(node, yaml.MappingNode):
        result: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = _build(key_node, (*loc, "__key__"), src, errors)
            src.marks.pop((*loc, "__key__"), None)
            if not isinstance(key, str | int):
                errors.append(Diagnostic(src.file, key_node.start_mark.line + 1,
                                         key_node.start_mark.column + 1,
                                         f"a key must be a name, not {type(key).__name__}",
                                         "write keys as plain words such as 'id:'"))
                continue
            if isinstance(key, bool | int):  # as the JSON the schema sees ('true', '12'), so marks match its locs
                key = str(key).lower() if isinstance(key, bool) else str(key)
            if key in result:
                errors.append(Diagnostic(src.file, key_node.start_mark.line + 1,
                                         key_node.start_mark.column + 1,
                                         f"key '{key}' appears twice in the same mapping",
                                         "remove or rename one of them"))
                continue
            src.key_marks[(*loc, key)] = Mark(key_node.start_mark.line + 1, key_node.start_mark.column + 1)
            result[key] = _build(value_node, (*loc, key), src, errors)
        return result
    if isinstance(node, yaml.SequenceNode):
        return [_build(item, (*loc, i), src, errors) for i, item in enumerate(node.value)]
    return _scalar_constructor.construct_object(node, deep=True)


def read_yaml(text: str, file: str) -> Source:
    """Parse ``text``; raise :class:`StationError` with the position of any syntax error."""
    src = Source(file=file, data=None)
    try:
        root = yaml.compose(text, Loader=_Loader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        problem = exc.problem or exc.context or "invalid YAML"
        cm = exc.context_mark
        if exc.problem and exc.context and cm is not None and mark is not None and cm.line != mark.line:
            problem += f" ({exc.context} at line {cm.line + 1}, column {cm.column + 1})"
        bad_line = text.split("\n")[mark.line] if mark is not None and mark.line <= text.count("\n") else ""
        if mark is not None and bad_line[mark.column:mark.column + 1] == "\t":
            problem += " (a tab: indent YAML with spaces)"
        raise StationError([Diagnostic(file, line, col, f"YAML syntax error: {problem}",
                                       "check indentation, colons and quotes around this line")]) from None
    except yaml.YAMLError as exc:
        raise StationError([Diagnostic(file, 1, 1, f"YAML error: {exc}", "")]) from None
    except ValueError as exc:  # e.g. characters PyYAML refuses
        raise StationError([Diagnostic(file, 1, 1, f"cannot read the file as YAML: {exc}", "")]) from None
    if root is None:
        raise StationError([Diagnostic(file, 1, 1, "the file is empty",
                                       "a station file starts with 'id:', 'name:' and 'tracks:'")])
    errors: list[Diagnostic] = []
    try:
        src.data = _build(root, (), src, errors)
    except (yaml.YAMLError, ValueError, TypeError, RecursionError) as exc:
        raise StationError([Diagnostic(file, 1, 1, f"cannot read a value: {exc}", "")]) from None
    if errors:
        raise StationError(errors)
    return src


def read_text(path: Path, missing_hint: str = "give a bundled station name (see 'liansuo stations') or a path"
              ) -> str:
    """The file's text; :class:`StationError` at ``FILE:1:1`` when it is missing or unreadable."""
    try:
        return path.read_text(encoding="utf-8")
    except (FileNotFoundError, NotADirectoryError):
        raise StationError([Diagnostic(str(path), 1, 1, f"no such file; {missing_hint}")]) from None
    except IsADirectoryError:
        raise StationError([Diagnostic(str(path), 1, 1, f"this is a folder, not a file; {missing_hint}")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise StationError([Diagnostic(str(path), 1, 1, f"cannot read the file: {exc}",
                                       "liansuo's files are UTF-8 text")]) from None

