"""The built-in kinematic train engine: trains as consists of wheelsets moving over the topology.

Each step every train picks a target speed from its driver, accelerates or brakes towards it, moves, and the field
is told where every wheelset stands, so the track circuits (and through them the interlocking) see the trains: as
the sections each train shunts, worked out again only when they can have changed (:mod:`.wheelsets`). Every train's
cab signal reads the code at its leading wheelset, and the ATP brakes on a lost code or a wrong carrier
(:mod:`.cabsignal`); a train with wheelsets in a long dead zone leaks traction current into the next section
(:mod:`.traction`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from liansuo.circuits.field import Field
from liansuo.circuits.leakage import LongDeadZone, long_dead_zones
from liansuo.circuits.railgeometry import Axle
from liansuo.rules import RuleSet, load_rules
from liansuo.simulation.trains.autoshunt import EmergencyStops
from liansuo.simulation.trains.cabsignal import ATP, CabReader, CabReading, CabSignal
from liansuo.simulation.trains.consist import Consist
from liansuo.simulation.trains.drivers import Lookout, aim, stopping_speed
from liansuo.simulation.trains.engine import KinematicEngine, MotionEngine
from liansuo.simulation.trains.movement import OUTSIDE, Notify, Position, TrackGeometry
from liansuo.simulation.trains.odometerfeed import OdometerFeed
from liansuo.simulation.trains.traction import leaking_sections
from liansuo.simulation.trains.wheelsets import TrainWheelsets, wheelsets_now
from liansuo.stations.schema import Direction, Marker
from liansuo.stations.station import Station
from liansuo.stations.topology import Move

MODES = ("manual", "signal", "auto")
WHEEL_OHM = Axle._field_defaults["ohm"]  # a clean wheelset
SLIP_RAMP_S = 1.0


@dataclass
class PlatformStop:
    """ATO platform stop (Xu Yue et al., docs/references.md): stop in the window, open the doors on the platform side
    with the screen doors, dwell, close, and leave only with the doors closed and locked."""

    platform: str
    section: str
    door_keys: tuple[str, ...]
    window_m: float
    state: str = "approaching"  # approaching, stopped, doors_open, closing, done, missed
    stop_x: float = 0.0
    until: float = 0.0


@dataclass
class Train:
    name: str
    consist: Consist
    pos: Position
    mode: str = "manual"
    speed_ms: float = 0.0
    commanded_kmh: float = 0.0  # manual driving
    aspect_limit_ms: float = 1e9  # speed of the last aspect passed
    state: str = "running"  # running, stopped at buffer, derailed, left
    why: str = ""  # what limits its speed now
    platform_stop: PlatformStop | None = None
    train_doors_open: bool = False
    controller: object | None = None  # the automatic shunting controller, when in auto mode
    shunting: bool = False  # a shunting movement (heeds shunting signals) rather than a train movement
    # emergency stops by source (Liu Jing et al. 2025, docs/references.md)
    estops: EmergencyStops = field(default_factory=EmergencyStops)
    # on-board speed and distance measurement (Liu Bin et al., docs/references.md)
    odometer: OdometerFeed = field(default_factory=OdometerFeed)  # worked out when read
    travelled_m: float = 0.0  # the true distance run since placed (what the odometer estimates)
    slip_ratio: float = 0.0  # wheel speed / true speed - 1 while an injected slip (> 0) or slide (< 0) lasts
    slip_from: float = 0.0
    slip_until: float = 0.0
    extra: dict[str, object] = field(default_factory=dict)
    traction: bool = True  # draws traction current (a track trolley does not)
    cab: CabSignal = field(default_factory=CabSignal, repr=False, compare=False)  # the cab signal (机车信号)
    wheelsets: TrainWheelsets | None = field(default=None, repr=False, compare=False)  # as the field last took them

    @property
    def direction(self) -> Direction:
        return self.pos.moves[-1][1]

    @property
    def speed_kmh(self) -> float:
        return self.speed_ms * 3.6


Aspects = Callable[[], dict[str, str]]


@dataclass(frozen=True)
class Departure:
    """A train that has run out of the station over a boundary: what is left to tell of it."""

    name: str
    direction: str  # "down" or "up"
    mode: str
    t: float  # when its last wheelset left


def _lineside(station: Station, rules: RuleSet) -> tuple[dict[str, list[LongDeadZone]], dict[str, list[Marker]]]:
    """What trains meet along the track: the long dead zones by track, and the balises and RFID tags by track, in
    the station's order."""
    tags: dict[str, list[Marker]] = {}
    for mk in station.model.markers:
        if mk.kind.value in ("balise", "rfid"):
            tags.setdefault(mk.track, []).append(mk)
    return long_dead_zones(station, rules.design.dead_zone_long_m), tags


