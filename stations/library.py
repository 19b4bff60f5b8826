"""The bundled station library (``stations/library/*.yaml``), addressable by name or by path."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

import yaml

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


def describe(path: Path) -> str:
    """The one-line description of a bundled station, read without validating the whole file."""
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError):
        return "(unreadable)"
    if not isinstance(data, dict):
        return ""
    name = data.get("name") or {}
    desc = str(data.get("description", "")).strip().splitlines()
    first = desc[0] if desc else ""
    if isinstance(name, dict):
        return f"{name.get('zh', '')} {name.get('en', '')}: {first}".strip()
    return first
