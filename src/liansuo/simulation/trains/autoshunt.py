"""Automatic shunting control logic (调车机车自动驾驶): conditions, emergency stops, priorities, depot limits.

Pure logic, after Liu Jing et al. 2025 (docs/references.md; control conditions and modes of automatic shunting) and
Liu Huawei et al. 2021 (docs/references.md; automatic shunting in a locomotive depot). Nothing here moves a train: the
train driver of the simulation asks these functions whether it may enter automatic mode, whether it may move, what it
must do now, how fast it may run and where it must stop.

Positions are metres along the line as in the station file (``down`` = towards larger positions). Markers are the
station file's ``markers:`` (any object with ``id, kind, track, at, length_m, speed_kmh``); a sanding or washing
stretch covers ``[at, at + length_m]``. Pass ``tracks`` (the tracks of the movement's path) where parallel depot
tracks share positions, so that only the markers on the movement's own tracks count.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable
from dataclasses import dataclass, replace
from enum import StrEnum
from typing import Any, Protocol

from liansuo.rules import DARK, Aspects, load_rules

SAFE_DISTANCE_M = 10.0  # stop this far before a closed/blue signal, the station boundary or an obstacle (typical)
DEPOT_LIMIT_KMH = 8.0  # Liu Huawei et al. 2021 (docs/references.md): depot speed limit
SERVICE_LIMIT_KMH = 3.0  # Liu Huawei et al. 2021 (docs/references.md): over sanding and washing points (and pits)
REMOTE_LIMIT_KMH = 5.0  # Liu Jing et al. 2025 (docs/references.md): remote driving (远程遥控) at most 5 km/h ...
REMOTE_LIMIT_M = 200.0  # ... and 200 m (or one signal interval)
ONE_STOP_WINDOW_M = 5.0  # a stand this close before a one-stop point counts as the stop there (typical)
SERVICE_DECEL_MS2 = 0.3  # braking used for the permitted-speed curve (typical for a light locomotive)

_SERVICE_KINDS = ("sanding", "washing")


# ---- conditions (控制条件) --------------------------------------------------------------------------------------
@dataclass
class ShuntingInputs:
    """What the automatic driving system knows now.

    The first ten are required: the simulation states them every cycle. The rest, also from Liu Jing et al. 2025
    (docs/references.md), default to "met" (not modelled, so no fault); set one to ``False`` to study that failure.
    """

    # driving conditions (行车条件), Liu Jing et al. 2025 (docs/references.md) section 1.2 (numbers as there)
    authorised_onboard: bool  # 1 the cab's automatic-driving switch is at "auto"
    authorised_centre: bool  # 2 the control centre's terminal is at "automatic driving"
    shunting_order: bool  # 3 a shunting order allows movement (推进/起动/减速/十车/五车/三车/连结/溜放)
    route_ahead_locked: bool  # 4 the route ahead is locked (hand-thrown turnouts single-locked)
    signal_ahead_open: bool  # 5 the signal ahead is open
    plan_matches_route: bool  # 6 shunting plan, route and signal agree
    loco_healthy: bool  # 8 locomotive status normal (also entry self-check: control output and sensors)
    perception_healthy: bool  # 9 environment perception allows movement
    obstacle_ahead_m: float | None  # distance to an obstacle seen ahead, None if none
    speed_kmh: float
    position_matches_plan: bool = True  # 7 the locomotive stands where plan, route and signal expect it
    system_healthy: bool = True  # 10 the automatic driving system itself is healthy
    area_ahead_ok: bool = True  # no failed non-critical ground input (gate, hand-thrown turnout) covers the area
    # entry conditions (投入条件): the crew's check (人检) and the self-check (自检), Liu Jing et al. 2025
    # (docs/references.md) section 1.1
    crew_confirmed: bool = True  # positioning right, plan matches position, direction and distance right
    positioning_ok: bool = True  # satellite, RFID tag and balise positioning working
    ground_signals_ok: bool = True  # signal and yard indications received
    plan_received: bool = True  # shunting plan received
    comms_ok: bool = True  # train-ground communication
    ground_sensors_ok: bool = True  # gates, hand-thrown turnouts, derailers, stop devices (non-critical)
    external_interfaces_ok: bool = True  # wireless shunting radio, loading equipment hand-over tokens

    @classmethod
    def all_clear(cls, **changes: Any) -> ShuntingInputs:
        """Every condition met, at a stand, no obstacle; then ``changes`` (``all_clear(signal_ahead_open=False)``)."""
        base = cls(authorised_onboard=True, authorised_centre=True, shunting_order=True, route_ahead_locked=True,
                   signal_ahead_open=True, plan_matches_route=True, loco_healthy=True, perception_healthy=True,
                   obstacle_ahead_m=None, speed_kmh=0.0)
        return replace(base, **changes)


_DRIVING = (
    ("authorised_onboard", "automatic-driving switch on the locomotive is not at 'auto'"),
    ("authorised_centre", "the control centre has not authorised automatic driving"),
    ("shunting_order", "no shunting order allows movement"),
    ("route_ahead_locked", "the route ahead is not locked"),
    ("signal_ahead_open", "the signal ahead is not open"),
    ("plan_matches_route", "the shunting plan does not match the route and signal"),
    ("position_matches_plan", "the locomotive is not where the plan, route and signal expect it"),
    ("loco_healthy", "locomotive status is not normal"),
    ("perception_healthy", "environment perception does not allow movement"),
    ("system_healthy", "the automatic driving system is not healthy"),
    ("area_ahead_ok", "a ground input of the area ahead has failed (gate, hand-thrown turnout): no automatic movement"),
)
_ENTRY = (
    ("crew_confirmed", "the crew has not confirmed position, plan, direction and distance"),
    ("positioning_ok", "positioning is not working (satellite, RFID tags, balises)"),
    ("loco_healthy", "locomotive control or sensor readings are not normal"),
    ("ground_signals_ok", "signal and yard indications are not received"),
    ("plan_received", "no shunting plan received"),
    ("comms_ok", "train-ground communication is down"),
    ("external_interfaces_ok", "an external interface (shunting radio, loading equipment) is down"),
    ("system_healthy", "the automatic driving system failed its self-check"),
)
# remote driving (远程遥控) is the fallback when these are missing (e.g. a long consist covers a track circuit)
_REMOTE_WAIVES = frozenset({"shunting_order", "route_ahead_locked", "signal_ahead_open", "plan_matches_route",
                            "position_matches_plan"})


def entry_conditions(inputs: ShuntingInputs) -> list[str]:
    """Unmet conditions to enter automatic driving from manual; empty: the crew may switch to automatic."""
    return [why for name, why in _ENTRY if not getattr(inputs, name)]


def entry_warnings(inputs: ShuntingInputs) -> list[str]:
    """Non-critical self-check failures: entry is allowed, with an alarm; movement is refused where they apply."""
    if inputs.ground_sensors_ok:
        return []
    return ["ground sensors (gates, hand-thrown turnouts, derailers, stop devices) not all read: no automatic "
            "movement where they are missing"]


def driving_conditions(inputs: ShuntingInputs, *, waive: Collection[str] = (),
                       safe_distance_m: float = SAFE_DISTANCE_M) -> list[str]:
    """Unmet conditions to move under automatic control; empty: may move, otherwise stay braked."""
    unmet = [why for name, why in _DRIVING if name not in waive and not getattr(inputs, name)]
    if inputs.obstacle_ahead_m is not None and inputs.obstacle_ahead_m <= safe_distance_m:
        unmet.append(f"obstacle {inputs.obstacle_ahead_m:.0f} m ahead, within the {safe_distance_m:g} m safe distance")
    return unmet


# ---- emergency stop (应急停车) -----------------------------------------------------------------------------------
SOURCES = {"team": "the shunting team", "cab": "the cab button", "remote": "the remote operator",
           "system": "the automatic driving system"}


def _who(source: str) -> str:
    return SOURCES.get(source, f"'{source}'")


class EmergencyStops:
    """Emergency stops by source: whoever set a stop releases it (谁下达，谁解锁); sources coexist independently.

    Sources (Liu Jing et al. 2025, docs/references.md): ``team`` (shunting team's radio order), ``cab`` (button in
    the cab or on the body), ``remote`` (remote terminal), ``system`` (the automatic system itself: perception, sudden
    signal change, service brake failure). Other source names are accepted and follow the same rule.
    """

    def __init__(self) -> None:
        self._active: dict[str, str] = {}

    def apply(self, source: str, reason: str = "") -> None:
        if not source:
            raise ValueError("an emergency stop needs a source")
        self._active.setdefault(source, reason)

    def release(self, source: str, by: str) -> str:
        """Release ``source``'s stop on behalf of ``by``: '' when released, else why not."""
        if source not in self._active:
            return f"no emergency stop from {_who(source)} is active"
        if by != source:
            return f"the emergency stop from {_who(source)} can only be released by {_who(source)}, not by {_who(by)}"
        del self._active[source]
        return ""

    @property
    def active(self) -> frozenset[str]:
        return frozenset(self._active)

    @property
    def stopped(self) -> bool:
        return bool(self._active)

    def reason(self, source: str) -> str:
        return self._active.get(source, "")


