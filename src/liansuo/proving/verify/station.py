"""Station-wide items of the interlocking test: the power-up state (上电解锁) after the interlocking starts, and red
lamp transfer (红灯转移) to the signals in rear of every signal that has a red lamp."""

from __future__ import annotations

from liansuo.interlocking.table.build import Route
from liansuo.proving.oracle.authority import Tracer
from liansuo.proving.verify.lines import shows_guide
from liansuo.proving.verify.probe import Context, Probe, route_line
from liansuo.stations.schema import SignalKind

_STATION = ("throat", "station_track", "spur")


def power_up(ctx: Context) -> None:
    """After a restart every signal is closed, every section locked: routes, guide aspects under guide total lock and
    individual operation are refused;
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
    for throat in ctx.table.throats:  # nor a guide aspect under guide total lock: it is a movement authority too
        if throat in st.signals and shows_guide(ctx, throat) and p.do(f"guide-lock {throat}").ok:
            result = p.do(f"guide {throat}")
            p.run(1.0)
            ctx.record(not result.ok and p.closed(throat), "power-up", subject, f"'guide {throat}' under guide "
                       f"total lock before the power-up release: {result.message}; {throat} shows "
                       f"{p.aspect(throat)}", p)
            p.do(f"guide-unlock {throat}")
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


def queued_move(ctx: Context) -> None:
    """A turnout move waiting in the queue (more moves asked than the rule set's ``turnout_concurrency`` drive at
    once) is never started after a vehicle has entered its turnout's section: the interlocking looks at the section
    again when the move's turn comes. Each throw counts as one move (a crossover pair or a driven turnout queues
    more), so the last one thrown surely waits."""
    st = ctx.station
    p = Probe(ctx)
    asked: list[tuple[str, str]] = []  # (turnout, its position before the throw)
    for t in sorted(st.turnouts):
        if any(t in members and t != members[0] for members in st.pairs.values()):
            continue  # thrown with its partner
        was = p.sim.turnout_state(t)[0]
        if was is None or not p.do(f"throw {t} {'reverse' if was == 'normal' else 'normal'}").ok:
            continue
        asked.append((t, was))
        if len(asked) > ctx.rules.turnout_concurrency:
            break
    if len(asked) <= ctx.rules.turnout_concurrency:
        return  # too few turnouts to fill the drives: no move ever waits
    t, was = asked[-1]
    section = st.turnout_section[t]
    p.do(f"occupy {section}")
    p.run(ctx.rules.turnout_timeout_s + 2.0)  # every move before it has ended (or timed out) by then
    now = p.sim.turnout_state(t)[0]
    ctx.record(now == was, "queued-move", "turnouts", f"turnout {t} was driven from {was} (now "
               f"{now or 'without indication'}) after {section} became occupied while its move waited in the queue", p)


def red_lamp_transfer(ctx: Context) -> None:
    """Every signal with a red lamp: with its red lamp dark (both filaments), the automatic block signal in rear of it
    shows H, and no route ending at it opens (the signal would show nothing to the train it receives).

    A signal that only block signals stand in rear of is tried together with others whose signals and sections do
    not touch its own (:func:`_apart`), on one simulation: on a line of thousands of block signals a simulation each
    would make the test grow with the square of the line. Where such a group fails, each of its signals is tried
    again alone, so a failure comes with the script of its own signal."""
    st = ctx.station
    tracer = Tracer(st)
    rear_blocks: dict[str, list[str]] = {}
    reach: dict[str, list[str]] = {}  # block signal -> the sections of its authority (up to the signal ahead)
    for s in st.model.signals:
        if s.kind is SignalKind.block:
            a = tracer.trace(s.id, "train", lambda t: None)
            reach[s.id] = a.all_sections
            if a.end_signal is not None:
                rear_blocks.setdefault(a.end_signal, []).append(s.id)
    names = ctx.rules.aspects
    ending: dict[str, list[Route]] = {}
    for r in ctx.table.routes.values():
        if r.kind == "train" and r.end_signal is not None:
            ending.setdefault(r.end_signal, []).append(r)
    alone: list[str] = []
    line: list[str] = []  # signals with only block signals in rear: tried in groups
    for s in st.model.signals:
        if names.stop_lamp not in {lamp.value for lamp in s.lamps}:
            continue
        if ending.get(s.id):
            alone.append(s.id)
        elif rear_blocks.get(s.id):
            line.append(s.id)
    for group in _apart(ctx, line, rear_blocks, reach):
        if len(group) == 1 or not _dark_red(ctx, group, rear_blocks, [], quiet=True):
            for sig in group:
                _dark_red(ctx, [sig], rear_blocks, [])
    for sig in alone:
        _dark_red(ctx, [sig], rear_blocks, ending[sig][:1])


def _entry_section(ctx: Context, signal: str) -> str:
    st = ctx.station
    return st.tracks[st.signal_entry_track(signal)].section


def _apart(ctx: Context, signals: list[str], rear_blocks: dict[str, list[str]], reach: dict[str, list[str]]
           ) -> list[list[str]]:
    """``signals`` in groups whose members touch nothing of each other: not the same signals (each with the block
    signals in rear of it) and not the same sections (the section it protects, occupied for the test, and those the
    signals in rear of it read). First fit, in the file's order: a line needs two groups."""
    groups: list[tuple[list[str], set[str], set[str]]] = []
    for sig in signals:
        mine = {sig, *rear_blocks[sig]}
        secs = {_entry_section(ctx, sig), *(x for b in rear_blocks[sig] for x in reach.get(b, ()))}
        for members, used, sections in groups:
            if not (mine & used or secs & sections):
                members.append(sig)
                used |= mine
                sections |= secs
                break
        else:
            groups.append(([sig], mine, secs))
    return [members for members, _, _ in groups]


def _dark_red(ctx: Context, signals: list[str], rear_blocks: dict[str, list[str]], routes: list[Route], *,
              quiet: bool = False) -> bool:
    """One simulation with the red lamp of each of ``signals`` dark: the block signals in rear show H, and the first
    of ``routes`` (ending at the one signal) does not open. ``quiet``: only say whether every check held (a group
    tried again signal by signal where it did not)."""
    st = ctx.station
    names = ctx.rules.aspects
    p = Probe(ctx)
    for sig in signals:
        p.do(f"fault filament {sig} lamp={names.stop_lamp} which=both")
        if st.signals[sig].kind is SignalKind.block:  # a block signal at stop: a train in its section ahead
            p.do(f"occupy {_entry_section(ctx, sig)}")
    p.run(1.0)
    held = True
    for sig in signals:
        for b in rear_blocks.get(sig, []):
            ok = p.aspect(b) == names.stop
            held = held and ok
            if not quiet:
                ctx.record(ok, "red-lamp-transfer", f"signal {sig}", f"the red lamp of {sig} is dark with it at "
                           f"stop: block signal {b} in rear shows {p.aspect(b)}", p)
    if routes:
        r = routes[0]
        p.do(route_line(r))
        p.run(20.0)
        ok = p.closed(r.signal)
        held = held and ok
        if not quiet:
            ctx.record(ok, "red-lamp-transfer", f"signal {signals[0]}", f"the red lamp of {signals[0]} is dark: "
                       f"{r.signal} opened over {r.id} ({p.aspect(r.signal)})", p)
    if quiet and held:  # each check held: count them as the signal-by-signal run would
        ctx.checks += sum(len(rear_blocks.get(sig, [])) for sig in signals)
    return held
