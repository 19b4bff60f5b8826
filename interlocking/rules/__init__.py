"""National rule sets. A rule set is data (``NAME.yaml``) plus the aspect functions in ``aspects.py``."""

from __future__ import annotations

from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Literal

import yaml
from pydantic import BaseModel, ConfigDict

HERE = Path(str(files("liansuo.interlocking.rules")))  # package data, installed with liansuo


class ApproachLocking(BaseModel):
    """How far in rear of a signal its approach (接近区段) reaches."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    home: dict[str, int]  # line kind in rear (automatic, 64d, none) -> block sections
    other: int  # track sections in rear of every other signal


class RuleSet(BaseModel):
    """The numbers and tables of one national rule set."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str
    release_s: dict[str, float]
    section_fault_release_s: float
    overlap_release_s: float
    squeeze_alarm_s: float
    turnout_concurrency: int
    turnout_timeout_s: float
    lamp_mismatch_cycles: int
    block_pulse_s: float
    usu_min_turnout_number: int
    guide_close_s: float
    throw_time_s: dict[str, float]
    downgrade: dict[str, dict[str, str]]
    lamps: dict[str, list[str]]
    cab_codes: dict[str, str | None]
    semi_auto_departure: str
    approach_locking: ApproachLocking
    enemy_onto_track: list[tuple[Literal["train", "shunt"], Literal["train", "shunt"]]]


@cache
def load_rules(name: str = "china") -> RuleSet:
    return RuleSet.model_validate(yaml.safe_load((HERE / f"{name}.yaml").read_text(encoding="utf-8")))
