"""Station-wide items of the interlocking test: the power-up state (上电解锁) after the interlocking starts, and red
lamp transfer (红灯转移) to the signals in rear of every signal that has a red lamp."""

from __future__ import annotations

from liansuo.stations.schema import SignalKind

from ..oracle.authority import Tracer
from .probe import Context, Probe, route_line

_STATION = ("throat", "station_track", "spur")


def power_up(ctx: Context) -> None:
    """After a restart every signal is closed, every section locked: routes and individual operation are refused;
    the power-up release is refused while a section shows occupied and then releases every section."""
    st = ctx.station
    subject = "power-up"
    p = Probe(ctx)
    result = p.do("restart")
    if not ctx.record(result.ok, "power-up", subject, f"'restart': {result.message}", p):
        return
    p.run(1.0)
    open_ = [s.id for s in st.model.signals if s.kind is not SignalKind.block and not p.closed(s.id)]
    ctx.record(not open_, "power-up", subject, f"after a restart signals {', '.join(open_)} are not closed", p)
    sections = [s for s, sec in st.sections.items() if sec.role.value in _STATION]
    free = [s for s in sections if p.sim.section_state(s) != "locked"]
    ctx.record(not free, "power-up", subject, f"after a restart sections {', '.join(free)} are not locked", p)
    r = next(iter(ctx.table.routes.values()), None)
    if r is not None:
        result = p.do(route_line(r))
        ctx.record(not result.ok, "power-up", subject, f"'{route_line(r)}' before the power-up release: "
                   f"{result.message}", p)
    for t in st.turnouts:
        pos = p.sim.turnout_state(t)[0] or "normal"
        result = p.do(f"throw {t} {'reverse' if pos == 'normal' else 'normal'}")
        ctx.record(not result.ok, "power-up", subject, f"turnout {t} could be thrown before the power-up release: "
                   f"{result.message}", p)
    if sections:
        p.do(f"occupy {sections[0]}")
        result = p.do("power-up-release")
        ctx.record(not result.ok and sections[0] in result.message, "power-up", subject,
                   f"'power-up-release' with {sections[0]} occupied: {result.message}", p)
        p.do(f"vacate {sections[0]}")
    result = p.do("power-up-release")
    p.run(1.0)
    still = [s for s in sections if p.sim.section_state(s) == "locked"]
    ctx.record(result.ok and not still, "power-up", subject, f"'power-up-release' with the station clear: "
               f"{result.message}" + (f"; still locked: {', '.join(still)}" if still else ""), p)


def red_lamp_transfer(ctx: Context) -> None:
    """Every signal with a red lamp: with its red lamp dark (both filaments), the automatic block signal in rear of it
    shows H, and no route ending at it opens (the signal would show nothing to the train it receives)."""
    st = ctx.station
    tracer = Tracer(st)
    rear_blocks: dict[str, list[str]] = {}
    for s in st.model.signals:
        if s.kind is SignalKind.block:
            a = tracer.trace(s.id, "train", lambda t: None)
            if a.end_signal is not None:
                rear_blocks.setdefault(a.end_signal, []).append(s.id)
    names = ctx.rules.aspects
    for s in st.model.signals:
        if names.stop_lamp not in {lamp.value for lamp in s.lamps}:
            continue
        routes = [r for r in ctx.table.routes.values() if r.kind == "train" and r.end_signal == s.id]
        blocks = rear_blocks.get(s.id, [])
        if not routes and not blocks:
            continue
        subject = f"signal {s.id}"
        p = Probe(ctx)
        p.do(f"fault filament {s.id} lamp={names.stop_lamp} which=both")
        if s.kind is SignalKind.block:  # a block signal at stop: a train in its section ahead
            p.do(f"occupy {st.tracks[st.signal_entry_track(s.id)].section}")
        p.run(1.0)
        for b in blocks:
            ctx.record(p.aspect(b) == names.stop, "red-lamp-transfer", subject, f"the red lamp of {s.id} is dark "
                       f"with it at stop: block signal {b} in rear shows {p.aspect(b)}", p)
        if routes:
            r = routes[0]
            p.do(route_line(r))
            p.run(20.0)
            ctx.record(p.closed(r.signal), "red-lamp-transfer", subject, f"the red lamp of {s.id} is dark: "
                       f"{r.signal} opened over {r.id} ({p.aspect(r.signal)})", p)

