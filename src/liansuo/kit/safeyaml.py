"""The one way liansuo reads a YAML file: bounded, with the line and column of every value, in plain words.

Every file kind (stations, test scripts, scenarios, exercises, rule files, a recording's kind check) goes through
:func:`read_file`, :func:`compose` and :func:`build`, within :data:`.inputlimits.LIMITS`:

- :func:`read_file` reads only a regular file, and at most ``max_file_bytes`` of it (``/dev/zero`` or a FIFO is
  refused at once, never read), as UTF-8;
- :func:`compose` refuses control characters, more than one document, tags other than plain values (``!!python/...``,
  merge keys ``<<``), nesting deeper than ``max_depth``, values longer than ``max_value_chars`` and aliases that
  would repeat more than ``max_alias_values`` values (a 700-byte alias bomb expands to 10^9), each at the place in
  the file where it stands. It composes the document itself from the C parser's events, never recursing, so it also
  never meets the C composer's crash on deep nesting;
- :func:`build` turns the composed document into plain data and remembers where each value and key stands.

Every problem is a :class:`YamlProblem` with a 1-based line and column and a message without PyYAML's
``in "<unicode string>"`` tail. This is the bottom layer: ``kit/source.py`` and ``rules/reader.py`` both use it.
"""

from __future__ import annotations

import gc
import os
import re
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import yaml
from yaml.events import (
    AliasEvent,
    DocumentStartEvent,
    MappingEndEvent,
    MappingStartEvent,
    ScalarEvent,
    SequenceEndEvent,
    SequenceStartEvent,
)
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from liansuo.kit.inputlimits import LIMITS, InputLimits

try:  # the C parser is much faster where libyaml is present
    from yaml import CSafeLoader as _Loader
except ImportError:  # pragma: no cover - depends on how PyYAML was built
    from yaml import SafeLoader as _Loader  # type: ignore[assignment]

Loc = tuple[str | int, ...]

_CORE = "tag:yaml.org,2002:"
_SCALAR_TAGS = {f"{_CORE}{t}": what for t, what in (("str", "text"), ("int", "whole number"), ("float", "number"),
                                                      ("bool", "true or false"), ("null", "null"),
                                                      ("timestamp", "date"))}
_SEQ, _MAP = f"{_CORE}seq", f"{_CORE}map"
# control characters (tab, line feed and carriage return are YAML's own), lone surrogates, and the line and paragraph
# separators YAML counts as line breaks where an editor shows none
_CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\u2028\u2029\ufffe\uffff]")
_CONTROL_NAMES = {0x00: "NUL", 0x07: "BEL", 0x08: "BS", 0x1b: "ESC", 0x7f: "DEL", 0x85: "NEL", 0x9b: "CSI"}


@dataclass(frozen=True)
class Mark:
    """A 1-based line and column in a source file."""

    line: int
    column: int


class YamlProblem(Exception):
    """Why a file cannot be read, and where: ``what`` is ``missing`` or ``folder`` for a path that names no file
    (the caller adds how to name one), empty otherwise."""

    def __init__(self, line: int, column: int, message: str, hint: str = "", what: str = "") -> None:
        self.line, self.column, self.message, self.hint, self.what = line, column, message, hint, what
        super().__init__(f"{line}:{column}: {message}")


def _at(mark: Any, message: str, hint: str = "") -> YamlProblem:
    return YamlProblem(mark.line + 1, mark.column + 1, message, hint)