class Fleet:
    """Every train of one simulation."""

    def __init__(self, station: Station, fld: Field, aspects: Aspects, notify: Notify,
                 auto_limit: Callable[[Train], tuple[float, str] | None] | None = None,
                 engine: MotionEngine | None = None, rules: RuleSet | None = None) -> None:
        self.auto_limit = auto_limit
        self.rules = rules or load_rules()  # drivers read its driving part and its aspects
        self.engine: MotionEngine = engine or KinematicEngine()
        self.station = station
        self.field = fld
        self.track = TrackGeometry(station, fld)
        self.lookout = Lookout(station, self.rules)  # what drivers look out for, sorted out once
        # long dead zones by track, balises and RFID tags by track: read only, shared by every fleet of the station
        self.long_zones, self.tags = station.derived(_lineside, self.rules)
        self.cabs = CabReader(station, fld, self.track, self.long_zones, WHEEL_OHM)
        self.aspects = aspects
        self.notify = notify
        self.trains: dict[str, Train] = {}
        self.departed: dict[str, Departure] = {}  # trains that have left the station, until the name is used again
        self.t = 0.0
        self.dt = 0.25

    # ---- placing -------------------------------------------------------------------------------------------------
    def place(self, name: str, consist: Consist, section: str, direction: Direction, mode: str,
              back_m: float = 5.0, front_x: float | None = None) -> str:
        pos = self.track.place(section, direction, consist.length_m, back_m, front_x)
        if isinstance(pos, str):
            return pos
        why = self.engine.add(name, consist, 0.0)
        if why:
            return why
        train = Train(name, consist, pos, mode)
        self.trains[name] = train
        self.departed.pop(name, None)
        return ""

    def remove(self, name: str) -> None:
        self.trains.pop(name, None)
        self.engine.remove(name)

    # ---- stepping ----------------------------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        self.t += dt
        self.dt = dt
        targets: dict[str, float] = {}
        limits: dict[str, float] = {}
        aspects = self.aspects()
        for tr in self.trains.values():
            if tr.state in ("derailed", "left"):
                continue
            target, why = self._target(tr, aspects)
            if tr.mode == "auto":
                aspects = self.aspects()  # its controller may have asked for a route: read the signals afresh
            if tr.platform_stop is not None and tr.mode != "manual":
                target, why = self._platform(tr, target, why)
            tr.why = why
            targets[tr.name] = target
            if tr.platform_stop is not None or tr.mode == "auto":  # else it has no exact stopping point
                stop_at = self._exact_stop(tr)
                if stop_at is not None:
                    limits[tr.name] = stop_at
        motion = self.engine.step(dt, targets, limits)
        ahead = self.track.ahead
        for name, (speed, ds) in motion.items():
            moving = self.trains.get(name)
            if moving is not None:
                accel = (speed - moving.speed_ms) / dt
                moving.speed_ms = speed
                passing = ahead(moving.pos, ds) if ds > 0 else []  # the nodes its front passes in this step
                self._odometry(moving, dt, ds, accel, passing)
                self._move(moving, ds, passing)
        for tr in list(self.trains.values()):
            if tr.state not in ("derailed", "left") and self.cabs.update(tr) is not None:  # its state changed
                self._atp(tr, tr.cab.reading)

    def _atp(self, tr: Train, reading: CabReading) -> None:
        """The ATP brakes a train movement to a stand when its cab loses the code or reads a wrong carrier."""
        if not reading.failed or tr.shunting or ATP in tr.estops.active:
            return
        tr.estops.apply(ATP, reading.why)
        self.notify("train", f"train {tr.name}: ATP brakes to a stand: {reading.why}")
        self.notify("alarm", f"ATP braked train {tr.name}: {reading.why}")

    def leaking(self) -> set[str]:
        """The sections taking traction current leaking through long dead zones from the trains' wheelsets."""
        return leaking_sections(self.track, self.long_zones, self.trains.values()) if self.long_zones else set()

    def _odometry(self, tr: Train, dt: float, ds: float, accel: float, passing: list[tuple[float, str, Move]]) -> None:
        """Feed the on-board odometer: the wheels turn at the train's speed, faster while slipping, slower while
        sliding; it is corrected at balises / RFID tags and where the front crosses into the next section (the
        nodes in ``passing``: ``Track.ahead`` of the front over ``ds``)."""
        slip = 0.0
        if tr.slip_ratio and self.t < tr.slip_until + SLIP_RAMP_S:
            # a slip or slide builds up and dies away over about a second rather than jumping
            since = self.t - tr.slip_from
            slip = tr.slip_ratio * max(0.0, min(1.0, since / SLIP_RAMP_S, (tr.slip_until + SLIP_RAMP_S - self.t)
                                                 / SLIP_RAMP_S))
        before = tr.travelled_m
        tr.travelled_m += ds
        tr.odometer.update(dt, (ds / dt) * (1.0 + slip), accel)
        if ds <= 0:
            return
        v = ds / dt
        for dist, node, _ in passing:
            if dist > ds:
                break
            if node in self.station.joints:  # passed (ds - dist) / v seconds before the end of this step
                tr.odometer.section_transition(before + dist, since_s=(ds - dist) / v)
        for start, move in self.track.moves_ahead(tr.pos, ds) if self.tags else ():
            for mk in self.tags.get(move[0], ()):
                s = self.track.s_of_x(move, mk.at)
                if s is not None and 0.0 <= start + s < ds:
                    tr.odometer.correct(before + start + s, mk.kind.value, since_s=(ds - start - s) / v)

    def _move(self, tr: Train, ds: float, passing: list[tuple[float, str, Move]]) -> None:
        c = tr.consist
        if ds <= 0.0:
            return
        self._note_signals_passed(tr, ds, passing)
        moved, stop = self.track.advance(tr.name, tr.pos, ds, self.notify)
        if stop:
            tr.speed_ms = 0.0
            self.engine.set_speed(tr.name, 0.0)
            tr.state = "derailed" if stop == "derailed" else "running"
        self.track.trim(tr.pos, c.length_m)
        if tr.pos.moves[-1][0] == OUTSIDE and all(mv[0] == OUTSIDE for mv in tr.pos.moves):
            tr.state = "left"
            self.notify("train", f"train {tr.name} has left the station")
            self.departed[tr.name] = Departure(tr.name, tr.direction.value, tr.mode, self.t)
            self.remove(tr.name)
        del moved

    def _target(self, tr: Train, aspects: dict[str, str]) -> tuple[float, str]:
        if tr.estops.stopped:  # an emergency stop outranks everything, the driver's traction too
            return 0.0, "emergency stop (" + ", ".join(sorted(tr.estops.active)) + ")"
        c = tr.consist
        vmax = c.vmax_kmh / 3.6
        if tr.mode == "manual":
            return min(abs(tr.commanded_kmh) / 3.6, vmax), "driver"
        rules = self.rules.driving
        horizon = tr.speed_ms ** 2 / (2 * c.brake_ms2) + 400.0
        margin = rules.shunt_margin_m if tr.mode == "auto" else rules.stop_margin_m
        # target_speed(look_ahead(...)) in one pass (drivers.aim)
        v, why = aim(self.track, tr.pos, aspects, self.lookout, horizon, margin, tr.shunting, tr.mode == "auto",
                     tr.aspect_limit_ms, vmax, c.brake_ms2, tr.speed_ms * self.dt)
        if tr.mode == "auto" and self.auto_limit is not None:
            extra = self.auto_limit(tr)
            if extra is not None and extra[0] < v:
                v, why = extra
        return v, why

    def _exact_stop(self, tr: Train) -> float | None:
        """Distance to the point the train must stop at, if it is stopping there this step."""
        ps = tr.platform_stop
        if ps is not None and ps.state == "approaching" and tr.mode != "manual":
            d = self._distance_to_x(tr, ps.stop_x)
            if d is not None and d >= 0:
                return d
        if tr.mode != "auto":
            return None
        stop = tr.extra.get("stop_at")
        return float(stop) if isinstance(stop, float | int) else None

    def _note_signals_passed(self, tr: Train, ds: float, passing: list[tuple[float, str, Move]]) -> None:
        if not passing:
            return
        rules = self.rules.driving
        aspects = self.aspects()
        for dist, node, _ in passing:
            if dist > ds:
                break
            for sig in self.station.signals_at(node):
                if sig.direction is tr.direction and (sig.kind.value == "shunting") == tr.shunting:
                    aspect = aspects.get(sig.id, "")
                    limit = rules.aspect_speed_kmh.get(aspect)
                    tr.aspect_limit_ms = 1e9 if limit is None else limit / 3.6
                    if aspect in self.rules.aspects.closed:
                        self.notify("train", f"train {tr.name} passed signal {sig.id} at {aspect or 'dark'}")

    # ---- platform stop and doors (Xu Yue et al., docs/references.md) ------------------------------------------------
    def set_platform_stop(self, tr: Train, platform: str) -> str:
        p = next((p for p in self.station.model.platforms if p.id == platform), None)
        if p is None:
            return f"there is no platform '{platform}'"
        tracks = self.station.section_tracks[p.section]
        lo = min(self.station.track_span(t)[0] for t in tracks)
        hi = max(self.station.track_span(t)[1] for t in tracks)
        margin = 20.0  # the stopping mark stands short of the starting signal
        stop = next((m.at for m in self.station.model.markers if m.kind.value == "stop" and m.track in tracks), None)
        if stop is None:
            stop = hi - margin if tr.direction is Direction.down else lo + margin
        keys = tuple(f"{p.id}:{d.side.value}" for d in p.screen_doors)
        tr.platform_stop = PlatformStop(p.id, p.section, keys, p.stop_window_m, stop_x=stop)
        return ""

    def _distance_to_x(self, tr: Train, x: float) -> float | None:
        """Distance from the train's front to position ``x`` along the rails ahead (negative: just passed)."""
        for start, move in self.track.moves_ahead(tr.pos, 3000.0):
            s = self.track.s_of_x(move, x)
            if s is not None and (start + s >= -tr.consist.length_m or start >= 0):
                return start + s
        return None

    def _platform(self, tr: Train, target: float, why: str) -> tuple[float, str]:
        ps = tr.platform_stop
        assert ps is not None
        if ps.state == "approaching":
            d = self._distance_to_x(tr, ps.stop_x)
            if d is None:
                return target, why
            if d < -ps.window_m:
                ps.state = "missed"
                self.notify("train", f"train {tr.name} overran the stopping window at {ps.platform}")
                return target, why
            if abs(d) <= ps.window_m and tr.speed_ms < 0.05:
                ps.state = "stopped"
                self.notify("train", f"train {tr.name} stopped at platform {ps.platform}, {d:+.2f} m from the mark "
                            f"(window ±{ps.window_m:g} m): door-open permission "
                            f"{', '.join(k.split(':')[1] for k in ps.door_keys) or 'none'}")
                return 0.0, f"platform {ps.platform}"
            v = stopping_speed(max(d, 0.0), tr.consist.brake_ms2)
            return (v, f"platform {ps.platform}") if v < target else (target, why)
        if ps.state in ("stopped", "doors_open", "closing"):
            return 0.0, f"platform {ps.platform} ({ps.state})"
        return target, why

    # ---- what the track circuits and front ends see -----------------------------------------------------------
    def wheelsets(self) -> dict[str, TrainWheelsets]:
        """Where every train's wheelsets stand, by train, as the field takes them (``Field.set_axles``): a train that
        has not moved keeps its object, and the sections it shunts are worked out again only when they can have
        changed."""
        out: dict[str, TrainWheelsets] = {}
        geometry = self.field.geometry
        for tr in self.trains.values():
            w = wheelsets_now(self.track, geometry, tr.wheelsets, tr.pos, tr.consist.axle_offsets_m, WHEEL_OHM)
            tr.wheelsets = out[tr.name] = w
        return out

    def sections_of(self, tr: Train) -> tuple[str, ...]:
        secs: list[str] = []
        for a in self.track.axles(tr.pos, tr.consist.axle_offsets_m):
            s = self.station.tracks[a.track].section
            if s not in secs:
                secs.append(s)
        return tuple(secs)

    def front(self, tr: Train) -> tuple[str, float]:
        move = tr.pos.moves[-1]
        if move[0] == OUTSIDE:
            return OUTSIDE, 0.0
        return move[0], self.track.x_at(move, tr.pos.front_s)


__all__ = ["MODES", "Departure", "Fleet", "PlatformStop", "Train"]
