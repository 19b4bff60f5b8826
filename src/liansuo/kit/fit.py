"""Text for a terminal: every line of the commands' text output fits ``WIDTH`` columns.

A long line is folded at spaces and its continuation lines are indented, so a reader sees where an item goes on; a
word longer than the width (a long file path) is never cut. Chinese characters count as two columns, as a terminal
shows them. Control characters are written out (:func:`.printable.printable`): a line may quote a file, and the
terminal must only receive what liansuo means to draw.
"""

from __future__ import annotations

from rich.cells import cell_len

from liansuo.kit.printable import printable_block

WIDTH = 100


def columns(text: str) -> int:
    """How many terminal columns ``text`` takes, as a terminal draws it (rich's cell widths: wide and full-width
    characters take two, combining marks none)."""
    return cell_len(text)


def fit(line: str, indent: str = "    ", width: int = WIDTH, keep: int = 1) -> str:
    """``line`` folded to ``width`` columns, continuation lines starting with ``indent`` after the line's own
    leading spaces; its first ``keep`` words stay on its first line (a diagnostic's 'FILE:LINE:COL: error: what')."""
    line = printable_block(line)
    if columns(line) <= width:
        return line
    lead = line[:len(line) - len(line.lstrip(" "))]
    out: list[str] = []
    current = lead
    for n, word in enumerate(line[len(lead):].split(" ")):  # runs of spaces (aligned columns): empty words
        candidate = f"{current} {word}" if current.strip() else current + word
        if current.strip() and word and n >= keep and columns(candidate) > width:
            out.append(current.rstrip())
            current = lead + indent + word
        else:
            current = candidate
    out.append(current.rstrip())
    return "\n".join(out)


def fit_all(lines: list[str], indent: str = "    ", width: int = WIDTH) -> str:
    """Every line folded (:func:`fit`; an item of several lines line by line), joined with newlines."""
    return "\n".join(fit(one, indent, width) for line in lines for one in line.split("\n"))


__all__ = ["WIDTH", "columns", "fit", "fit_all", "metres", "number", "plural"]


def number(x: float) -> str:
    """A quantity as every text output writes it: to two decimals, no trailing zeros, never '-0' ('11.2', '8.45',
    '140')."""
    text = f"{round(x, 2) + 0.0:.2f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def metres(x: float) -> str:
    """A length: :func:`number` and its unit ('8.45 m')."""
    return f"{number(x)} m"


def plural(n: int, word: str, many: str = "") -> str:
    """'1 pair', '2 pairs' (``many`` where the plural is not ``word`` + 's')."""
    return f"{n} {word if n == 1 else many or word + 's'}"
