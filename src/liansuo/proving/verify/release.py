"""The interlocking test of one route, continued: cancel with the approach clear, manual time release with it
occupied, sequential release behind a passing train (with the overlap timer), section fault release, the guide
aspect, platform screen doors, and the aspects the signal shows with the onward routes set."""

from __future__ import annotations

from functools import partial

from liansuo.proving.judge.rules import fault_release_delay, overlap_time, release_delay
from liansuo.proving.verify.lines import reach
from liansuo.proving.verify.probe import (
    Context,
    Probe,
    other,
    prepare,
    route_line,
)
from liansuo.proving.verify.routecheck import RouteItems
from liansuo.proving.verify.signalchecks import SignalChecks, door_platforms
from liansuo.stations.schema import SignalKind


class ReleaseChecks(RouteItems):
    """The release items: cancel, time release, sequential release, fault release, overlap, guide."""

    def run(self) -> None:
        self.cancel()
        self.time_release()
        self.normal_release()
        self.flicker()
        self.fault_release()
        self.overlap_fault_release()
        self.guide()
        self.guide_route()
        SignalChecks(self.rt).run()

    def approached(self) -> Probe | None:
        """A probe with the route's signal open and a train standing in its approach, or None (the route's failure
        to open already reported)."""
        p = Probe(self.ctx)
        if not self.rt.opened(p, "opens"):
            return None
        for s in self.r.approach:
            p.do(f"occupy {s}")
        p.run(1.0)
        return p

    def all_free(self, p: Probe) -> str:
        """'' when every section and turnout of the route is free again, else what is still locked."""
        locked = [s for s in self.r.all_sections if p.sim.section_state(s) == "locked"]
        locked += [f"turnout {t.id}" for t in self.r.all_turnouts if p.sim.turnout_state(t.id)[1]]
        return ", ".join(locked)

    # ---- cancel and manual time release ------------------------------------------------------------------------
    def cancel(self) -> None:
        r, p = self.r, Probe(self.ctx)
        if not self.rt.opened(p, "opens"):
            return
        result = p.do(f"cancel {r.signal}")
        p.run(0.5)
        held = self.all_free(p)
        self.rt.check(result.ok and p.closed(r.signal) and p.state(r) == "released" and not held, "cancel",
                      f"'cancel {r.signal}' with the approach clear: {result.message}; signal shows "
                      f"{p.aspect(r.signal)}, route {p.state(r)}" + (f", still locked: {held}" if held else ""), p)

    def time_release(self) -> None:
        r = self.r
        if not r.approach:
            self.na("time-release (no approach section)")
            return
        p = self.approached()
        if p is None:
            return
        result = p.do(f"cancel {r.signal}")
        self.rt.check(not result.ok and p.state(r) != "released", "approach-locking",
                      f"'cancel {r.signal}' with approach {', '.join(r.approach)} occupied was accepted", p)
        result = p.do(f"release {r.signal}")
        delay = release_delay(self.st, self.ctx.rules, r.signal, r.kind)  # the published rule, not the product's
        t0 = p.sim.t
        p.run(1.0)
        ok = result.ok and p.closed(r.signal) and p.state(r) == "time_release"
        if not self.rt.check(ok, "time-release", f"'release {r.signal}': {result.message}; signal shows "
                             f"{p.aspect(r.signal)}, route {p.state(r)}", p):
            return
        # the approach showing clear again (a train backing off, or one that does not shunt) neither ends the time
        # release nor lets a section fault release cut it short
        for s in r.approach:
            p.do(f"vacate {s}")
        inner = next((s for s in r.sections if not self.st.is_station_track(s)), None)
        if inner is not None:
            result = p.do(f"fault-release {inner}")
            if not self.rt.check(not result.ok and p.state(r) == "time_release", "time-release",
                                 f"'fault-release {inner}' during the time release, the approach clear again: "
                                 f"{result.message}; route {p.state(r)}", p):
                return
        # a section further in showing occupied (a red band, a vehicle come another way) is no movement entering
        # from the signal: the delay runs on
        further = next((s for s in r.sections[1:] if not self.st.is_station_track(s)), None)
        if further is not None:
            p.do(f"occupy {further}")
            p.run(1.0)
            state = p.state(r)
            p.do(f"vacate {further}")
            if not self.rt.check(state == "time_release", "time-release", f"{further} showing occupied during the "
                                 f"time release, nothing entering from {r.signal}: the route went {state}", p):
                return
        p.run(t0 + delay - 1.0 - p.sim.t)
        held = [s for s in r.sections if p.sim.section_state(s) != "locked"]
        if not self.rt.check(p.state(r) == "time_release" and not held, "time-release",
                             f"{delay - 1:g} s into the {delay:g} s time release the route is {p.state(r)}"
                             + (f", sections not locked: {', '.join(held)}" if held else ""), p):
            return
        p.run(2.0)
        held_s = self.all_free(p)
        self.rt.check(p.state(r) == "released" and not held_s and p.closed(r.signal), "time-release",
                      f"{delay + 1:g} s after 'release {r.signal}' the route is {p.state(r)}"
                      + (f", still locked: {held_s}" if held_s else ""), p)

    # ---- a train passing: sequential release, overlap ----------------------------------------------------------
    def normal_release(self) -> None:
        """Occupancy moves through the approach, each route section and beyond, as a train does: the signal closes
        as it enters (a shunting signal once the consist is past it), each section releases behind it, nothing
        reopens, and the whole route is released at the end (the overlap after its timer)."""
        r, p = self.r, Probe(self.ctx)
        if not self.rt.opened(p, "opens"):
            return
        rs = p.sim.interlocking.routes[r.id]
        sig, secs, beyond = r.signal, rs.sections, p.sim.interlocking.lifecycle.beyond(rs)  # with the run-on, if any
        for s in r.approach:
            p.do(f"occupy {s}")
        p.run(1.0)
        for i, s in enumerate(secs):
            p.do(f"occupy {s}")
            p.run(1.0)
            if i == 0:
                if r.kind == "train" and not self.rt.check(p.closed(sig), "closes-on-entry",
                                                           f"the train entered {s}: signal {sig} still shows "
                                                           f"{p.aspect(sig)}", p):
                    return
                for a in r.approach:
                    p.do(f"vacate {a}")
                p.run(1.0)
                if not self.rt.check(p.closed(sig), "closes-on-entry", f"the movement is past signal {sig} "
                                     f"(approach clear, in {s}): the signal still shows {p.aspect(sig)}", p):
                    return
            else:
                p.do(f"vacate {secs[i - 1]}")
                p.run(1.0)
            if i == len(secs) - 1 and r.category == "receiving":
                break  # the train stops on the receiving track
            behind = [x for x in secs[:i] if p.sim.section_state(x) != "free"]
            ahead = [x for x in secs[i + 1:] if p.sim.section_state(x) != "locked"]
            if not self.rt.check(not behind and not ahead, "sequential-release",
                                 f"train in {s}: " + "; ".join(
                                     ([f"not released behind it: {', '.join(behind)}"] if behind else [])
                                     + ([f"not locked ahead of it: {', '.join(ahead)}"] if ahead else [])), p):
                return
        if r.category != "receiving":
            if beyond is not None:
                p.do(f"occupy {beyond}")
                p.run(1.0)
            p.do(f"vacate {secs[-1]}")
            p.run(1.0)
        done = p.until(lambda: p.state(r) == "released", 5.0)
        held = [s for s in secs if p.sim.section_state(s) == "locked"]
        if not self.rt.check(done and not held, "sequential-release", f"after the train the route is {p.state(r)}"
                             + (f", still locked: {', '.join(held)}" if held else ""), p):
            return
        self.rt.check(p.closed(sig), "no-automatic-reopening", f"signal {sig} shows {p.aspect(sig)} after the "
                      "train passed", p)
        if r.overlap_sections:
            self.overlap(p)
        else:
            self.na("overlap")

    def flicker(self) -> None:
        """The three-point check (三点检查): a section that shows clear again before the next one is occupied (a
        track circuit flickering under the train, a vehicle in a dead zone) is not released."""
        r = self.r
        if len(r.sections) < 2 or not r.approach:
            self.na("three-point check (one section)")
            return
        p = self.approached()
        if p is None:
            return
        first, second = r.sections[0], r.sections[1]
        p.do(f"occupy {first}")
        p.run(1.0)
        for a in r.approach:
            p.do(f"vacate {a}")
        p.run(1.0)
        p.do(f"vacate {first}")
        p.run(1.0)
        self.rt.check(p.sim.section_state(first) == "locked", "three-point-check",
                      f"{first} was occupied and showed clear again with {second} still clear: it was released "
                      f"({p.sim.section_state(first)}); it must wait for the next section to be occupied", p)

    def overlap(self, p: Probe) -> None:
        r = self.r
        held = [s for s in r.overlap_sections if p.sim.section_state(s) != "locked"]
        if not self.rt.check(not held, "overlap", f"the train stands on {r.sections[-1]}: overlap sections not "
                             f"locked: {', '.join(held)}", p):
            return
        rivals = [o for o in self.ctx.table.routes.values() if o.signal != r.signal and o.signal != r.end_signal
                  and set(o.sections) & set(r.overlap_sections)]
        for o in rivals[:2]:
            result = p.do(route_line(o))
            self.rt.check(not result.ok, "overlap", f"'{route_line(o)}' over the overlap of {r.id} while it is held: "
                          f"{result.message}", p)
            if result.ok:
                p.do(f"cancel {o.signal}")
        self.through_while_held(p)
        time = overlap_time(self.st, self.ctx.rules, r.end_signal or "")  # the published rule, not the table's
        p.run(time - 3.0)
        held = [s for s in r.overlap_sections if p.sim.section_state(s) != "locked"]
        if not self.rt.check(not held, "overlap", f"overlap released early ({', '.join(held)}), before its "
                             f"{time:g} s", p):
            return
        p.run(4.0)
        held = [s for s in r.overlap_sections if p.sim.section_state(s) == "locked"]
        held += [f"turnout {t.id}" for t in r.overlap_turnouts if p.sim.turnout_state(t.id)[1]]
        self.rt.check(not held, "overlap", f"{time:g} s after the train stopped the overlap still holds "
                      f"{', '.join(held)}", p)

    def through_while_held(self, p: Probe) -> None:
        """With the train on the receiving track and the overlap held for it, each onward departure that continues
        over the overlap in the same direction (the train's own departure) may be set: it is no enemy. Tried on a
        copy of the run so far (the same lines on a fresh probe), so the overlap's own timer is judged untouched."""
        r = self.r
        onward = [o for o in self.ctx.table.routes.values() if o.kind == "train" and o.signal == r.end_signal
                  and o.direction is r.direction and o.id not in r.conflicts]
        for o in onward[:2]:
            q = Probe(self.ctx)
            for line in p.script():
                if line.startswith("run "):
                    q.run(_seconds(line))
                else:
                    q.do(line)
            prepare(q, o)
            result = q.do(route_line(o))
            q.until(partial(q.is_open, o.signal), 40.0)
            self.rt.check(result.ok and q.is_open(o.signal), "overlap", f"'{route_line(o)}' continuing over the "
                          f"overlap of {r.id} while it is held for the train: {result.message}; {q.blocker(o)}", q)

    def overlap_fault_release(self) -> None:
        """Section fault release (区故解) of an overlap section, as of any section the route locks: refused while the
        signal is open with a train approaching (its overlap turnouts stay locked); with the train running in, held
        for as long as it is in the route (the overlap is there for that train), whatever the delay."""
        r = self.r
        if not r.overlap_sections:
            return
        p = self.approached()
        if p is None:
            return
        for s in r.overlap_sections:
            result = p.do(f"fault-release {s}")
            p.run(0.5)
            loose = [t.id for t in r.overlap_turnouts if not p.sim.turnout_state(t.id)[1]]
            self.rt.check(not result.ok and p.sim.section_state(s) == "locked" and not loose, "fault-release",
                          f"'fault-release {s}' (the overlap) under the open signal {r.signal} with a train "
                          f"approaching: {result.message}" + (f"; turnouts {', '.join(loose)} unlocked" if loose
                                                               else ""), p)
        p.do(f"occupy {r.sections[0]}")  # the train enters and runs towards the overlap
        p.run(1.0)
        for a in r.approach:
            p.do(f"vacate {a}")
        p.run(1.0)
        first = r.overlap_sections[0]
        result = p.do(f"fault-release {first}")
        delay = self.ctx.rules.section_fault_release_s
        p.run(delay + 5.0)
        self.rt.check(result.ok and p.sim.section_state(first) == "locked", "fault-release",
                      f"'fault-release {first}' (the overlap) with the train running in: {result.message}; the "
                      f"overlap is {p.sim.section_state(first)} {delay + 5:g} s later, the train still in the route "
                      "(the overlap is there for it)", p)

    def fault_release(self) -> None:
        """Section fault release (区故解) of the locked clear sections ahead of a train that entered the route: refused
        on a station track and on the occupied section; delayed by the rule set's time while the movement is still on
        its way to them (it stands in the route), and at once once it has left the route."""
        r = self.r
        if len(r.sections) < 2:
            self.na("fault-release (one section)")
            return
        p = self.approached()
        if p is None:
            return
        p.do(f"occupy {r.sections[0]}")
        p.run(1.0)
        for a in r.approach:
            p.do(f"vacate {a}")
        p.run(1.0)
        result = p.do(f"fault-release {r.sections[0]}")
        self.rt.check(not result.ok, "fault-release", f"'fault-release {r.sections[0]}' of the occupied section "
                      f"was accepted: {result.message}", p)
        ahead = [s for s in r.sections[1:] if not self.st.is_station_track(s)]
        for s in r.sections[1:]:
            result = p.do(f"fault-release {s}")
            if self.st.is_station_track(s):
                self.rt.check(not result.ok and p.sim.section_state(s) == "locked", "fault-release",
                              f"'fault-release {s}' on a station track: {result.message}", p)
            else:
                self.rt.check(result.ok and p.sim.section_state(s) == "locked", "fault-release",
                              f"'fault-release {s}' ahead of the train standing in {r.sections[0]}: "
                              f"{result.message}; the section is {p.sim.section_state(s)}, not locked on for the "
                              "delay", p)
        delay = fault_release_delay(self.ctx.rules, r.kind)
        p.run(delay - 5.0)
        early = [s for s in ahead if p.sim.section_state(s) != "locked"]
        self.rt.check(not early, "fault-release", f"section fault release ahead of the train released "
                      f"{', '.join(early)} before {delay:g} s", p)
        p.run(10.0)
        late = [s for s in ahead if p.sim.section_state(s) != "free"]
        self.rt.check(not late, "fault-release", f"section fault release ahead of the train: {', '.join(late)} "
                      f"still not free {delay + 5:g} s after it was given", p)
        q = Probe(self.ctx)  # the movement has left the route: released at once
        if not self.rt.opened(q, "opens"):
            return
        for step in (*(f"occupy {a}" for a in r.approach), f"occupy {r.sections[0]}",
                     *(f"vacate {a}" for a in r.approach), f"vacate {r.sections[0]}"):
            q.do(step)
            q.run(1.0)
        for s in ahead:
            result = q.do(f"fault-release {s}")
            self.rt.check(result.ok and q.sim.section_state(s) == "free", "fault-release",
                          f"'fault-release {s}' with the movement gone from the route: {result.message}; the section "
                          f"is {q.sim.section_state(s)}", q)

    # ---- guide, doors --------------------------------------------------------------------------------------------
    def guide_route(self) -> None:
        """A guide route (引导进路锁闭) over a red band on the receiving track: selected and locked without looking at
        its track circuits, the guide aspect shown once its turnouts are in position, every turnout locked."""
        r, sig = self.r, self.st.signals[self.r.signal]
        guide = self.ctx.rules.aspects.guide
        if r.kind != "train" or r.category != "receiving" or r.overlap_alternative or not \
                self.ctx.rules.aspects.can_show(guide, [lamp.value for lamp in sig.lamps]):
            self.na("guide route")
            return
        p = Probe(self.ctx)
        faulty = r.sections[-1]
        p.do(f"occupy {faulty}")
        refused = p.do(route_line(r))
        result = p.do(" ".join(["guide", *r.buttons]))
        p.until(lambda: p.aspect(r.signal) == guide, 40.0)
        loose = [t.id for t in r.all_turnouts if not p.sim.turnout_state(t.id)[1]]
        self.rt.check(not refused.ok and result.ok and p.aspect(r.signal) == guide and not loose, "guide",
                      f"'{' '.join(['guide', *r.buttons])}' with {faulty} showing occupied: {result.message}; the "
                      f"signal shows {p.aspect(r.signal)}" + (f"; turnouts not locked: {', '.join(loose)}" if loose
                                                              else "") + ("" if not refused.ok else
                                                                          f"; '{route_line(r)}' was accepted"), p)

    def guide(self) -> None:
        """Guide aspect HB (引导) over a track-circuit fault on the route: shown with the route locked, closed once
        the guided train has passed."""
        r, sig = self.r, self.st.signals[self.r.signal]
        guide = self.ctx.rules.aspects.guide
        if r.kind != "train" or sig.kind not in (SignalKind.home, SignalKind.route) or \
                not self.ctx.rules.aspects.can_show(guide, [lamp.value for lamp in sig.lamps]) or len(r.sections) < 2:
            self.na("guide")
            return
        p = Probe(self.ctx)
        if not self.rt.opened(p, "opens"):
            return
        faulty = r.sections[-1]
        p.do(f"occupy {faulty}")
        p.run(1.0)
        if r.turnouts:  # a guide route still needs every turnout in position with its indication
            t = r.turnouts[0].id
            p.do(f"fault no-indication {t}")
            p.run(1.0)
            result = p.do(f"guide {r.signal}")
            p.run(1.0)
            self.rt.check(not result.ok and not p.is_open(r.signal), "guide", f"'guide {r.signal}' with turnout {t} "
                          f"of the route without indication: {result.message}; the signal shows "
                          f"{p.aspect(r.signal)}", p)
            p.do(f"repair no-indication {t}")
            p.run(1.0)
        result = p.do(f"guide {r.signal}")
        p.run(1.0)
        if not self.rt.check(result.ok and p.aspect(r.signal) == guide, "guide",
                             f"'guide {r.signal}' with {faulty} showing occupied: {result.message}; the signal "
                             f"shows {p.aspect(r.signal)}", p):
            return
        self.guide_unused(faulty)
        loose = [t.id for t in r.all_turnouts if not p.sim.turnout_state(t.id)[1]]
        self.rt.check(not loose, "guide", f"turnouts not locked under the guide aspect: {', '.join(loose)}", p)
        doors = door_platforms(self.st, self.r)
        if doors:  # the guide aspect checks the screen doors like any other: a door failing closes it
            q = Probe(self.ctx)
            if self.rt.opened(q, "opens"):
                q.do(f"occupy {faulty}")
                q.run(1.0)
                q.do(f"guide {r.signal}")
                q.run(1.0)
                q.do(f"fault psd-stuck {doors[0]}")
                q.run(1.0)
                self.rt.check(q.aspect(r.signal) != guide, "guide", f"screen door of {doors[0]} failed open under "
                              f"the guide aspect: {r.signal} still shows {guide}", q)
        for a in r.approach:
            p.do(f"occupy {a}")
        p.run(1.0)
        self.rt.check(p.aspect(r.signal) == guide, "guide", f"the guided train approaches {r.signal}: it shows "
                      f"{p.aspect(r.signal)}", p)
        p.do(f"occupy {r.sections[0]}")
        p.run(0.5)
        self.rt.check(p.closed(r.signal), "guide", f"the guided train entered {r.sections[0]} (its tail still in the "
                      f"approach): {r.signal} still shows {p.aspect(r.signal)}", p)

    def guide_unused(self, faulty: str) -> None:
        """A guide aspect no train comes to closes by itself after the rule set's ``guide_close_s`` (the time from
        the rule data, not from the interlocking)."""
        r, guide = self.r, self.ctx.rules.aspects.guide
        q = Probe(self.ctx)
        if not self.rt.opened(q, "opens"):
            return
        q.do(f"occupy {faulty}")
        q.run(1.0)
        q.do(f"guide {r.signal}")
        limit = self.ctx.rules.guide_close_s
        q.run(limit + 2.0)
        self.rt.check(q.aspect(r.signal) != guide, "guide", f"the guide aspect of {r.signal} still lit "
                      f"{limit + 2.0:g} s after it was given, with no train coming (it closes after {limit:g} s)", q)

