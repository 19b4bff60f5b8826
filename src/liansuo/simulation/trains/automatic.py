"""Automatic shunting (Liu Huawei et al. 2021, Liu Jing et al. 2025: docs/references.md): the locomotive moves only
while its driving conditions hold.

The centre works through the shunting plan: it asks the interlocking for each planned route in turn (the same
``shunt``/``route`` commands a signaller gives). On board, the controller checks the entry conditions once and the
driving conditions every step; when one fails the locomotive stays (or is brought to a stop) braked, and the reason is
shown. It stops a safe distance before a closed or blue signal and before the station boundary, keeps to the depot
limits (8 km/h, 3 km/h over sanding and washing points), stops once at every one-stop point, obeys emergency stops
from several sources (each released only by its own source), and gives way at once to manual driving.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from liansuo.interlocking.io import Result
from liansuo.simulation.trains.autoshunt import (
    ONE_STOP_WINDOW_M,
    ShuntingInputs,
    driving_conditions,
    entry_conditions,
    permitted_speed_kmh,
)
from liansuo.simulation.trains.fleet import Train
from liansuo.simulation.trains.lineside import Lineside

ONE_STOP_MARGIN_M = 1.0  # the front comes to a stand this far short of a one-stop point

# condition flags an instructor can set with 'auto NAME key=on|off'
FLAGS = {"onboard": "authorised_onboard", "centre": "authorised_centre", "loco": "loco_healthy",
         "perception": "perception_healthy"}


@dataclass
class AutoController:
    plan: list[str]
    step: int = 0
    authorised_onboard: bool = True
    authorised_centre: bool = True
    loco_healthy: bool = True
    perception_healthy: bool = True
    one_stops_done: set[str] = field(default_factory=set)
    requested: str = ""  # the plan route last asked of the interlocking
    unmet: list[str] = field(default_factory=list)

    @property
    def current(self) -> str | None:
        return self.plan[self.step] if self.step < len(self.plan) else None


def _next_signal(sim: Lineside, tr: Train) -> tuple[str | None, float]:
    """The next signal ahead that governs this shunting movement, and the distance to it."""
    names = sim.rules.aspects
    for dist, node, _ in sim.fleet.track.ahead(tr.pos, 2000.0):
        for sig in sim.station.signals_at(node):
            if sig.direction is tr.direction and names.can_show(names.shunt, [lp.value for lp in sig.lamps]):
                return sig.id, dist
    return None, 1e9


def inputs_for(sim: Lineside, tr: Train, ctl: AutoController) -> ShuntingInputs:
    view = sim.view
    sig, _dist = _next_signal(sim, tr)
    route = view.route_of(sig) if sig else None
    rid = route.id if route is not None else None
    locked = route is not None and route.state in ("locked", "open", "guide", "closed", "in_use")
    front_track, _ = sim.fleet.front(tr)
    front_section = sim.station.tracks[front_track].section if front_track in sim.station.tracks else ""
    in_route = bool(front_section) and view.section(front_section).locked
    if not in_route and front_section and sim.station.sections[front_section].role.value in ("spur", "station_track"):
        # on a depot or station track beyond the end of its route: the movement goes on under the shunting order up
        # to a safe distance before the next signal or buffer stop (the track holds no turnouts to lock)
        in_route = True
    names = sim.rules.aspects
    aspect = view.aspect(sig) if sig else ""
    plan_route = ctl.current
    return ShuntingInputs(
        authorised_onboard=ctl.authorised_onboard,
        authorised_centre=ctl.authorised_centre,
        shunting_order=plan_route is not None or in_route,
        route_ahead_locked=locked or in_route,
        signal_ahead_open=aspect in names.train_proceed or aspect == names.shunt or in_route,
        plan_matches_route=(plan_route is None and in_route) or (rid is not None and rid == plan_route) or in_route,
        loco_healthy=ctl.loco_healthy,
        perception_healthy=ctl.perception_healthy,
        obstacle_ahead_m=_obstacle(sim, tr),
        speed_kmh=tr.speed_kmh,
    )


def _obstacle(sim: Lineside, tr: Train) -> float | None:
    """Distance to the nearest wheelset of another train (or parked vehicle) on the way ahead."""
    others = [a for name, t in sim.fleet.trains.items() if name != tr.name
              for a in sim.fleet.track.axles(t.pos, t.consist.axle_offsets_m)]
    others += [a for group in sim.parked.values() for a in group]
    best: float | None = None
    for start, move in sim.fleet.track.moves_ahead(tr.pos, 500.0):
        for a in others:
            if a.track != move[0]:
                continue
            s = sim.fleet.track.s_of_x(move, a.x)
            if s is not None and start + s > 0 and (best is None or start + s < best):
                best = start + s
    return best


def attach(sim: Lineside, tr: Train, plan: list[str], flags: dict[str, bool] | None = None) -> Result:
    """Switch ``tr`` to automatic shunting (or, if it already is, update its plan and condition flags)."""
    ctl = tr.controller if isinstance(tr.controller, AutoController) else AutoController(plan)
    if plan:
        ctl.plan, ctl.step, ctl.requested = plan, 0, ""
    for key, value in (flags or {}).items():
        setattr(ctl, FLAGS[key], value)
    if tr.controller is ctl and tr.mode == "auto":
        return Result.accept(f"train {tr.name}: automatic shunting updated")
    unmet = entry_conditions(inputs_for(sim, tr, ctl))
    if unmet:
        return Result.refuse(f"train {tr.name} cannot enter automatic mode: {'; '.join(unmet)}")
    tr.mode = "auto"
    tr.shunting = True
    tr.controller = ctl
    sim.log("train", f"train {tr.name}: automatic shunting" + (f", plan {' -> '.join(plan)}" if plan else ""))
    return Result.accept(f"train {tr.name} in automatic mode" + (f" with {len(plan)} planned routes" if plan else ""))


def centre(sim: Lineside, tr: Train) -> None:
    """The centre's side: ask for the next planned route when the previous one has been run through."""
    ctl = tr.controller
    if not isinstance(ctl, AutoController):
        return
    rid = ctl.current
    if rid is None:
        return
    state = sim.view.route_state(rid)
    if ctl.requested == rid:
        if state == "released":
            route = sim.table.routes[rid]
            sig, _ = _next_signal(sim, tr)
            if sig != route.signal:  # run through (the train has passed its signal): next step of the plan
                ctl.step += 1
                ctl.requested = ""
        return
    if state == "released":
        route = sim.table.routes[rid]
        verb = "shunt" if route.kind == "shunt" else "route"
        result = sim.command(" ".join([verb, *route.buttons]))
        if result.ok:
            ctl.requested = rid
            sim.log("train", f"train {tr.name}: centre asked for {rid}")


