"""Automatic shunting control logic (调车机车自动驾驶): conditions, emergency stops, depot limits.

Pure logic, after Liu Jing et al. 2025 (docs/references.md; control conditions and modes of automatic shunting) and
Liu Huawei et al. 2021 (docs/references.md; automatic shunting in a locomotive depot). Nothing here moves a train: the
automatic driver of the simulation (``automatic.py``) asks these functions whether it may enter automatic mode,
whether it may move and how fast it may run. The papers' driving-mode arbiter and one-stop bookkeeping on a straight
line, which the simulation does not drive, are in ``research/shunting.py``.

Positions are metres along the line as in the station file (``down`` = towards larger positions). Markers are the
station file's ``markers:`` (any object with ``id, kind, track, at, length_m, speed_kmh``); a sanding or washing
stretch covers ``[at, at + length_m]``. Pass ``tracks`` (the tracks of the movement's path) where parallel depot
tracks share positions, so that only the markers on the movement's own tracks count.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable
from dataclasses import dataclass, replace
from typing import Any, Protocol

SAFE_DISTANCE_M = 10.0  # stop this far before a closed/blue signal, the station boundary or an obstacle (typical)
DEPOT_LIMIT_KMH = 8.0  # Liu Huawei et al. 2021 (docs/references.md): depot speed limit
SERVICE_LIMIT_KMH = 3.0  # Liu Huawei et al. 2021 (docs/references.md): over sanding and washing points (and pits)
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


def stop_source(source: str) -> str:
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
            return f"no emergency stop from {stop_source(source)} is active"
        if by != source:
            who = stop_source(source)
            return f"the emergency stop from {who} can only be released by {who}, not by {stop_source(by)}"
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


# ---- depot limits -------------------------------------------------------------------------------------------------
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
class StopTarget:
    at_m: float  # where the front of the movement must come to a stand
    reason: str
    marker: str | None = None


def markers_on(markers: Iterable[MarkerLike], tracks: Collection[str] | None) -> list[MarkerLike]:
    return [m for m in markers if tracks is None or m.track in tracks]


def direction_sign(direction: str) -> float:
    if direction not in ("down", "up"):
        raise ValueError(f"direction is 'down' or 'up', not {direction!r}")
    return 1.0 if direction == "down" else -1.0


def distance_ahead(front_m: float, at_m: float, direction: str) -> float:
    """Distance from the front to ``at_m`` in the direction of travel (negative: already passed)."""
    return (at_m - front_m) * direction_sign(direction)


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
    for m in markers_on(markers, tracks):
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
    ms = markers_on(markers, tracks)
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


