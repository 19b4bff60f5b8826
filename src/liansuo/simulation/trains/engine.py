"""Train engines: what turns the drivers' target speeds into movement.

A :class:`MotionEngine` is told each step the speed every train aims for and must leave each train's speed and
distance run in the step; the fleet then moves the train over the topology (squeezing or derailing at turnouts as
they lie), so the track circuits and the interlocking see the same thing whichever engine runs. The built-in
:class:`KinematicEngine` (the default, and the fast one) accelerates and brakes each train on its own; the optional
SUMO engine (``simulation.trains.sumo``) lets Eclipse SUMO compute the motion.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

from liansuo.simulation.trains.consist import Consist


class MotionEngine(Protocol):
    name: str

    def add(self, train: str, consist: Consist, speed_ms: float) -> str:
        """A train enters the engine ('' or why it cannot)."""

    def remove(self, train: str) -> None: ...

    def step(self, dt: float, targets: Mapping[str, float],
             limits: Mapping[str, float]) -> dict[str, tuple[float, float]]:
        """Advance ``dt`` seconds. ``targets``: the speed (m/s) each train aims for; ``limits``: a distance (m) each
        must not exceed in this step (an exact stopping point), or absent. Returns (speed m/s, metres run) per
        train."""

    def set_speed(self, train: str, speed_ms: float) -> None:
        """Force a train's speed (0 after a derailment or at a buffer stop)."""

    def close(self) -> None: ...


class KinematicEngine:
    """Each train accelerates at its traction rate towards its target and brakes at its service rate."""

    name = "kinematic"

    def __init__(self) -> None:
        self.consists: dict[str, Consist] = {}
        self.speeds: dict[str, float] = {}

    def add(self, train: str, consist: Consist, speed_ms: float) -> str:
        self.consists[train] = consist
        self.speeds[train] = speed_ms
        return ""

    def remove(self, train: str) -> None:
        self.consists.pop(train, None)
        self.speeds.pop(train, None)

    def step(self, dt: float, targets: Mapping[str, float],
             limits: Mapping[str, float]) -> dict[str, tuple[float, float]]:
        out: dict[str, tuple[float, float]] = {}
        for name, target in targets.items():
            c = self.consists[name]
            v = self.speeds[name]
            v = min(target, v + c.accel_ms2 * dt) if v < target else max(target, v - c.brake_ms2 * dt)
            ds = v * dt
            limit = limits.get(name)
            if limit is not None and ds >= limit:
                ds, v = max(limit, 0.0), 0.0  # reach the stopping point exactly rather than overshoot by a step
            self.speeds[name] = v
            out[name] = (v, ds)
        return out

    def set_speed(self, train: str, speed_ms: float) -> None:
        self.speeds[train] = speed_ms

    def close(self) -> None:
        return None