# ---- the file ---------------------------------------------------------------------------------------------------
def read_file(path: Path, limits: InputLimits = LIMITS) -> str:
    """The text of the regular file at ``path``; :class:`YamlProblem` when there is none, it is a device, a pipe or
    a folder, larger than ``limits.max_file_bytes``, unreadable or not UTF-8. A FIFO is never waited on."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except (FileNotFoundError, NotADirectoryError):
        raise YamlProblem(1, 1, "no such file", what="missing") from None
    except IsADirectoryError:
        raise YamlProblem(1, 1, "this is a folder, not a file", what="folder") from None
    except OSError as exc:
        raise YamlProblem(1, 1, f"cannot read the file: {exc.strerror or exc}",
                          "check the file's permissions") from None
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise YamlProblem(1, 1, "this is a folder, not a file", what="folder")
        if not stat.S_ISREG(mode):
            raise YamlProblem(1, 1, "not a regular file (a device, a pipe or a socket): liansuo reads its files "
                              "whole, so give a file saved on disk")
        data = _read(fd, limits.max_file_bytes + 1)
    except OSError as exc:
        raise YamlProblem(1, 1, f"cannot read the file: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if len(data) > limits.max_file_bytes:
        raise YamlProblem(1, 1, f"the file is too large: liansuo reads files of at most "
                          f"{limits.max_file_bytes // (1024 * 1024)} MB", "is this the file you meant?")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = len(data[data.rfind(b"\n", 0, exc.start) + 1:exc.start].decode("utf-8", "replace")) + 1
        raise YamlProblem(line, column, f"not UTF-8 text (byte 0x{data[exc.start]:02x})",
                          "liansuo's files are UTF-8 text; save the file as UTF-8") from None


def _read(fd: int, most: int) -> bytes:
    """Up to ``most`` bytes of the open file ``fd``, from its start."""
    parts: list[bytes] = []
    left = most
    while left > 0:
        part = os.read(fd, min(left, 1 << 20))
        if not part:
            break
        parts.append(part)
        left -= len(part)
    return b"".join(parts)


# ---- the document -----------------------------------------------------------------------------------------------
def check_text(text: str, limits: InputLimits = LIMITS) -> None:
    """:class:`YamlProblem` for text too large or holding a control character, at the character's place."""
    if len(text) > limits.max_file_bytes:
        raise YamlProblem(1, 1, f"the text is too large: liansuo reads files of at most "
                          f"{limits.max_file_bytes // (1024 * 1024)} MB")
    found = _CONTROL.search(text)
    if found is not None:
        pos = found.start()
        code = ord(found.group())
        name = _CONTROL_NAMES.get(code)
        line = text.count("\n", 0, pos) + 1
        column = pos - (text.rfind("\n", 0, pos) + 1) + 1
        raise YamlProblem(line, column, f"the control character U+{code:04X}{f' ({name})' if name else ''} is not "
                          "allowed in a liansuo file", "remove it: the files hold plain text")


def _short(tag: str) -> str:
    return "!!" + tag[len(_CORE):] if tag.startswith(_CORE) else tag


def _tag_problem(mark: Any, tag: str, on: str) -> YamlProblem:
    if tag == f"{_CORE}merge":
        return _at(mark, "YAML merge keys ('<<') are not supported", "write the keys out in this mapping")
    return _at(mark, f"the tag '{_short(tag)}' is not allowed on {on}: liansuo files hold plain values (text, "
               "numbers, true or false, lists and mappings)", "remove the tag")


def _resolve(value: str, implicit: tuple[bool, bool]) -> str:
    """The tag of a plain or quoted value (``12`` an int, ``true`` a bool ...); short values, which repeat (ids,
    kinds, numbers), from a cache."""
    return _resolve_short(value, implicit) if len(value) <= 32 else _resolve_any(value, implicit)


@lru_cache(maxsize=1 << 14)
def _resolve_short(value: str, implicit: tuple[bool, bool]) -> str:
    return _resolve_any(value, implicit)


def _resolve_any(value: str, implicit: tuple[bool, bool]) -> str:
    return str(_RESOLVER.resolve(ScalarNode, value, implicit))  # type: ignore[no-untyped-call]


_RESOLVER = yaml.resolver.Resolver()


@dataclass
class _Open:
    """A list or mapping being composed: its node, the key waiting for its value, its size (values once aliases are
    expanded) and its anchor."""

    node: SequenceNode | MappingNode
    anchor: str | None
    key: Node | None = None
    size: int = 1


def compose(text: str, limits: InputLimits = LIMITS) -> Node | None:
    """The one document of ``text`` as YAML nodes (``None`` when it holds none), within ``limits``;
    :class:`YamlProblem` at the place of the first thing wrong."""
    check_text(text, limits)
    try:
        with _no_collection():
            return _compose(text, limits)
    except yaml.MarkedYAMLError as exc:
        if exc.problem == _LIBYAML_TOO_DEEP:
            raise _too_deep(text, limits, exc) from None
        raise _syntax(exc, text) from None
    except yaml.reader.ReaderError as exc:
        raise YamlProblem(text.count("\n", 0, exc.position) + 1, 1, f"cannot read the file: {exc.reason}") from None
    except yaml.YAMLError:
        raise YamlProblem(1, 1, "cannot read the file as YAML", "is this a YAML file?") from None


def _too_deep(text: str, limits: InputLimits, exc: yaml.MarkedYAMLError) -> YamlProblem:
    """Nesting deeper than libyaml's own limit (about 1,000 flow levels, PyYAML 6.0.4 on) is refused by its scanner
    before our limit speaks in the events: the scanner looks far ahead inside flow collections. The text cut just past
    the bracket that opens one flow level more than our limit is read again, so our limit speaks at its own place; if
    that finds nothing (the brackets were not where a rough look saw them), the limit is named at libyaml's place."""
    depth = _depth_message(limits)
    cut = _past_flow_depth(text, limits.max_depth + 1)
    if cut is not None:
        try:
            with _no_collection():
                _compose(text[:cut], limits)
        except YamlProblem as problem:
            if problem.message == depth:
                return problem
        except yaml.YAMLError:
            pass
    mark = exc.problem_mark or exc.context_mark
    line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
    return YamlProblem(line, col, depth, _DEPTH_HINT)


