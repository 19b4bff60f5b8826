"""Where a command's report goes: stdout, or the file of ``-o FILE`` (docs/commands.md, "Output formats")."""

from __future__ import annotations

import sys
from pathlib import Path

from liansuo.kit.exitcodes import Exit, refuse


def deliver(command: str, text: str, output: str | None, also: list[str]) -> int:
    """Write ``text`` to ``output`` (stdout when None), then a ``wrote FILE`` line for it and for each file of
    ``also`` (files the command wrote besides); the exit status, with the reason when the file cannot be written."""
    wrote = list(also)
    if output is None:
        sys.stdout.write(text)
    else:
        try:
            Path(output).write_text(text, encoding="utf-8", newline="")
        except OSError as exc:
            return refuse(command, f"cannot write {output}: {exc.strerror or exc}; give -o a file in a folder you "
                          "can write to", Exit.USAGE)
        wrote.insert(0, output)
    for f in wrote:
        print(f"wrote {f}")
    return 0
