"""The canonical key of an explored state: two states with the same key behave the same from here on.

The key is the state itself, written out: the interlocking's routes with their stages, marks and timers, every lock,
the turnout moves and the queue, the alarms, the outputs and the relays it reads (with the changes it has not taken
yet); the field's switch machines, lamps, doors, track circuits and faults; the virtual neighbours' block machines;
and the oracle's memory (the authorities it holds, what closed and may reopen, the findings waiting).

The time abstraction (docs/explore.md, :class:`Clock`): a timer is kept as its place in the order in which the timers
of the state run out, not as the seconds left: the move time-outs and the switch machines' throws, the squeeze
alarm, time releases, overlaps, guide aspects left unused, the section fault releases counting down, and the
oracle's own overlap times. Time only runs by ``advance`` to the next moment something changes, so what happens next
depends on which timer runs out first, never on by how much. The routes and the move queue are in a fixed order (of
their ids): two routes set in either order, their turnouts queued in either order, are one state.

What is left out changes nothing ahead: the event log and its counters, cached memos (``tests/test_quiet_same.py``
holds them to that), the cab codes (worked out from the rest each cycle), sealed-button counts,
the alarms (shown to the operator; no decision of the interlocking reads them); of the signals the oracle lets the
operator open again, those that have not closed since (opening forgets them); of the sections released on the
operator's word, those no movement under way covers any more (the oracle forgets them at its next look).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from typing import Any

from liansuo.interlocking.locks import Lock
from liansuo.interlocking.state import RouteStage
from liansuo.proving.judge.judge import TOLERANCE_S
from liansuo.proving.oracle.watch import Watch
from liansuo.simulation.sim import Simulation


def state_key(sim: Simulation, watch: Watch) -> bytes:
    """A 16-byte digest of the state of ``sim`` and of the oracle watching it."""
    clock = Clock(sim.t)
    data = (interlocking_part(sim, clock), field_part(sim, clock), oracle_part(sim, watch, clock),
            judge_part(watch, clock))
    # written with repr, not pickle: a pickle's bytes follow which equal values happen to be one object
    return hashlib.blake2b(repr(clock.ranked(data)).encode(), digest_size=16).digest()


class Clock:
    """The timers of a state, each written as its place in the order in which they will run out (the region
    abstraction of timed automata): which runs out first, and which have run out, is what decides what happens next;
    by how much, no event waits for. A timer that has run out is ``-1``; none is None."""

    def __init__(self, now: float) -> None:
        self.now = now
        self.left: list[float] = []

    def timer(self, at: float | None) -> tuple[str, int] | None:
        """A timer running out at ``at`` (absolute simulated time)."""
        if at is None:
            return None
        self.left.append(round(at - self.now, 3))
        return ("timer", len(self.left) - 1)

    def ranked(self, data: Any) -> Any:
        order = sorted({x for x in self.left if x > 0})
        rank = {x: i for i, x in enumerate(order)}
        places = [rank[x] if x > 0 else -1 for x in self.left]

        def put(x: Any) -> Any:
            if isinstance(x, tuple):
                if len(x) == 2 and x[0] == "timer" and isinstance(x[1], int):
                    return ("timer", places[x[1]])
                return tuple(put(y) for y in x)
            return x
        return put(data)


def _items(d: dict[Any, Any]) -> tuple[tuple[Any, Any], ...]:
    return tuple(sorted(d.items()))


def _holds(locks: Iterable[Lock]) -> tuple[tuple[str, str], ...]:
    return tuple(sorted((lk.hold.value, lk.holder) for lk in locks))


def _flat(obj: object, leave: tuple[str, ...] = ()) -> tuple[tuple[str, object], ...]:
    """A small record's fields, written out the same way in every process (for parts with no time in them)."""
    return tuple(sorted((k, _canon(v)) for k, v in vars(obj).items() if k not in leave))