def _past_flow_depth(text: str, depth: int) -> int | None:
    """Just past the '[' or '{' that opens the ``depth``-th nested flow collection, passing over quoted values and
    comments (roughly: a quote inside a plain value is taken for a quoted value); None when there is none."""
    level, i, n = 0, 0, len(text)
    while i < n:
        c = text[i]
        if c in "[{":
            level += 1
            if level >= depth:
                return i + 1
        elif c in "]}":
            level = max(0, level - 1)
        elif c == "#" and (i == 0 or text[i - 1] in " \t\n"):
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        elif c in "'\"":
            i += 1
            while i < n and text[i] != c:
                i += 2 if c == '"' and text[i] == "\\" else 1
        i += 1
    return None


def _depth_message(limits: InputLimits) -> str:
    return f"lists and mappings nested more than {limits.max_depth} deep"


_LIBYAML_TOO_DEEP = "exceeded maximum nesting depth"  # the problem libyaml's scanner names past its own limit
_DEPTH_HINT = "a liansuo file nests a few levels; check the indentation above"


@contextmanager
def _no_collection() -> Iterator[None]:
    """The cycle collector paused while a document is read: its values hold no cycles, and collecting while hundreds
    of thousands of them are made takes three times as long as making them."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _compose(text: str, limits: InputLimits) -> Node | None:
    root: Node | None = None
    stack: list[_Open] = []
    anchors: dict[str, tuple[Node, int]] = {}
    repeated = 0  # values produced by aliases so far
    documents = 0
    for ev in yaml.parse(text, Loader=_Loader):
        node: Node
        if isinstance(ev, ScalarEvent):
            if len(ev.value) > limits.max_value_chars:
                raise _at(ev.start_mark, f"a value of {len(ev.value):,} characters: liansuo takes at most "
                          f"{limits.max_value_chars:,}", "shorten it")
            tag = _resolve(ev.value, ev.implicit) if ev.tag in (None, "!") else ev.tag
            if tag not in _SCALAR_TAGS:
                raise _tag_problem(ev.start_mark, tag, "a value")
            start: Any = ev.start_mark  # the C parser's marks, which the nodes keep as PyYAML's own
            node, size = ScalarNode(tag, ev.value, start, ev.end_mark, ev.style), 1  # type: ignore[arg-type]
            _anchor(anchors, ev, node, size)
        elif isinstance(ev, AliasEvent):
            if any(o.anchor == ev.anchor for o in stack):
                raise _at(ev.start_mark, f"the alias '*{ev.anchor}' stands inside the part its anchor "
                          f"'&{ev.anchor}' marks, so it would repeat itself without end", "remove the alias")
            if ev.anchor not in anchors:
                raise _at(ev.start_mark, f"the alias '*{ev.anchor}' names no anchor '&{ev.anchor}' above it",
                          "mark the part to repeat with '&NAME' before '*NAME' repeats it")
            node, size = anchors[str(ev.anchor)]
            repeated += size
            if repeated > limits.max_alias_values:
                raise _at(ev.start_mark, f"the alias '*{ev.anchor}' repeats {size:,} values, and the file's aliases "
                          f"so far {repeated:,}: liansuo expands at most {limits.max_alias_values:,}",
                          "write the repeated parts out, or repeat less")
        elif isinstance(ev, SequenceStartEvent | MappingStartEvent):
            if len(stack) >= limits.max_depth:
                raise _at(ev.start_mark, _depth_message(limits), _DEPTH_HINT)
            seq = isinstance(ev, SequenceStartEvent)
            tag = (_SEQ if seq else _MAP) if ev.tag in (None, "!") else ev.tag
            if tag != (_SEQ if seq else _MAP):
                raise _tag_problem(ev.start_mark, tag, "a list" if seq else "a mapping")
            cls = SequenceNode if seq else MappingNode
            begin: Any = ev.start_mark
            stack.append(_Open(cls(tag, [], begin, None, ev.flow_style), ev.anchor))
            continue
        elif isinstance(ev, SequenceEndEvent | MappingEndEvent):
            done = stack.pop()
            node, size = done.node, done.size
            node.end_mark = ev.end_mark
            _anchor(anchors, done, node, size)
        elif isinstance(ev, DocumentStartEvent):
            documents += 1
            if documents > 1:
                raise _at(ev.start_mark, "a second YAML document ('---'): a liansuo file holds one",
                          "remove the second '---' and what follows it, or put it in a file of its own")
            continue
        else:
            continue
        if not stack:
            root = node
            continue
        parent = stack[-1]
        parent.size += size
        if isinstance(parent.node, SequenceNode):
            parent.node.value.append(node)
        elif parent.key is None:
            parent.key = node
        else:
            parent.node.value.append((parent.key, node))
            parent.key = None
    return root


def _anchor(anchors: dict[str, tuple[Node, int]], ev: Any, node: Node, size: int) -> None:
    name = ev.anchor
    if name is None:
        return
    if name in anchors:
        first = anchors[name][0].start_mark
        raise _at(node.start_mark, f"the anchor '&{name}' is defined twice (first at line {first.line + 1})",
                  "give each anchor its own name")
    anchors[name] = (node, size)


def _syntax(exc: yaml.MarkedYAMLError, text: str) -> YamlProblem:
    """A parser's error in plain words at its place: the problem, and where the construct it is in began."""
    mark = exc.problem_mark or exc.context_mark
    line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
    problem = exc.problem or exc.context or "invalid YAML"
    cm = exc.context_mark
    if exc.problem and exc.context and cm is not None and mark is not None and cm.line != mark.line:
        problem += f" ({exc.context} at line {cm.line + 1}, column {cm.column + 1})"
    lines = text.split("\n")
    bad_line = lines[mark.line] if mark is not None and mark.line < len(lines) else ""
    if mark is not None and bad_line[mark.column:mark.column + 1] == "\t":
        problem += " (a tab: indent YAML with spaces)"
    return YamlProblem(line, col, f"YAML syntax error: {problem}",
                       "check indentation, colons and quotes around this line")


