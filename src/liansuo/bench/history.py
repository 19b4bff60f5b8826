"""The benchmark's history: each run asked for (``liansuo bench --history FILE``) is appended to FILE as one line of
JSON, its report with the time it ended and the commit it ran, so docs/benchmark.md keeps only the current figures
(the project's own history is docs/benchmark-history.jsonl)."""

from __future__ import annotations

import datetime
import json
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


def append(path: Path, report: dict[str, Any]) -> None:
    """Append ``report`` to the history at ``path`` as one line, with the time (UTC) and the commit."""
    entry = {"date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"), "commit": commit(), **report}
    with path.open("a", encoding="utf-8") as f:
        f.write(json.dumps(entry, ensure_ascii=False, separators=(",", ":")) + "\n")
