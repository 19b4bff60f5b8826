"""National rule sets. A rule set is data (``NAME.yaml``) plus the aspect functions in ``aspects.py``."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import yaml
from pydantic import BaseModel, ConfigDict

HERE = Path(__file__).parent


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


@cache
def load_rules(name: str = "china") -> RuleSet:
    return RuleSet.model_validate(yaml.safe_load((HERE / f"{name}.yaml").read_text(encoding="utf-8")))
