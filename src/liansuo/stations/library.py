"""The bundled station library (``stations/library/*.yaml``), addressable by name or by path."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from liansuo.kit.printable import printable
from liansuo.kit.safeyaml import YamlProblem, build, compose, read_file

LIBRARY = Path(str(files("liansuo.stations") / "library"))  # package data, installed with liansuo
DEFAULT_STATION = "jiaopei"


def bundled() -> dict[str, Path]:
    """Bundled station names and their files."""
    return {p.stem: p for p in sorted(LIBRARY.glob("*.yaml"))}


def resolve(name_or_path: str | Path) -> Path:
    """A bundled name becomes its file; anything else is taken as a path."""
    text = str(name_or_path)
    found = bundled().get(text)
    if found is not None:
        return found
    return Path(text)


def resolve_from(name_or_path: str, named_in: str | Path) -> Path:
    """The station that the file ``named_in`` (a script, a scenario, an exercise) names with ``station:``: a
    bundled name, or a path, a relative one taken from the folder of ``named_in`` (docs/commands.md), never from the
    current folder, so a file means the same station from wherever it is run."""
    found = bundled().get(name_or_path)
    if found is not None:
        return found
    return Path(named_in).parent / Path(name_or_path)  # an absolute path stays as it is


def describe(path: Path) -> str:
    """The one-line description of a bundled station, read without validating the whole file, control characters
    written out."""
    try:
        root = compose(read_file(path))
    except YamlProblem:
        return "(unreadable)"
    data = build(root).data if root is not None else None
    if not isinstance(data, dict):
        return ""
    name = data.get("name") or {}
    desc = str(data.get("description", "")).strip().splitlines()
    first = desc[0] if desc else ""
    if isinstance(name, dict):
        return printable(f"{name.get('zh', '')} {name.get('en', '')}: {first}".strip())
    return printable(first)
