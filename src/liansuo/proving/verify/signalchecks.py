"""The interlocking test of one route, its signal: each lamp of the aspect it shows darkened in turn, the platform
screen doors, and the aspects it shows with the onward routes set (and the block sections ahead varied)."""

from __future__ import annotations

from functools import partial

from liansuo.interlocking.aspects import is_open
from liansuo.interlocking.table.build import Route
from liansuo.proving.verify.probe import Failure, Probe, against_running, open_route, route_line
from liansuo.proving.verify.routecheck import RouteItems
from liansuo.stations.schema import Link
from liansuo.stations.station import Station


def door_platforms(st: Station, r: Route) -> list[str]:
    """The platforms with screen doors beside the route or in rear of its signal."""
    rear = st.signal_rear_track(r.signal)
    rear_section = st.tracks[rear].section if rear else None
    return [pl.id for pl in st.model.platforms if pl.screen_doors
            and (pl.section in r.sections or pl.section == rear_section)]


class SignalChecks(RouteItems):
    """The signal's items: its lamps, the screen doors, the aspects with the onward routes set."""

    def run(self) -> None:
        self.lamps()
        self.doors()
        self.aspects()

    def lamps(self) -> None:
        """A lamp of the aspect shown goes dark (both filaments): the interlocking commands a more restrictive
        aspect (the rule set's downgrade), never keeps the one it can no longer show."""
        r = self.r
        p = Probe(self.ctx)
        if not self.rt.opened(p, "opens"):
            return
        shown = p.aspect(r.signal)
        lamps = [lamp for lamp in self.ctx.rules.lamps.get(shown, [])
                 if lamp in {x.value for x in self.st.signals[r.signal].lamps}]
        rank = self.ctx.rules.aspects.rank_of
        for i, lamp in enumerate(lamps):  # each lamp of the aspect, the second yellow of UU as much as the first
            if i:
                p = Probe(self.ctx)
                if not self.rt.opened(p, "opens"):
                    return
            p.do(f"fault filament {r.signal} lamp={lamp} which=both")
            p.run(1.0)
            after = p.aspect(r.signal)
            if not self.rt.check(after != shown and rank(after) <= rank(shown), "lamp-proving",
                                 f"lamp {lamp} of {r.signal} dark while it showed {shown}: the interlocking commands "
                                 f"{after}", p):
                return

    def doors(self) -> None:
        """Platform screen doors (站台门): a door stuck open keeps the signal closed; the bypass (互锁解除) lets it
        open; a door failing while the signal is open closes it."""
        r = self.r
        platforms = door_platforms(self.st, self.r)
        if not platforms:
            self.na("doors")
            return
        for pl in platforms:
            p = Probe(self.ctx)
            p.do(f"fault psd-stuck {pl}")
            open_route(p, r, timeout_s=20.0)
            self.rt.check(p.closed(r.signal) and p.state(r) == "locked", "doors",
                          f"screen door of {pl} stuck open: signal {r.signal} shows {p.aspect(r.signal)}, route "
                          f"{p.state(r)}", p)
            p.do(f"fault psd-bypass {pl}")
            ok = p.until(partial(p.is_open, r.signal), 5.0)
            self.rt.check(ok, "doors", f"with {pl}'s interlock bypass on, signal {r.signal} stays closed: "
                          f"{p.blocker(r)}", p)
            p = Probe(self.ctx)
            if not self.rt.opened(p, "opens"):
                continue
            p.do(f"fault psd-stuck {pl}")
            p.run(1.0)
            self.rt.check(p.closed(r.signal), "doors", f"screen door of {pl} failed open: signal {r.signal} still "
                          f"shows {p.aspect(r.signal)}", p)

    # ---- aspects with the onward routes ---------------------------------------------------------------------------
    def aspects(self) -> None:
        """Set each onward route from the end signal (and vary the block sections ahead): every aspect shown is one
        the table lists; the ones shown are reported. USU degrades to UU when an electronic flasher fails."""
        r = self.r
        if r.kind != "train":
            return
        table = self.ctx.table
        onward = [o for o in table.routes.values()
                  if o.kind == "train" and r.end_signal and o.signal == r.end_signal and o.id not in r.conflicts]
        if r.category == "departure":
            p = Probe(self.ctx)
            if self.rt.opened(p, "opens"):
                self.vary_blocks(p, r.exit_link, r)
        for o in onward:
            q = Probe(self.ctx)  # a through train: the departure is usually set first, so the home signal shows L
            self.rt.check(open_route(q, o, r), "onward", f"'{route_line(o)}', then '{route_line(r)}' (the onward "
                          f"route first): {q.blocker(r)}; {q.blocker(o)}", q)
            p = Probe(self.ctx)
            if not open_route(p, r, o):
                self.rt.check(False, "onward", f"'{route_line(r)}' with onward route {o.id}: {p.blocker(r)}; "
                              f"{p.blocker(o)}", p)
                continue
            self.seen(p)
            if p.aspect(r.signal) in self.ctx.rules.aspects.flashing:
                self.flasher(p)
            if o.category == "departure" and self._automatic(o.exit_link):
                p = Probe(self.ctx)
                if open_route(p, r, o):
                    self.vary_blocks(p, o.exit_link, o)

    def seen(self, p: Probe) -> None:
        r = self.r
        shown = p.aspect(r.signal)
        if is_open(shown):
            self.rt.res.aspects_seen.add(shown)
        self.rt.check(shown in r.aspects, "aspect", f"signal {r.signal} shows {shown}; the table gives "
                      f"{'/'.join(r.aspects)}", p)

    def vary_blocks(self, p: Probe, link_id: str | None, departure: Route) -> None:
        """Occupy the third, then the second block section beyond a departure: the departure signal shows LU, then U
        (four-aspect automatic block); the route under test follows."""
        link = self._automatic(link_id)
        if link is None:
            return
        signal = departure.signal
        if against_running(self.st, link.id):
            # worked against its running direction (改方) the line is one block: any section occupied closes it
            p.do(f"occupy {link.sections[-1]}")
            p.run(1.0)
            self.rt.check(p.closed(signal), "aspect", f"line {link.id} worked against its running direction is one "
                          f"block: with {link.sections[-1]} occupied {signal} shows {p.aspect(signal)}", p)
            return
        for n, s in ((2, link.sections[2:3]), (1, link.sections[1:2])):
            if not s:
                continue
            p.do(f"occupy {s[0]}")
            p.run(1.0)
            self.seen(p)
            want = self.ctx.rules.aspects.automatic_block[n]
            self.rt.check(p.aspect(signal) == want, "aspect", f"{n} clear block section(s) beyond {signal}: it "
                          f"shows {p.aspect(signal)}, expected {want}", p)

    def _automatic(self, link_id: str | None) -> Link | None:
        """The link ``link_id`` if it is worked by automatic block (its block sections can be varied), else None."""
        link = next((lk for lk in self.st.model.links if lk.id == link_id), None)
        return link if link is not None and link.kind.value == "automatic" else None

    def flasher(self, p: Probe) -> None:
        r = self.r
        relay = self.st.signals[r.signal].flasher == "relay"
        flashing = p.aspect(r.signal)  # called when the signal shows a flashing aspect
        p.do(f"fault flasher {r.signal}")
        p.run(4.0)
        shown = p.aspect(r.signal)
        if relay:
            self.ctx.record(True, "flasher", r.id, "")
            if shown == flashing:
                self.ctx.warnings.append(Failure(
                    "flasher", r.id, f"signal {r.signal} has a relay flasher (SNJ/SNJJ): a bad SNJ contact darkens the "
                    f"flashing lamp and the interlocking keeps commanding {flashing} ('liansuo docs faults')",
                    p.script()))
            return
        want = self.ctx.rules.aspects.downgrade.get(flashing, {}).get("flasher", "")
        self.rt.check(shown == want, "flasher", f"{flashing} flasher of {r.signal} failed: the signal shows {shown}, "
                      f"expected {want}", p)
