"""Equipment figures from ``equipment.yaml``."""

from __future__ import annotations

from functools import cache
from importlib.resources import files

import yaml
from pydantic import BaseModel, ConfigDict


class MachineSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    throw_s: float
    rated_force_N: float
    nominal_resistance_N: float


class DoorSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    open_s: float
    close_s: float


class ShuntSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    standard_25hz_ohm: float
    standard_zpw_ohm: float
    wheel_ohm: float
    poor_shunt_ohm: float


class Equipment(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    machines: dict[str, MachineSpec]
    obstruction_lock_mm: float
    doors: DoorSpec
    shunt: ShuntSpec


@cache
def equipment() -> Equipment:
    return Equipment.model_validate(yaml.safe_load((files("liansuo.circuits") / "equipment.yaml").read_text("utf-8")))