def _canon(v: object) -> object:
    """``v`` as plain data in a fixed order (a set's order follows the string hashing of its process)."""
    if isinstance(v, (set, frozenset)):
        return ("set", tuple(sorted((_canon(x) for x in v), key=repr)))
    if isinstance(v, dict):
        return ("dict", tuple(sorted(((_canon(k), _canon(x)) for k, x in v.items()), key=repr)))
    if isinstance(v, (list, tuple)):
        return tuple(_canon(x) for x in v)
    if isinstance(v, (str, int, float, bool)) or v is None:
        return v
    if hasattr(v, "__dict__"):
        return (type(v).__name__, _flat(v))
    return repr(v)


def interlocking_part(sim: Simulation, clock: Clock) -> tuple[object, ...]:
    core = sim.interlocking.core
    rules = core.rules
    t = clock.timer
    routes = tuple(sorted((
        rs.id, rs.stage.value, rs.run_on.sections if rs.run_on else None, rs.entered, tuple(rs.released),
        tuple(rs.was_occupied), t(rs.release_at), t(rs.overlap_release_at),
        rs.guide_first_clear, rs.guide_approach_seen,
        t(rs.since + rules.guide_close_s) if rs.stage is RouteStage.guide and not rs.guide_approach_seen else None,
        rs.overlap_released, rs.guide_route, tuple(sorted((i, t(at)) for i, at in rs.fault_release_at.items())),
    ) for rs in core.routes.values()))
    locks = core.locks
    ledger = (tuple(sorted((name, _holds(held)) for name, held in locks.sections.items())),
              tuple(sorted((name, _holds(held)) for name, held in locks.turnouts.items())),
              tuple(sorted(locks.blocked)))
    turnouts = tuple((ts.id, ts.target, ts.queued,
                      t(ts.move_started + rules.turnout_timeout_s) if ts.move_started is not None else None,
                      ts.no_indication_since is not None,
                      t(ts.no_indication_since + rules.squeeze_alarm_s)
                      if ts.no_indication_since is not None and not ts.squeeze_alarmed else None, ts.squeeze_alarmed)
                     for ts in core.turnouts.values()
                     if ts.target is not None or ts.queued or ts.no_indication_since is not None or ts.squeeze_alarmed)
    board = core.board
    relays = (_items(board.track), _items(board.dbj), _items(board.fbj),
              tuple(sorted((s, _items(lamps)) for s, lamps in board.lamps.items())), _items(board.flasher),
              _items(board.filament_alarm), _items(board.pdkj), _items(board.pdqcj),
              tuple(sorted((k, tuple(sorted(v))) for k, v in board.line_in.items())),
              tuple(sorted(board.changed_tracks)), tuple(sorted(board.changed_turnouts)),
              tuple(sorted(board.changed_signals)), tuple(sorted(board.changed_doors)))
    out = core.out
    outputs = (_items(out.signals), _items(out.turnouts), tuple(sorted((k, _flat(d)) for k, d in out.doors.items())),
               _items(out.line_direction), tuple(sorted((k, tuple(sorted(v))) for k, v in out.line_out.items())),
               tuple(sorted(out.axle_resets)), tuple(sorted(out.changed_signals)), tuple(sorted(out.changed_turnouts)))
    return (routes, ledger, tuple(sorted((r, t(at)) for r, at in core.overlap_pending.items())), turnouts,
            tuple(sorted(core.queue)), tuple(sorted(core.moving)), tuple(sorted(core.no_indication)),
            tuple(sorted(core.usu_failed)),
            tuple(sorted((s, None if g.approach_seen else t(g.since + rules.guide_close_s), g.approach_seen)
                         for s, g in core.guide_only.items())),
            tuple(sorted(core.line_out)), core.power_up_locked, core.codes_dirty, core.blocks_dirty,
            tuple(sorted((k, _flat(v)) for k, v in core.links.items())),
            tuple(sorted((k, _flat(v)) for k, v in core.station_links.items())),
            tuple(sorted(s for s, ss in core.signals.items() if ss.red_dark)), relays, outputs)


