"""The optional parts of liansuo and the extra that installs each (pyproject.toml ``[project.optional-dependencies]``).

The core install loads, checks, tables, verifies and simulates stations. A command that needs more says which extra
to install, in one line with exit status 2, before it starts (:func:`needed`), instead of failing on an import.
"""

from __future__ import annotations

from importlib.util import find_spec

# extra -> the modules it installs that liansuo imports
EXTRAS: dict[str, tuple[str, ...]] = {
    "console": ("textual", "websockets"),
    "serve": ("textual", "textual_serve", "websockets"),
    "cluster": ("distributed",),
}
WHAT = {"console": "the operator console", "serve": "the classroom server", "cluster": "work on several processes"}


def missing(extra: str) -> list[str]:
    """The modules of ``extra`` that are not installed (or cannot be found: a broken install counts as absent)."""
    return [m for m in EXTRAS[extra] if not _found(m)]


def _found(module: str) -> bool:
    try:
        return find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def needed(extra: str) -> str | None:
    """Why the command cannot run without ``extra`` (None when it is installed)."""
    absent = missing(extra)
    if not absent:
        return None
    return (f"{WHAT[extra]} needs the {extra} extra: pip install 'liansuo[{extra}]' "
            f"({', '.join(absent)} not installed)")