# ---- modes and priorities ----------------------------------------------------------------------------------------
class DrivingMode(StrEnum):
    manual = "manual"  # 人工驾驶
    auto_shunting = "auto-shunting"  # 调车自控
    field_remote = "field-remote"  # 现场遥控: the shunting team's portable set gives the orders
    remote = "remote"  # 远程遥控: remote driving desk, <= 5 km/h and <= 200 m
    hump_pushing = "hump-pushing"  # 驼峰推峰自控


class Action(StrEnum):
    emergency_brake = "emergency-brake"
    monitor = "monitor"  # emergency stop while secured at a stand: watch the speed, brake at once if it moves
    manual = "manual"  # the driver drives; automatic traction is cut
    brake = "brake"  # automatic: stop and stay braked
    move = "move"  # automatic: may drive, within ``speed_limit_kmh``


@dataclass(frozen=True)
class Decision:
    action: Action
    mode: DrivingMode
    reasons: tuple[str, ...] = ()
    speed_limit_kmh: float | None = None
    distance_limit_m: float | None = None


PRIORITY = (  # highest first: stopping outranks moving, manual outranks automatic
    ("emergency stop from any source, moving or not secured", Action.emergency_brake),
    ("emergency stop from any source, at a stand and secured", Action.monitor),
    ("driver's input in the cab (brake or traction)", Action.manual),
    ("manual mode", Action.manual),
    ("automatic mode, a condition unmet or no movement demanded", Action.brake),
    ("automatic mode, every condition met", Action.move),
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
            why = tuple(f"emergency stop from {_who(s)}" for s in sorted(self.stops.active))
            if secured and inputs.speed_kmh == 0:
                return Decision(Action.monitor, self.mode, why)
            return Decision(Action.emergency_brake, self.mode, why)
        if took_over:
            return Decision(Action.manual, self.mode, ("driver took over: automatic traction cut",))
        if self.mode is DrivingMode.manual:
            return Decision(Action.manual, self.mode)
        remote = self.mode is DrivingMode.remote
        unmet = driving_conditions(inputs, waive=_REMOTE_WAIVES if remote else ())
        if not demand_move:
            unmet.insert(0, "no movement demanded")
        if unmet:
            return Decision(Action.brake, self.mode, tuple(unmet))
        if remote:
            return Decision(Action.move, self.mode, (), REMOTE_LIMIT_KMH, REMOTE_LIMIT_M)
        return Decision(Action.move, self.mode)


# ---- depot limits and stopping points ----------------------------------------------------------------------------
class MarkerLike(Protocol):
    @property
    def id(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def track(self) -> str: ...
    @property
    def at(self) -> float: ...
    @property
    def length_m(self) -> float: ...
    @property
    def speed_kmh(self) -> float | None: ...


@dataclass(frozen=True)
class DepotMarker:
    """A plain marker, shaped like the station file's ``markers:`` entries."""

    id: str
    kind: str
    track: str
    at: float
    length_m: float = 0.0
    speed_kmh: float | None = None


@dataclass(frozen=True)
class StopTarget:
    at_m: float  # where the front of the movement must come to a stand
    reason: str
    marker: str | None = None


def _on(markers: Iterable[MarkerLike], tracks: Collection[str] | None) -> list[MarkerLike]:
    return [m for m in markers if tracks is None or m.track in tracks]


def _sign(direction: str) -> float:
    if direction not in ("down", "up"):
        raise ValueError(f"direction is 'down' or 'up', not {direction!r}")
    return 1.0 if direction == "down" else -1.0


def distance_ahead(front_m: float, at_m: float, direction: str) -> float:
    """Distance from the front to ``at_m`` in the direction of travel (negative: already passed)."""
    return (at_m - front_m) * _sign(direction)


def _restricted(m: MarkerLike) -> float | None:
    if m.kind in _SERVICE_KINDS:
        return m.speed_kmh if m.speed_kmh is not None else SERVICE_LIMIT_KMH
    return m.speed_kmh if m.length_m > 0 else None


def depot_speed_limit_kmh(front_m: float, markers: Iterable[MarkerLike], *, rear_m: float | None = None,
                          tracks: Collection[str] | None = None, depot_kmh: float = DEPOT_LIMIT_KMH) -> float:
    """The limit where the movement stands: 8 km/h in the depot, the stretch's limit (3 km/h) while any part of the
    movement (``rear_m`` to ``front_m``) is over a sanding or washing stretch."""
    lo, hi = sorted((front_m, front_m if rear_m is None else rear_m))
    limit = depot_kmh
    for m in _on(markers, tracks):
        v = _restricted(m)
        if v is not None and lo <= m.at + m.length_m and hi >= m.at:
            limit = min(limit, v)
    return limit


def braking_speed_kmh(distance_m: float, *, target_kmh: float = 0.0, decel_ms2: float = SERVICE_DECEL_MS2) -> float:
    """Highest speed from which braking at ``decel_ms2`` reaches ``target_kmh`` within ``distance_m``."""
    v_t = target_kmh / 3.6
    return 3.6 * math.sqrt(v_t * v_t + 2.0 * decel_ms2 * max(distance_m, 0.0))


def permitted_speed_kmh(front_m: float, direction: str, markers: Iterable[MarkerLike], *,
                        rear_m: float | None = None, tracks: Collection[str] | None = None,
                        stop: StopTarget | None = None, depot_kmh: float = DEPOT_LIMIT_KMH,
                        decel_ms2: float = SERVICE_DECEL_MS2) -> float:
    """The speed the automatic driver may run at now: the limit here, braking curves to the restricted stretches
    ahead and to the stopping point."""
    ms = _on(markers, tracks)
    limit = depot_speed_limit_kmh(front_m, ms, rear_m=rear_m, depot_kmh=depot_kmh)
    for m in ms:
        v = _restricted(m)
        if v is None:
            continue
        near = m.at if direction == "down" else m.at + m.length_m
        d = distance_ahead(front_m, near, direction)
        if d > 0:
            limit = min(limit, braking_speed_kmh(d, target_kmh=v, decel_ms2=decel_ms2))
    if stop is not None:
        limit = min(limit, braking_speed_kmh(distance_ahead(front_m, stop.at_m, direction), decel_ms2=decel_ms2))
    return limit


def next_stop(front_m: float, direction: str, markers: Iterable[MarkerLike], *, served: Collection[str] = (),
              tracks: Collection[str] | None = None) -> StopTarget | None:
    """The nearest one-stop point (一度停车点) ahead not yet served: the movement must come to a stand before it."""
    best: tuple[float, MarkerLike] | None = None
    for m in _on(markers, tracks):
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
        self.markers = [m for m in _on(markers, tracks) if m.kind == "one-stop"]
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
    s = _sign(direction)
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