def throat_checks(ctx: Context) -> None:
    """Guide total lock (引导总锁闭) of each throat: every turnout of the throat locked (individual operation
    refused), the guide aspect HB without a route, and everything free again after the unlock."""
    st = ctx.station
    for throat, turnouts in ctx.table.throats.items():
        subject = f"throat {throat}"
        p = Probe(ctx)
        result = p.do(f"guide-lock {throat}")
        if not ctx.record(result.ok, "guide-lock", subject, f"'guide-lock {throat}': {result.message}", p):
            continue
        for t in turnouts:
            pos = p.sim.turnout_state(t)[0] or "normal"
            result = p.do(f"throw {t} {other(pos)}")
            ctx.record(not result.ok, "guide-lock", subject, f"turnout {t} could be thrown under guide total lock: "
                       f"{result.message}", p)
        sig = st.signals.get(throat)
        guide = ctx.rules.aspects.guide
        if sig is not None and ctx.rules.aspects.can_show(guide, [lamp.value for lamp in sig.lamps]):
            result = p.do(f"guide {throat}")
            p.run(1.0)
            ctx.record(result.ok and p.aspect(throat) == guide, "guide-lock", subject,
                       f"'guide {throat}' under guide total lock: {result.message}; the signal shows "
                       f"{p.aspect(throat)}", p)
            for pl in _bordering_platforms(ctx, throat):
                # the way is not known under guide total lock: a door failing at any platform the throat leads
                # to closes the guide aspect, and it cannot be given again while the door is open
                p.do(f"fault psd-stuck {pl}")
                p.run(1.0)
                again = p.do(f"guide {throat}")
                ctx.record(p.aspect(throat) != guide and not again.ok, "guide-lock", subject,
                           f"screen door of {pl} failed open under guide total lock: {throat} shows "
                           f"{p.aspect(throat)}, 'guide {throat}' {'accepted' if again.ok else 'refused'}", p)
                p.do(f"repair psd-stuck {pl}")
                p.run(1.0)
            p.do(f"cancel {throat}")
        result = p.do(f"guide-unlock {throat}")
        loose = result.ok and not any(p.sim.turnout_state(t)[1] for t in turnouts)
        ctx.record(loose, "guide-lock", subject, f"'guide-unlock {throat}': {result.message}", p)


def _bordering_platforms(ctx: Context, signal: str) -> list[str]:
    """Platforms with screen doors whose track borders the throat ``signal`` leads into, or lies in it
    (:func:`.lines.reach`)."""
    inner, border = reach(ctx, signal)
    return [pl.id for pl in ctx.station.model.platforms if pl.screen_doors and pl.section in inner | border]


def _seconds(line: str) -> float:
    """The time of a probe's 'run' line ('run 2s', 'run 250ms')."""
    value = line.split()[1]
    return float(value[:-2]) / 1000.0 if value.endswith("ms") else float(value[:-1])
