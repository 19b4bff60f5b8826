"""The papers' automatic-shunting models that the simulation does not drive (research code, tested, used by no
command): the driving modes and the priority table that decides between them each cycle (Liu Jing et al. 2025,
docs/references.md), and one-stop points and stopping targets on a straight line (Liu Huawei et al. 2021).

The simulation's automatic driver (``automatic.py``) has one mode, automatic shunting, and gives way to manual driving
and emergency stops in the train fleet itself; it finds its one-stop points on the track graph. What is here keeps the
papers' whole rule sets (remote and hump-pushing modes too) for experiments, from plain inputs
(docs/trains-automation.md).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass
from enum import StrEnum

from liansuo.rules import DARK, Aspects, load_rules
from liansuo.simulation.trains.autoshunt import (
    ONE_STOP_WINDOW_M,
    SAFE_DISTANCE_M,
    EmergencyStops,
    MarkerLike,
    ShuntingInputs,
    StopTarget,
    direction_sign,
    distance_ahead,
    driving_conditions,
    entry_conditions,
    markers_on,
    stop_source,
)

REMOTE_LIMIT_KMH = 5.0  # Liu Jing et al. 2025 (docs/references.md): remote driving (远程遥控) at most 5 km/h ...
REMOTE_LIMIT_M = 200.0  # ... and 200 m (or one signal interval)


# remote driving (远程遥控) is the fallback when these are missing (e.g. a long consist covers a track circuit)
_REMOTE_WAIVES = frozenset({"shunting_order", "route_ahead_locked", "signal_ahead_open", "plan_matches_route",
                            "position_matches_plan"})


# ---- modes and priorities ----------------------------------------------------------------------------------------
class DrivingMode(StrEnum):
    manual = "manual"  # 人工驾驶
    auto_shunting = "auto-shunting"  # 调车自控
    field_remote = "field-remote"  # 现场遥控: the shunting team's portable set gives the orders
    remote = "remote"  # 远程遥控: remote driving desk, <= 5 km/h and <= 200 m
    hump_pushing = "hump-pushing"  # 驼峰推峰自控


class ShuntAction(StrEnum):
    emergency_brake = "emergency-brake"
    monitor = "monitor"  # emergency stop while secured at a stand: watch the speed, brake at once if it moves
    manual = "manual"  # the driver drives; automatic traction is cut
    brake = "brake"  # automatic: stop and stay braked
    move = "move"  # automatic: may drive, within ``speed_limit_kmh``


@dataclass(frozen=True)
class Decision:
    action: ShuntAction
    mode: DrivingMode
    reasons: tuple[str, ...] = ()
    speed_limit_kmh: float | None = None
    distance_limit_m: float | None = None


PRIORITY = (  # highest first: stopping outranks moving, manual outranks automatic
    ("emergency stop from any source, moving or not secured", ShuntAction.emergency_brake),
    ("emergency stop from any source, at a stand and secured", ShuntAction.monitor),
    ("driver's input in the cab (brake or traction)", ShuntAction.manual),
    ("manual mode", ShuntAction.manual),
    ("automatic mode, a condition unmet or no movement demanded", ShuntAction.brake),
    ("automatic mode, every condition met", ShuntAction.move),
)


class ModeArbiter:
    """Decides the commanded behaviour each cycle, by the priority table ``PRIORITY``.

    Manual control has the highest priority and automatic control the lowest; stopping outranks moving. Driver input
    while in an automatic mode cuts the automatic traction and latches manual mode: automatic driving comes back only
    through ``engage`` (the crew's check and the switch). An emergency stop outranks everything, the driver's traction
    too; the driver may always brake.
    """

    def __init__(self, stops: EmergencyStops | None = None) -> None:
        self.stops = stops if stops is not None else EmergencyStops()
        self.mode = DrivingMode.manual

    def engage(self, mode: DrivingMode, inputs: ShuntingInputs) -> list[str]:
        """Switch to ``mode``; returns the unmet entry conditions (then the mode is unchanged)."""
        unmet = [] if mode is DrivingMode.manual else entry_conditions(inputs)
        if not unmet:
            self.mode = mode
        return unmet

    def decide(self, inputs: ShuntingInputs, *, manual_input: bool = False, demand_move: bool = True,
               secured: bool = False) -> Decision:
        took_over = manual_input and self.mode is not DrivingMode.manual
        if took_over:  # the automatic system cuts its traction and hands over at once, whatever else holds
            self.mode = DrivingMode.manual
        if self.stops.stopped:
            why = tuple(f"emergency stop from {stop_source(s)}" for s in sorted(self.stops.active))
            if secured and inputs.speed_kmh == 0:
                return Decision(ShuntAction.monitor, self.mode, why)
            return Decision(ShuntAction.emergency_brake, self.mode, why)
        if took_over:
            return Decision(ShuntAction.manual, self.mode, ("driver took over: automatic traction cut",))
        if self.mode is DrivingMode.manual:
            return Decision(ShuntAction.manual, self.mode)
        remote = self.mode is DrivingMode.remote
        unmet = driving_conditions(inputs, waive=_REMOTE_WAIVES if remote else ())
        if not demand_move:
            unmet.insert(0, "no movement demanded")
        if unmet:
            return Decision(ShuntAction.brake, self.mode, tuple(unmet))
        if remote:
            return Decision(ShuntAction.move, self.mode, (), REMOTE_LIMIT_KMH, REMOTE_LIMIT_M)
        return Decision(ShuntAction.move, self.mode)


@dataclass(frozen=True)
class DepotMarker:
    """A plain marker, shaped like the station file's ``markers:`` entries."""

    id: str
    kind: str
    track: str
    at: float
    length_m: float = 0.0
    speed_kmh: float | None = None


def next_stop(front_m: float, direction: str, markers: Iterable[MarkerLike], *, served: Collection[str] = (),
              tracks: Collection[str] | None = None) -> StopTarget | None:
    """The nearest one-stop point (一度停车点) ahead not yet served: the movement must come to a stand before it."""
    best: tuple[float, MarkerLike] | None = None
    for m in markers_on(markers, tracks):
        if m.kind != "one-stop" or m.id in served:
            continue
        d = distance_ahead(front_m, m.at, direction)
        if d >= 0 and (best is None or d < best[0]):
            best = (d, m)
    return None if best is None else StopTarget(best[1].at, f"one-stop point {best[1].id}", best[1].id)


class OneStopPoints:
    """One-stop points of a movement: each is served once the movement stood within ``window_m`` before it and the
    driver confirmed the restart (再发车确认, Liu Huawei et al. 2021, docs/references.md); until then it is the
    movement's stopping point."""

    def __init__(self, markers: Iterable[MarkerLike], *, tracks: Collection[str] | None = None,
                 window_m: float = ONE_STOP_WINDOW_M) -> None:
        self.markers = [m for m in markers_on(markers, tracks) if m.kind == "one-stop"]
        self.window_m = window_m
        self.stood: set[str] = set()
        self.served: set[str] = set()

    def next_stop(self, front_m: float, direction: str) -> StopTarget | None:
        return next_stop(front_m, direction, self.markers, served=self.served)

    def observe(self, front_m: float, direction: str, speed_kmh: float) -> str | None:
        """Note a stand before the next point; returns its id when this stand counts as the stop there."""
        target = self.next_stop(front_m, direction)
        if target is None or target.marker is None or speed_kmh != 0:
            return None
        if 0 <= distance_ahead(front_m, target.at_m, direction) <= self.window_m:
            self.stood.add(target.marker)
            return target.marker
        return None

    def confirm(self, marker: str) -> str:
        """The driver's restart confirmation at ``marker``: '' if accepted, else why not."""
        if marker not in self.stood:
            return f"the movement has not stopped at one-stop point {marker}"
        self.served.add(marker)
        return ""


def stop_target(front_m: float, direction: str, *, signal_at_m: float | None = None, signal_aspect: str = DARK,
                boundary_at_m: float | None = None, obstacle_ahead_m: float | None = None,
                buffer_at_m: float | None = None, one_stop: StopTarget | None = None,
                safe_distance_m: float = SAFE_DISTANCE_M, rules: Aspects | None = None) -> StopTarget | None:
    """The nearest point ahead where the front must stop: ``safe_distance_m`` before a closed signal (at a stop
    aspect of the rule set, or dark), the station boundary (pass ``boundary_at_m=None`` once the station has given a
    route beyond), an obstacle or a buffer stop; at a one-stop point. A target behind the front means: stop now."""
    s = direction_sign(direction)
    found: list[StopTarget] = []
    if signal_at_m is not None and signal_aspect in (rules or load_rules().aspects).closed:
        found.append(StopTarget(signal_at_m - s * safe_distance_m, f"signal ahead shows {signal_aspect or 'dark'}"))
    if boundary_at_m is not None:
        found.append(StopTarget(boundary_at_m - s * safe_distance_m, "station boundary"))
    if obstacle_ahead_m is not None:
        found.append(StopTarget(front_m + s * (obstacle_ahead_m - safe_distance_m), "obstacle ahead"))
    if buffer_at_m is not None:
        found.append(StopTarget(buffer_at_m - s * safe_distance_m, "buffer stop"))
    if one_stop is not None:
        found.append(one_stop)
    return min(found, key=lambda t: distance_ahead(front_m, t.at_m, direction), default=None)
