"""``liansuo docs [TOPIC]``: the documentation pages, readable wherever liansuo is installed.

The wheel carries the pages of ``docs/`` as ``liansuo/docs/*.md`` (setup.py copies them in at build time); a checkout
reads its own ``docs/``. Without a topic the command lists the pages; with one it prints the page, drawn by rich on a
terminal and as plain Markdown into a pipe or a file. The help of every command names its page as ``liansuo docs
TOPIC``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from liansuo.kit.exitcodes import Exit, refuse

Add = Callable[..., argparse.ArgumentParser]
HIDDEN = {"pypi"}  # the package index's description, not a guide


def folder() -> Path | None:
    """Where the pages are: in the installed package, else in the checkout this module lies in."""
    here = Path(__file__).resolve().parent.parent  # liansuo/
    for candidate in (here / "docs", here.parent.parent / "docs"):
        if candidate.is_dir() and any(candidate.glob("*.md")):
            return candidate
    return None


def pages() -> dict[str, Path]:
    where = folder()
    if where is None:
        return {}
    return {p.stem: p for p in sorted(where.glob("*.md")) if p.stem not in HIDDEN}


def title(path: Path) -> str:
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("# "):
            return line[2:].strip()
    return path.stem


def register(add: Add) -> None:
    sp = add("docs", cmd_docs, "read a documentation page (without a topic: the list of pages)")
    sp.add_argument("topic", nargs="?", help="a page, e.g. verify, station-format, classroom")


def cmd_docs(args: argparse.Namespace) -> int:
    found = pages()
    if not found:
        return refuse("docs", "the documentation pages are not installed with this copy of liansuo", Exit.USAGE)
    if not args.topic:
        width = max(len(n) for n in found)
        for name, page in found.items():
            print(f"{name:<{width}}  {title(page)}")
        return int(Exit.OK)
    topic = args.topic.removesuffix(".md").removeprefix("docs/")
    path = found.get(topic)
    if path is None:
        close = [n for n in found if topic.lower() in n]
        hint = f"; did you mean {', '.join(close)}?" if close else "; 'liansuo docs' lists the pages"
        return refuse("docs", f"no page '{args.topic}'{hint}", Exit.USAGE)
    text = path.read_text(encoding="utf-8")
    if sys.stdout.isatty():
        from rich.console import Console
        from rich.markdown import Markdown

        console = Console()
        with console.pager(styles=True):
            console.print(Markdown(text))
    else:
        sys.stdout.write(text)
    return int(Exit.OK)
