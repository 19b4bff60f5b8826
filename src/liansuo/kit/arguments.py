"""Checks of command-line values shared by the commands, made before any work starts (docs/commands.md)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def positive_int(text: str) -> int:
    """An argparse type: a whole number of at least 1 (``--turnouts``, ``--steps``)."""
    return _whole(text, 1, "is not a positive number")


def count(text: str) -> int:
    """An argparse type: a whole number, 0 or more (``--workers``, ``--runs``: 0 runs here, in no cluster)."""
    return _whole(text, 0, "is negative; give 0 (run here) or more")


def _whole(text: str, least: int, below: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"{value} {below}")
    return value


def positive_number(text: str) -> float:
    """An argparse type: a finite number greater than zero (``--speed``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text} is not greater than 0; give a positive number such as 1 or 0.5")
    return value


def unwritable(path: Path, option: str = "-o") -> str:
    """Why an output file cannot be written at ``path`` (a folder, or in no folder that exists), or ''."""
    if path.is_dir():
        return f"cannot write {path}: it is a folder; give {option} a file name"
    if not path.parent.is_dir():
        return (f"cannot write {path}: no folder {path.parent}; create it or give {option} a file in a folder that "
                "exists")
    return ""
