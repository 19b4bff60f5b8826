"""The parts of a rule set other than its aspects, one per rule file: what each layer reads.

- ``interlocking.yaml`` -> :class:`InterlockingRules` (timers, turnout drive, enemy-route classes, approach locking);
- ``driving.yaml`` -> :class:`DrivingRules` (the drivers' speeds and margins, read by the trains);
- ``design.yaml`` -> :class:`DesignRules` (the station-design limits, reported as warnings by the station loader);
- ``equipment.yaml`` -> :class:`Equipment` (switch machines, screen doors, the obstruction test, read by the field).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from liansuo.rules.reader import Loc

# Every number of a rule file has a range (docs/rules.md), as the station file's have (stations/limits.py, a layer
# above): what a railway has, widened to what a simulation can still wait for and compute.
Seconds = Annotated[float, Field(gt=0, le=600)]  # a timer: the rules' longest is 3 min; verify waits each out
Metres = Annotated[float, Field(gt=0, le=200_000)]  # within a station (stations/limits.py EXTENT)
Speed = Annotated[float, Field(gt=0, le=400)]  # km/h: the fastest Chinese lines run at 350
Gradient = Annotated[float, Field(ge=0, le=60)]  # per mille, as a station file's profile
Count = Annotated[int, Field(ge=1, le=10_000)]  # sections in rear, turnouts driven at once
TurnoutNumber = Annotated[int, Field(ge=1, le=62)]  # as a station file's turnout numbers (6 to 62)
Force = Annotated[float, Field(gt=0, le=100_000)]  # N: as the switching-resistance fault's range


class Part(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)  # every number finite


class ApproachLocking(Part):
    """How far in rear of a signal its approach (接近区段) reaches."""

    home: dict[str, Count]  # line kind in rear (automatic, 64d, none) -> block sections
    other: Count  # track sections in rear of every other signal


class InterlockingRules(Part):
    """The interlocking's numbers and tables."""

    release_s: dict[str, Seconds]  # manual time release, by route kind (train, shunt)
    section_fault_release_s: Seconds
    overlap_gradient_per_mille: Gradient  # an approach falling more steeply calls for an overlap
    # the braking distance within which the approach to a home signal is looked at: line speed (km/h, up to) -> m
    braking_distance_m: dict[Annotated[int, Field(gt=0, le=400)], Metres] = Field(min_length=1)
    overlap_release_s: Seconds  # for an overlap whose station file gives no release_s of its own
    squeeze_alarm_s: Seconds
    turnout_concurrency: Count
    turnout_timeout_s: Seconds
    block_pulse_s: Seconds
    usu_min_diverging_kmh: Speed  # USU only over turnouts that allow this diverging speed
    guide_close_s: Seconds
    approach_locking: ApproachLocking
    enemy_onto_track: list[tuple[Literal["train", "shunt"], Literal["train", "shunt"]]]

    def braking_distance(self, line_speed_kmh: float) -> float:
        """The braking distance for a line speed: the figure of the smallest speed not below it (the largest listed
        beyond the table)."""
        table = sorted(self.braking_distance_m.items())
        return next((m for v, m in table if v >= line_speed_kmh), table[-1][1])

    def problems(self) -> list[tuple[Loc, str]]:
        if set(self.release_s) == {"train", "shunt"}:
            return []
        return [(("release_s",), "release_s gives one delay for 'train' and one for 'shunt' routes, no other")]


class DrivingRules(Part):
    """What drivers do with what they see."""

    aspect_speed_kmh: dict[str, Speed | None]  # aspect -> speed past it (None: line speed)
    stop_margin_m: Metres
    shunt_margin_m: Metres
    buffer_margin_m: Metres
    platform_dwell_s: Seconds


class DesignRules(Part):
    """Station-design limits, each reported as a warning with the measured figure."""

    joint_stagger_max_m: Metres
    joint_stagger_max_turnout_m: Metres
    dead_zone_spacing_min_m: Metres
    dead_zone_spacing_relaxed_m: Metres
    dead_zone_short_m: Metres
    dead_zone_long_m: Metres
    fouling_clearance_m: Metres
    fouling_clearance_emu_m: Metres
    cab_code_min_time_s: Seconds
    cab_code_margin_m: Metres
    coding_speed_kmh: Speed
    diverging_speed_kmh: dict[TurnoutNumber, Speed] = Field(min_length=1)
    tuning_area_m: Metres
    tuning_area_tolerance_m: Metres
    tuning_dead_zone_max_m: Metres
    capacitor_min_section_m: Metres
    phase25hz_max_length_m: Metres

    def turnout_speed_kmh(self, number: int) -> float:
        """The typical diverging speed of a turnout of this number (the figure of the largest number not above it)."""
        table = sorted(self.diverging_speed_kmh.items())
        return next((v for n, v in reversed(table) if n <= number), table[0][1])


class MachineSpec(Part):
    throw_s: Seconds
    rated_force_N: Force
    nominal_resistance_N: Force


class DoorSpec(Part):
    open_s: Seconds
    close_s: Seconds


class Equipment(Part):
    """Trackside equipment figures."""

    machines: dict[str, MachineSpec]  # by switch machine type (ZD6, ZDJ9, S700K as station files name them)
    obstruction_lock_mm: Annotated[float, Field(gt=0, le=200)]
    doors: DoorSpec