def field_part(sim: Simulation, clock: Clock) -> tuple[object, ...]:
    f = sim.field
    machines = tuple((m.turnout, m.rails, m.locked, m.target, m.running, _canon(m.faults),
                      clock.timer(sim.t + m.spec.throw_s - m.progress) if m.running else None)
                     for m in f.machines.values())
    lamps = tuple((s, tuple(sorted(sl.commanded)),
                   tuple((n, lamp.main_ok, lamp.backup_ok, lamp.dj.up) for n, lamp in sorted(sl.lamps.items())))
                  for s, sl in f.lamps.items())
    flashers = tuple((s, fl.energised, fl.bad_contact) for s, fl in sorted(f.flashers.items()))
    circuits = tuple((s, c.k_switch, c.up, _canon(c.faults)) for s, c in f.circuits.items())
    doors = tuple((k, _flat(d)) for k, d in sorted(f.doors.items()))
    faults = tuple(sorted(((k, _canon(x)) for k, x in f.faults.items()), key=repr))
    axles = tuple(sorted((a.track, round(a.x, 3)) for a in f.axles))
    neighbours = tuple(sorted((k, _flat(v, ("t", "since", "at"))) for k, v in sim.neighbours.by_link.items()))
    return (machines, lamps, flashers, circuits, doors, faults, axles, neighbours,
            tuple(sorted(sim.alarms)), tuple(sorted(sim.parked)))


def oracle_part(sim: Simulation, watch: Watch, clock: Clock) -> tuple[object, ...]:
    o = watch.oracle
    open_ = tuple(sorted((s, a.kind, tuple(a.tracks), a.overlap_sections) for s, a in o.open.items()))
    in_use = tuple((u.auth.signal, tuple(u.auth.tracks), u.auth.overlap_sections, tuple(u.seen), tuple(sorted(u.pre)),
                    u.passed, u.reached_at is not None,
                    clock.timer(u.reached_at + u.auth.overlap_release_s) if u.reached_at is not None else None,
                    u.operator, u.guided)
                   for u in o.in_use)
    # a signal the operator may open again matters only once it has closed (opening forgets it)
    return (open_, _items(o.shown), in_use, _sorted(o.closed), _sorted(o.allowed & o.closed), _items(o.pending),
            _sorted(o.active), _items(o.was_moving), _sorted(o.approached), _sorted(o.operated),
            _sorted(o.guide_locked), _sorted(o.fault_released & {s for u in o.in_use for s in u.sections}),
            _sorted(o.turnout_sections_occupied), _sorted(o.guide_given))


def _sorted(xs: Iterable[str]) -> tuple[str, ...]:
    return tuple(sorted(xs))


def judge_part(watch: Watch, clock: Clock) -> tuple[object, ...]:
    """The reference judge's memory: the routes it follows and what they owe, its timers as the clock's."""
    if watch.judge is None:
        return ()
    m = watch.judge.memory
    unused = watch.judge.rules.guide_close_s + TOLERANCE_S  # when an unused guide aspect is owed closed
    claims = tuple(sorted((c.signal, c.kind, c.given, c.path, c.end_signal, c.entered, clock.timer(c.hold_until),
                           clock.timer(None if c.guide_since is None else c.guide_since + unused),
                           c.guide_approached, c.guide_entered_at, c.guide_first_clear, c.overlap_owed,
                           c.first_clear, c.guided, c.total_lock) for c in m.claims.values()))
    holds = tuple(sorted((h.what, h.sections, clock.timer(h.until)) for h in m.holds))
    watched = {s for c in m.claims.values() for s in c.path} | {s for h in m.holds for s in h.sections}
    return (claims, holds, m.powered_up, _sorted(m.locked & watched), m.commanded, _sorted(m.active),
            _sorted(m.occupied_before))
