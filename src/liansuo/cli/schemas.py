"""``liansuo schema [KIND]``: the JSON Schema of each kind of file liansuo reads, generated from the pydantic model
its loader validates with, and shipped with the package as ``liansuo/schemas/KIND-N.json``.

Every schema has a stable ``$id``, ``https://liansuo.dev/schema/KIND-N.json``, N the version of that file format:
it goes up only when a file valid under the old schema no longer is (a key removed, a value narrowed); additions
keep N. ``tests/test_schemas.py`` checks that the shipped files are what the models generate, so they cannot drift;
after a model changes, ``liansuo schema KIND > schemas/KIND-N.json`` rewrites its file (docs/schemas.md).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from importlib import import_module
from importlib.resources import files
from pathlib import Path
from typing import Any

from pydantic import BaseModel

Add = Callable[..., argparse.ArgumentParser]

DRAFT = "https://json-schema.org/draft/2020-12/schema"
BASE = "https://liansuo.dev/schema/"
# kind -> (the module and class of the model its loader validates with, the version of its format, its title); the
# model is imported when a schema is asked for, so the command line does not load every model to start
KINDS: dict[str, tuple[str, int, str]] = {
    "station": ("liansuo.stations.schema:StationFile", 1, "liansuo station file"),
    "script": ("liansuo.proving.fileschemas:ScriptFile", 1, "liansuo test script"),
    "scenario": ("liansuo.proving.fileschemas:ScenarioFile", 1, "liansuo scenario"),
    "exercise": ("liansuo.classroom.schema:ExerciseFile", 1, "liansuo exercise"),
    "points": ("liansuo.fieldio.points:PointMapFile", 1, "liansuo field I/O point map"),
}


def model(kind: str) -> type[BaseModel]:
    """The pydantic model of ``kind``."""
    module, name = KINDS[kind][0].split(":")
    found: type[BaseModel] = getattr(import_module(module), name)
    return found


def file_name(kind: str) -> str:
    """``station-1.json``: the shipped file's name, the last part of its ``$id``."""
    return f"{kind}-{KINDS[kind][1]}.json"


def schema_id(kind: str) -> str:
    return BASE + file_name(kind)


def generate(kind: str) -> dict[str, Any]:
    """The JSON Schema of ``kind`` from its model, with ``$schema``, ``$id`` and ``title`` first."""
    title = KINDS[kind][2]
    schema = model(kind).model_json_schema(by_alias=True)
    schema.pop("title", None)
    return {"$schema": DRAFT, "$id": schema_id(kind), "title": title, **schema}


def schema_text(kind: str) -> str:
    """The schema as written to stdout and shipped: indented JSON, one newline at the end."""
    return json.dumps(generate(kind), ensure_ascii=False, indent=2) + "\n"


def shipped(kind: str) -> Path:
    """The schema's file in the installed package."""
    return Path(str(files("liansuo") / "schemas" / file_name(kind)))


def cmd_schema(args: argparse.Namespace) -> int:
    print(schema_text(args.kind), end="")
    return 0


def register(add: Add) -> None:
    sp = add("schema", cmd_schema, "print the JSON Schema of a kind of file (station by default), for editors")
    sp.add_argument("kind", nargs="?", choices=tuple(KINDS), default="station", metavar="KIND",
                    help=f"the kind of file: {', '.join(KINDS)} (default: station); the same schemas ship as "
                         "liansuo/schemas/KIND-N.json")