# ---- plain data -------------------------------------------------------------------------------------------------
@dataclass
class Tree:
    """A document as plain data, the mark of every value (by its place, a tuple of keys and indexes) and of every
    key, and what could not be read."""

    data: Any = None
    marks: dict[Loc, Mark] = field(default_factory=dict)
    key_marks: dict[Loc, Mark] = field(default_factory=dict)
    problems: list[YamlProblem] = field(default_factory=list)


_CONSTRUCTOR = yaml.constructor.SafeConstructor()


def build(root: Node, *, keys_as_written: bool = False) -> Tree:
    """``root`` as plain data. Keys are names: with ``keys_as_written`` the text of the key as written (a lamp named
    ``Y`` stays ``Y``), otherwise its value as text (``1`` -> ``'1'``, ``true`` -> ``'true'``, as JSON writes them).
    A key twice in one mapping, a key that is a list or a mapping and a value its tag cannot read are problems."""
    tree = Tree()
    with _no_collection():
        tree.data = _value(root, (), tree, keys_as_written)
    return tree


def _mark(node: Node) -> Mark:
    return Mark(node.start_mark.line + 1, node.start_mark.column + 1)


def _value(node: Node, loc: Loc, tree: Tree, as_written: bool) -> Any:
    tree.marks[loc] = _mark(node)
    if isinstance(node, MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            key = _key(key_node, tree, as_written)
            if key is None:
                continue
            if key in out:
                tree.problems.append(YamlProblem(*_pair(key_node), f"key '{key}' appears twice in the same mapping",
                                                 "remove or rename one of them"))
                continue
            tree.key_marks[(*loc, key)] = _mark(key_node)
            out[key] = _value(value_node, (*loc, key), tree, as_written)
        return out
    if isinstance(node, SequenceNode):
        return [_value(item, (*loc, i), tree, as_written) for i, item in enumerate(node.value)]
    return _scalar(node, tree)


def _pair(node: Node) -> tuple[int, int]:
    return node.start_mark.line + 1, node.start_mark.column + 1


def _key(node: Node, tree: Tree, as_written: bool) -> str | None:
    if not isinstance(node, ScalarNode):
        kind = "list" if isinstance(node, SequenceNode) else "dict"
        tree.problems.append(YamlProblem(*_pair(node), f"a key must be a name, not {kind}",
                                         "write keys as plain words such as 'id:'"))
        return None
    if as_written:
        return str(node.value)
    key = _scalar(node, tree)
    if isinstance(key, bool):  # as the JSON the schema sees ('true', '12'), so marks match its locs
        return str(key).lower()
    if isinstance(key, str | int):
        return str(key)
    tree.problems.append(YamlProblem(*_pair(node), f"a key must be a name, not {type(key).__name__}",
                                     "write keys as plain words such as 'id:'"))
    return None


def _scalar(node: Node, tree: Tree) -> Any:
    if node.tag == f"{_CORE}str":
        return node.value
    try:
        return _CONSTRUCTOR.yaml_constructors[node.tag](_CONSTRUCTOR, node)
    except (ValueError, KeyError, TypeError, OverflowError, yaml.YAMLError):
        shown = node.value if len(node.value) <= 40 else node.value[:37] + "..."
        tree.problems.append(YamlProblem(*_pair(node), f"'{shown}' is not a {_SCALAR_TAGS[node.tag]}",
                                         f"write a {_SCALAR_TAGS[node.tag]}, or quote the value to make it text"))
        return None
