"""Fuzzing station files (the fuzz kind ``stations``, docs/robustness.md): mutants of the example stations through
``liansuo check``, then ``liansuo table``, then ``liansuo verify`` on the small ones, as a user runs them.

:func:`strategy` draws a :class:`StationSample`: one of the example stations with one to three changes to its data
(a key dropped, a number made extreme, a type swapped, an id made unknown, too long or full of control characters, a
list item repeated, a part shared through a YAML alias) and sometimes one to its text (an alias bomb, deep nesting, a
control character, a tab, a merge key, a Python tag, a line lost or repeated, bytes that are not UTF-8, the file cut
short). :func:`attempt` writes it to a file and runs the three commands through their command-line handlers.

A refusal must be the documented one: exit status 3 with ``FILE:LINE:COLUMN: error: ...`` on stderr. Anything else
raises :class:`Defect`: another exit status, a command refusing a file that ``check`` accepted, or a raw control
character reaching the terminal. An exception from the product escapes as it is (a traceback is a defect too).
"""

from __future__ import annotations

import argparse
import copy
import io
import math
import re
import tempfile
from collections.abc import Callable
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

from liansuo.circuits.zpw import cli as zpw_cli
from liansuo.interlocking.table import cli as table_cli
from liansuo.kit.exitcodes import Exit
from liansuo.proving.verify import cli as verify_cli
from liansuo.stations import cli as stations_cli

NAME = "stations"
EXAMPLES = Path(str(files("liansuo"))) / "examples" / "stations"
# the small example stations (shuangxian for its overrides): a mutant is checked and tabled in a fraction of a second
SEEDS = ("minimal", "danxian", "doubleslip", "shuangxian")
VERIFY = frozenset({"minimal", "danxian"})  # verify runs in well under a second on these

Draw = Callable[[st.SearchStrategy[Any]], Any]
Place = tuple[str | int, ...]

EXTREME_NUMBERS = (math.nan, math.inf, -math.inf, -1, 0, 1e-300, 1e308, -1e308, 2**31, 2**63, 1e9, 100_000_000,
                   10**400, -10**400)  # 400 digits: no float holds them
ALIEN_VALUES: tuple[Any, ...] = (None, True, "text", 12, 1.5, [], {}, [1, 2], {"a": 1}, "K12+345.6")
TEXTS = ("", "X" * 65, "X" * 5000, "\x1b]0;pwned\x07\x1b[2J", "名" * 40, "NOSUCH", "X-NOSUCH", "a b", "X\n",
         "X-XI(NOSUCH)", "1/3/5", "-", "K1+2", f"K{10**400}+0", f"K1+{10**400}.5")
_RAW_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
_DIAGNOSTIC = re.compile(r"^(.+):(\d+):(\d+): error: .+")


class WrongAnswer(AssertionError):
    """The product answered a sample as it must not: the wrong exit status, a refusal without FILE:LINE:COLUMN,
    a file ``check`` accepts and another command refuses, or a raw control character on the terminal."""


@dataclass(frozen=True)
class StationSample:
    """A station file to feed to the commands: the example it was made from, what was changed, the bytes."""

    seed: str
    changes: tuple[str, ...]
    content: bytes


# ---- drawing a sample -------------------------------------------------------------------------------------------
@cache
def _seed(name: str) -> Any:
    return yaml.safe_load((EXAMPLES / f"{name}.yaml").read_text(encoding="utf-8"))


