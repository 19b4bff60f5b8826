"""Station-wide items of the interlocking test about who may move on a line and into a guided throat.

- **Line direction** (改方) of a bidirectional automatic line: set for departures, no train is received from it (no
  route, no guide route, no guide aspect under guide total lock from the home signal it leads to); and the direction
  is not changed while a guide aspect calls a train in from it, nor may a departure then go out onto it.
- **Guide total lock** (引导总锁闭): while the guide aspect of a throat is lit, no route may lead into that throat or
  onto a track the guided train may reach from it (the interlocking does not know its way); and the guide aspect is
  refused while such a route is set.

What a guided train may reach is found here on the track layout (the tracks reached from the signal through the
throat, and those bordering it), not from the interlocking; the oracle watches every probe.
"""

from __future__ import annotations

from liansuo.interlocking.table.build import Route
from liansuo.proving.verify.probe import Context, Probe, against_running, open_route, prepare, route_line
from liansuo.stations.schema import LinkKind, SignalKind

_INNER = ("throat", "spur")


def line_direction(ctx: Context) -> None:
    st = ctx.station
    guide = ctx.rules.aspects.guide
    for lk in st.model.links:
        if lk.kind is not LinkKind.automatic or not lk.bidirectional or not against_running(st, lk.id):
            continue
        subject = f"line {lk.id}"
        homes = [s.id for s in st.model.signals if s.kind is SignalKind.home
                 and (rear := st.signal_rear_track(s.id)) is not None and st.tracks[rear].section in lk.sections]
        receiving = [r for r in ctx.table.routes.values() if r.kind == "train" and r.signal in homes]
        departures = [r for r in ctx.table.routes.values() if r.kind == "train" and r.exit_link == lk.id]
        p = Probe(ctx)
        result = p.do(f"line-direction {lk.id} out")
        p.run(1.0)
        if not ctx.record(result.ok, "line-direction", subject, f"'line-direction {lk.id} out': {result.message}",
                          p):
            continue
        for r in receiving:
            for line in (route_line(r), " ".join(["guide", *r.buttons])):
                result = p.do(line)
                ctx.record(not result.ok, "line-direction", subject, f"'{line}' with line {lk.id} set for "
                           f"departures from this station: {result.message}", p)
                if result.ok:
                    p.do(f"cancel {r.signal}")
        for h in homes:
            if not shows_guide(ctx, h):
                continue
            p.do(f"guide-lock {h}")
            result = p.do(f"guide {h}")
            ctx.record(not result.ok, "line-direction", subject, f"'guide {h}' under guide total lock with line "
                       f"{lk.id} set for departures from this station: {result.message}", p)
            if result.ok:
                p.do(f"cancel {h}")
            p.do(f"guide-unlock {h}")
        for h in homes:  # a guide aspect calls a train in from the line: the direction stays, no departure onto it
            if not shows_guide(ctx, h):
                continue
            q = Probe(ctx)
            q.do(f"guide-lock {h}")
            q.do(f"guide {h}")
            q.run(1.0)
            if q.aspect(h) != guide:
                continue
            result = q.do(f"line-direction {lk.id} out")
            ctx.record(not result.ok, "line-direction", subject, f"'line-direction {lk.id} out' while {h} shows the "
                       f"guide aspect for a train from it: {result.message}", q)
            for d in departures:
                result = q.do(route_line(d))
                q.run(1.0)
                ctx.record(not result.ok, "line-direction", subject, f"'{route_line(d)}' out onto line {lk.id} "
                           f"while {h} shows the guide aspect for a train from it: {result.message}", q)
        for r in receiving[:1]:  # a route received from the line: the direction stays
            q = Probe(ctx)
            if open_route(q, r):
                result = q.do(f"line-direction {lk.id} out")
                ctx.record(not result.ok, "line-direction", subject, f"'line-direction {lk.id} out' with {r.id} "
                           f"open for a train from it: {result.message}", q)


def guide_area(ctx: Context) -> None:
    st = ctx.station
    guide = ctx.rules.aspects.guide
    for throat in ctx.table.throats:
        if throat not in st.signals or not shows_guide(ctx, throat):
            continue
        subject = f"throat {throat}"
        inner, border = reach(ctx, throat)
        meets = [r for r in ctx.table.routes.values()
                 if r.signal != throat and (set(r.sections) & (inner | border) or r.leads_into in border)]
        p = Probe(ctx)
        p.do(f"guide-lock {throat}")
        p.do(f"guide {throat}")
        p.run(1.0)
        if p.aspect(throat) != guide:
            continue  # guide total lock itself is throat_checks' item
        for r in meets:
            prepare(p, r)
            result = p.do(route_line(r))
            ctx.record(not result.ok, "guide-lock", subject, f"'{route_line(r)}' into the throat of {throat} or onto "
                       f"a track it leads to, while {throat} shows the guide aspect under guide total lock: "
                       f"{result.message}", p)
            if result.ok:
                p.run(1.0)
                p.do(f"cancel {r.signal}")
        for r in _opposing(ctx, throat, border)[:3]:  # and the other way round: a route set first
            q = Probe(ctx)
            if not open_route(q, r):
                continue
            q.do(f"guide-lock {throat}")
            result = q.do(f"guide {throat}")
            q.run(1.0)
            ctx.record(not result.ok and q.aspect(throat) != guide, "guide-lock", subject, f"'guide {throat}' "
                       f"under guide total lock with {r.id} set onto a track it leads to: {result.message}", q)


def reach(ctx: Context, signal: str) -> tuple[set[str], set[str]]:
    """(throat sections, bordering sections): the sections reached from ``signal`` through its throat whichever way
    the turnouts lie, and those where the throat ends (station tracks, the lines), found on the track layout."""
    st = ctx.station
    start = st.signal_entry_track(signal)
    rear = st.signal_rear_track(signal)
    seen, todo = {start, rear}, [start]
    inner, border = {st.tracks[start].section}, set()
    while todo:
        for port in st.track_ports[todo.pop()]:
            for _, nxt in st.node_tracks[port.node]:
                if nxt in seen:
                    continue
                seen.add(nxt)
                sec = st.tracks[nxt].section
                if st.sections[sec].role.value in _INNER:
                    inner.add(sec)
                    todo.append(nxt)
                else:
                    border.add(sec)
    return inner - border, border


def _opposing(ctx: Context, throat: str, border: set[str]) -> list[Route]:
    """Train routes of the other direction ending on a track the guided train may reach."""
    d = ctx.station.signals[throat].direction
    return [r for r in ctx.table.routes.values() if r.kind == "train" and r.direction is not d
            and r.category == "receiving" and r.sections and r.sections[-1] in border]


def shows_guide(ctx: Context, signal: str) -> bool:
    sig = ctx.station.signals[signal]
    return sig.kind in (SignalKind.home, SignalKind.route) and ctx.rules.aspects.can_show(
        ctx.rules.aspects.guide, [lamp.value for lamp in sig.lamps])
