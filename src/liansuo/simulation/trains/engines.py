"""Choosing the train engine by name: ``kinematic`` (the default, built in, fast) or ``sumo`` (Eclipse SUMO)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from liansuo.simulation.trains.engine import KinematicEngine, MotionEngine
from liansuo.stations.station import Station

if TYPE_CHECKING:
    from liansuo.simulation.trains.fleet import Fleet

ENGINES = ("kinematic", "sumo")


def make_engine(engine: str | MotionEngine, station: Station, cycle_s: float) -> MotionEngine:
    """The engine called ``engine`` for ``station`` (an engine object is returned as it is). ``sumo`` raises
    :class:`~simulation.trains.sumo_export.SumoUnavailable` when the extra is not installed and
    :class:`~simulation.trains.sumo.SumoEngineError` when SUMO cannot start."""
    if not isinstance(engine, str):
        return engine
    if engine == "kinematic":
        return KinematicEngine()
    if engine == "sumo":
        from liansuo.simulation.trains.sumo import SumoEngine

        return SumoEngine(station, step_s=cycle_s)
    raise ValueError(f"unknown train engine '{engine}': choose {' or '.join(ENGINES)}")


def attach_engine(engine: MotionEngine, fleet: Fleet) -> None:
    """Engines that need the fleet (where the trains are, the aspects, the event log) get it here."""
    attach = getattr(engine, "attach", None)
    if callable(attach):
        attach(fleet)


__all__ = ["ENGINES", "attach_engine", "make_engine"]