def auto_limit(sim: Lineside, tr: Train) -> tuple[float, str] | None:
    """The automatic controller's speed limit this step (m/s) and why; None to leave it to the signals."""
    ctl = tr.controller
    if not isinstance(ctl, AutoController):
        return None
    centre(sim, tr)
    unmet = driving_conditions(inputs_for(sim, tr, ctl))
    if unmet != ctl.unmet and unmet:
        sim.log("train", f"train {tr.name} braked: {'; '.join(unmet)}")
    ctl.unmet = unmet
    if unmet:
        return 0.0, unmet[0]
    axles = sim.fleet.track.axles(tr.pos, tr.consist.axle_offsets_m)
    _, x = sim.fleet.front(tr)
    tracks = {a.track for a in axles} | {m[0] for _, m in sim.fleet.track.moves_ahead(tr.pos, 100.0)}
    rear = axles[-1].x if axles else x
    # the limit here and the braking curves to the restricted stretches ahead (8 km/h, 3 km/h:
    # Liu Huawei et al. 2021, docs/references.md)
    limit = permitted_speed_kmh(x, tr.direction.value, sim.station.model.markers, rear_m=rear, tracks=tracks,
                                decel_ms2=tr.consist.brake_ms2) / 3.6
    why = f"depot limit {limit * 3.6:g} km/h"
    tr.extra.pop("stop_at", None)
    for mk in sim.station.model.markers:
        if mk.kind.value != "one-stop" or mk.id in ctl.one_stops_done:
            continue
        for start, move in sim.fleet.track.moves_ahead(tr.pos, 200.0):
            if move[0] != mk.track:
                continue
            s = sim.fleet.track.s_of_x(move, mk.at)
            if s is None:
                continue
            d = start + s - ONE_STOP_MARGIN_M  # the front stops just short of the point
            if d <= ONE_STOP_WINDOW_M and tr.speed_ms < 0.05:
                ctl.one_stops_done.add(mk.id)  # a stand this close before the point is the stop there
                sim.log("train", f"train {tr.name} stopped at one-stop point {mk.id} ({d + ONE_STOP_MARGIN_M:.1f} m "
                        "short of it)")
            elif d > -ONE_STOP_MARGIN_M:
                tr.extra["stop_at"] = max(d, 0.0)
                v = (2 * tr.consist.brake_ms2 * max(d, 0.0)) ** 0.5
                if v < limit:
                    limit, why = v, f"one-stop point {mk.id}"
            break
    return limit, why