def _paths(data: Any, here: Place = ()) -> list[Place]:
    out = [here]
    if isinstance(data, dict):
        for k, v in data.items():
            out += _paths(v, (*here, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out += _paths(v, (*here, i))
    return out


def _get(data: Any, path: Place) -> Any:
    for p in path:
        data = data[p]
    return data


def _set(data: Any, path: Place, value: Any) -> None:
    _get(data, path[:-1])[path[-1]] = value


def _pick(draw: Draw, data: Any, keep: Callable[[Any], bool]) -> Place | None:
    found = [p for p in _paths(data) if p and keep(_get(data, p))]
    return draw(st.sampled_from(found)) if found else None


def _number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _drop(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, lambda v: True)
    if path is None:
        return "nothing to drop"
    del _get(data, path[:-1])[path[-1]]
    return f"dropped {path}"


def _extreme(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, _number)
    if path is None:
        return "no number"
    old = _get(data, path)
    near = (-old, old * 1000, old + 0.001, old + 1, old - 1, old * 1.5) if abs(old) < 1e300 else ()
    new = draw(st.sampled_from((*EXTREME_NUMBERS, *near)))
    _set(data, path, new)
    return f"{path} = {new!r}"


def _alien(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, lambda v: True)
    if path is None:
        return "nothing to replace"
    new = draw(st.sampled_from(ALIEN_VALUES))
    _set(data, path, copy.deepcopy(new))
    return f"{path} = {new!r}"


def _text(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, lambda v: isinstance(v, str))
    if path is None:
        return "no text"
    new = draw(st.sampled_from(TEXTS))
    _set(data, path, new)
    return f"{path} = {new[:20]!r}{'...' if len(new) > 20 else ''}"


def _reference(draw: Draw, data: Any) -> str:
    """A text value replaced by another one of the file: an id where another id belongs."""
    path = _pick(draw, data, lambda v: isinstance(v, str))
    values = sorted({v for p in _paths(data) if p and isinstance(v := _get(data, p), str) and len(v) < 40})
    if path is None or not values:
        return "no text"
    new = draw(st.sampled_from(values))
    _set(data, path, new)
    return f"{path} = {new!r}"


def _repeat(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, lambda v: isinstance(v, list) and bool(v))
    if path is None:
        return "no list"
    items = _get(data, path)
    items.append(copy.deepcopy(items[draw(st.integers(0, len(items) - 1))]))
    return f"an item of {path} repeated"


def _share(draw: Draw, data: Any) -> str:
    """Two places holding the same object: the dump writes an anchor and an alias."""
    src = _pick(draw, data, lambda v: isinstance(v, dict | list))
    dst = _pick(draw, data, lambda v: True)
    if src is None or dst is None or dst[:len(src)] == src or src[:len(dst)] == dst:
        return "nothing to share"
    _set(data, dst, _get(data, src))
    return f"{dst} = alias of {src}"


def _unknown_key(draw: Draw, data: Any) -> str:
    path = _pick(draw, data, lambda v: isinstance(v, dict))
    if path is None:
        return "no mapping"
    _get(data, path)["colour"] = "red"
    return f"unknown key in {path}"


# weighted towards the changes a schema cannot refuse at once, so that more mutants reach the table and verify
DATA_CHANGES = (*[_extreme] * 4, *[_reference] * 3, *[_share] * 2, _repeat, _text, _drop, _alien, _unknown_key)


def _bomb(depth: int) -> str:
    lines = ["lol0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"lol{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]" for i in range(1, depth + 1)]
    return "\n".join(lines) + "\n"


def _text_change(draw: Draw, text: str) -> tuple[str, bytes]:
    lines = text.split("\n")
    at = draw(st.integers(0, max(0, len(lines) - 2)))
    kind = draw(st.sampled_from(("bomb", "nest", "control", "tab", "merge", "tag", "lose", "repeat", "bytes", "cut")))
    if kind == "bomb":
        depth = draw(st.integers(2, 9))
        return f"alias bomb {depth} deep", (_bomb(depth) + text).encode()
    if kind == "nest":
        n = draw(st.sampled_from((10, 63, 65, 1000, 100_000)))
        return f"nested {n} deep", (text + f"deep: {'[' * n}{']' * n}\n").encode()
    if kind == "control":
        char = draw(st.sampled_from(("\x00", "\x1b", "\x07", "\x7f", "\x85", "\x9b", "\u2028", "\ufeff")))
        pos = draw(st.integers(0, len(text)))
        return f"U+{ord(char):04X} at {pos}", (text[:pos] + char + text[pos:]).encode()
    if kind == "tab":
        lines[at] = "\t" + lines[at].lstrip()
        return f"tab on line {at + 1}", "\n".join(lines).encode()
    if kind in ("merge", "tag"):
        extra = ("<<: {colour: red}" if kind == "merge" else "name: !!python/object/apply:os.system [ls]")
        return f"{kind} at the top", (extra + "\n" + text).encode()
    if kind == "lose":
        del lines[at]
        return f"line {at + 1} lost", "\n".join(lines).encode()
    if kind == "repeat":
        lines.insert(at, lines[at])
        return f"line {at + 1} repeated", "\n".join(lines).encode()
    raw = text.encode()
    pos = draw(st.integers(0, len(raw)))
    if kind == "bytes":
        return f"byte 0xff at {pos}", raw[:pos] + b"\xff" + raw[pos:]
    return f"cut at byte {pos}", raw[:pos]


@st.composite
def _sample(draw: Draw) -> StationSample:
    seed = draw(st.sampled_from(SEEDS))
    data = copy.deepcopy(_seed(seed))
    how_many = draw(st.sampled_from((1, 1, 1, 2, 3)))
    changes = [draw(st.sampled_from(DATA_CHANGES))(draw, data) for _ in range(how_many)]
    text = yaml.safe_dump(data, allow_unicode=True, sort_keys=False, width=120)
    content = text.encode()
    if draw(st.integers(0, 3)) == 0:  # one sample in four: a change to the text as well
        what, content = _text_change(draw, text)
        changes.append(what)
    return StationSample(seed, tuple(changes), content)


def strategy() -> st.SearchStrategy[StationSample]:
    """Mutants of the small example stations (:class:`StationSample`)."""
    return _sample()


# ---- feeding it to the commands ---------------------------------------------------------------------------------
@cache
def commands() -> argparse.ArgumentParser:
    """``check``, ``table`` and ``verify`` registered by their rooms as the command line registers them (cli/main.py;
    tests/test_fuzz_stations.py holds the two equal): the fuzzer stands below the command line."""
    parser = argparse.ArgumentParser(prog="liansuo")
    sub = parser.add_subparsers(dest="command")

    def add(name: str, handler: Callable[[argparse.Namespace], int], help_: str) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help_)
        sp.set_defaults(handler=handler)
        return sp

    stations_cli.register(add, more_warnings=(zpw_cli.check_warnings, table_cli.check_warnings),
                          more_errors=(table_cli.check_errors,))
    table_cli.register(add)
    verify_cli.register(add)
    return parser


@cache
def run(*argv: str) -> tuple[int, str, str]:
    """``liansuo ARGV``'s exit status, stdout and stderr."""
    args = commands().parse_args(argv)
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = int(args.handler(args))
    return code, out.getvalue(), err.getvalue()


def _screen(command: str, out: str, err: str) -> None:
    found = _RAW_CONTROL.search(out + err)
    if found is not None:
        raise WrongAnswer(f"'liansuo {command}' sent the control character {found.group()!r} to the terminal")


def _refusal(command: str, file: Path, code: int, err: str) -> None:
    first = err.splitlines()[0] if err else ""
    m = _DIAGNOSTIC.match(first)
    if code != Exit.BAD_INPUT or m is None or m.group(1) != str(file):
        raise WrongAnswer(f"'liansuo {command}' refused with exit status {code} and {first!r}, not exit status "
                          f"{int(Exit.BAD_INPUT)} and {file}:LINE:COLUMN: error: ...")


def attempt(sample: StationSample) -> str:
    """``check``, then ``table`` and (on the small stations) ``verify`` when check accepted the file: "accepted"
    or "refused"; :class:`Defect` when the answer is not one a user may get."""
    with tempfile.TemporaryDirectory(prefix="liansuo-fuzz-") as tmp:
        file = Path(tmp) / f"{sample.seed}.yaml"
        file.write_bytes(sample.content)
        code, out, err = run("check", str(file))
        _screen("check", out, err)
        if code != Exit.OK:
            _refusal("check", file, code, err)
            return "refused"
        later = [("table",), ("verify",)] if sample.seed in VERIFY else [("table",)]
        for command in later:
            code, out, err = run(*command, str(file))
            _screen(command[0], out, err)
            if code not in (Exit.OK, Exit.FAILED):  # verify's failed checks are an answer about the station
                raise WrongAnswer(f"'liansuo check' accepted the file, 'liansuo {command[0]}' exits {code}: "
                                  f"{err.splitlines()[:1]}")
        return "accepted"
