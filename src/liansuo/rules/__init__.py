"""National rule sets: every rule file of a country in one folder, chosen by one name.

``load_rules("china")`` reads the folder ``rules/china/`` (or any folder given by path) into one :class:`RuleSet`:

- ``interlocking.yaml``: the interlocking's timers, turnout drive, enemy-route classes and approach locking, read as
  the rule set's own fields (``rules.release_s``, ``rules.enemy_onto_track`` ...);
- ``aspects.yaml``: ``rules.aspects``, the aspects by role, their lamps and colours, downgrades and cab codes;
- ``driving.yaml``: ``rules.driving``; ``design.yaml``: ``rules.design``; ``equipment.yaml``: ``rules.equipment``.

It stands on the kit alone (the bounded YAML reader, :mod:`~liansuo.kit.safeyaml`), so every layer above may read
it (docs/rules.md). It holds rule data and its validation only, never rule code: the Chinese aspect selection lives
in ``interlocking/aspects.py``, and the safety oracle, which may read this package, shares none of that code."""

from __future__ import annotations

from functools import cache
from importlib.resources import files
from pathlib import Path

from pydantic import BaseModel

from liansuo.rules.aspects import DARK, Aspects
from liansuo.rules.parts import (
    ApproachLocking,
    DesignRules,
    DoorSpec,
    DrivingRules,
    Equipment,
    InterlockingRules,
    MachineSpec,
)
from liansuo.rules.reader import Problem, RuleError, RuleFile, read, validate

DEFAULT = "china"  # the rule set used where none is chosen
BUNDLED = Path(str(files("liansuo.rules")))  # package data, installed with liansuo
FILES = ("interlocking", "aspects", "driving", "design", "equipment")


class RuleSet(InterlockingRules):
    """One national rule set: the interlocking's part as its own fields, the other parts one attribute each."""

    name: str
    aspects: Aspects
    driving: DrivingRules
    design: DesignRules
    equipment: Equipment

    # the aspect tables under the names the interlocking has always read them by
    @property
    def lamps(self) -> dict[str, list[str]]:
        return self.aspects.lamps

    @property
    def downgrade(self) -> dict[str, dict[str, str]]:
        return self.aspects.downgrade

    @property
    def cab_codes(self) -> dict[str, str | None]:
        return self.aspects.cab_codes

    @property
    def semi_auto_departure(self) -> str:
        return self.aspects.semi_auto_departure


def bundled() -> list[str]:
    """The names of the rule sets shipped with liansuo."""
    return sorted(p.name for p in BUNDLED.iterdir() if (p / "interlocking.yaml").is_file())


def _folder(name: str) -> Path:
    if name in bundled():
        return BUNDLED / name
    path = Path(name)
    if path.is_dir():
        return path
    raise RuleError([Problem(str(name), 1, 1, f"no rule set '{name}': give one of {', '.join(bundled())} or the path "
                                              "of a folder holding " + ", ".join(f"{f}.yaml" for f in FILES))])


def _part(model: type[BaseModel], rf: RuleFile, problems: list[Problem]) -> BaseModel | None:
    try:
        part = validate(model, rf)
    except RuleError as exc:
        problems += exc.problems
        return None
    check = getattr(part, "problems", None)
    if callable(check):
        problems += [rf.problem(loc, text) for loc, text in check()]
    return part


def load_rules(name: str | Path = DEFAULT) -> RuleSet:
    """The rule set called ``name`` (a bundled one, see :func:`bundled`) or held in the folder ``name``, read once.

    Raises :class:`RuleError` naming file, line and what is wrong for every problem found in any of its files."""
    return _load(str(name))


@cache
def _load(name: str) -> RuleSet:
    folder = _folder(name)
    problems: list[Problem] = []
    files_read: dict[str, RuleFile] = {}
    for part in FILES:
        try:
            files_read[part] = read(folder / f"{part}.yaml")
        except RuleError as exc:
            problems += exc.problems
    if problems:
        raise RuleError(problems)
    models: dict[str, type[BaseModel]] = {"interlocking": InterlockingRules, "aspects": Aspects,
                                          "driving": DrivingRules, "design": DesignRules, "equipment": Equipment}
    parts = {key: _part(model, files_read[key], problems) for key, model in models.items()}
    aspects, driving = parts["aspects"], parts["driving"]
    if isinstance(aspects, Aspects) and isinstance(driving, DrivingRules):
        problems += [files_read["driving"].problem(("aspect_speed_kmh", a), f"'{a}' is no aspect of this rule set "
                                                   "(see aspects.yaml)")
                     for a in driving.aspect_speed_kmh if a not in aspects.lamps]
    if problems:
        raise RuleError(problems)
    interlocking = parts.pop("interlocking")
    return RuleSet.model_validate({**dict(interlocking or {}), "name": folder.name, **parts})


__all__ = ["BUNDLED", "DARK", "DEFAULT", "FILES", "ApproachLocking", "Aspects", "DesignRules", "DoorSpec",
           "DrivingRules", "Equipment", "InterlockingRules", "MachineSpec", "Problem", "RuleError", "RuleSet",
           "bundled", "load_rules"]
