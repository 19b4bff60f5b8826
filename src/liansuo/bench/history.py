"""The benchmark's history: each run asked for (``liansuo bench --history FILE``) is appended to FILE as one line of
JSON, its report with the time it ended and the commit it ran, so docs/benchmark.md keeps only the current figures
(the project's own history is docs/benchmark-history.jsonl)."""

from __future__ import annotations

import datetime
import json
import os
import subprocess
from pathlib import Path
from typing import Any

import liansuo


def commit() -> str | None:
    """The commit of the checkout liansuo runs from, with ``+`` when it has changes; None when installed."""
    root = Path(liansuo.__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+" if dirty else "")


def unfit(path: Path) -> str:
    """Why the run's report could not be appended to ``path`` (checked before the run, which may take minutes), or
    '': a folder that exists and may be written, and a file that is not there yet or holds a history already (each
    line a JSON object with its ``date``)."""
    folder = path.parent
    if path.is_dir():
        return f"cannot append to {path}: it is a folder; give --history a file name"
    if not folder.is_dir():
        return (f"cannot append to {path}: no folder {folder}; create it or give --history a file in a folder that "
                "exists")
    if not path.exists():
        return "" if os.access(folder, os.W_OK) else f"cannot create {path}: the folder {folder} is not writable"
    if not os.access(path, os.W_OK):
        return f"cannot append to {path}: the file is not writable"
    try:
        with path.open(encoding="utf-8") as f:
            first = f.readline()
        entry = json.loads(first) if first.strip() else {"date": ""}
    except (OSError, UnicodeDecodeError, ValueError):
        entry = None
    if not isinstance(entry, dict) or "date" not in entry:
        return (f"{path}:1:1: error: this is not a benchmark history (one JSON object a line, each with its date); "
                "give --history a new file or one liansuo bench wrote")
    return ""


def append(path: Path, report: dict[str, Any]) -> None:
    """Append ``report`` to the history at ``path`` as one line, with the time (UTC) and the commit."""
    entry = {"date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"), "commit": commit(), **report}
    with path.open("a", encoding="utf-8") as f:
        f.write(json.dumps(entry, ensure_ascii=False, separators=(",", ":")) + "\n")
