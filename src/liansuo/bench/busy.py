"""The busy scenario of the benchmark: up to 20 train routes that can be set at once, each set, opened and traversed
over and over by an imaginary train that occupies and vacates its sections (the teaching base's switch K)."""

from __future__ import annotations

from liansuo.interlocking.table.build import InterlockingTable, Route
from liansuo.simulation.sim import Simulation

BUSY_ROUTES = 20
DWELL_CYCLES = 4  # cycles a train head or tail spends before moving on by one section (1 s at 250 ms)


def _uses_beyond(r: Route) -> bool:
    """A route's last section releases once the train is beyond it, except on a receiving track."""
    return r.beyond is not None and r.category != "receiving"


def _footprint(r: Route) -> set[str]:
    """Every section a traversal of ``r`` occupies or the route locks."""
    return set(r.all_sections) | set(r.approach) | ({r.beyond} if r.beyond and _uses_beyond(r) else set())


def busy_routes(table: InterlockingTable, limit: int = BUSY_ROUTES) -> list[Route]:
    """Up to ``limit`` routes that can be set at once and traversed without touching each other.

    Greedy over receiving routes, then transfers, departures onto lines without a 64D block (a 64D departure would
    also need the block line worked) and shunting routes, shortest routes first."""
    order = {"receiving": 0, "transfer": 1, "departure": 2, "shunting": 3}
    candidates = [r for r in table.routes.values() if r.category in order
                  and not (r.exit_link and any(lk.id == r.exit_link and lk.kind.value == "64d"
                                               for lk in table.station.model.links))]
    candidates.sort(key=lambda r: (order[r.category], len(r.sections), r.id))
    chosen: list[Route] = []
    used: set[str] = set()
    signals: set[str] = set()
    for r in candidates:
        if len(chosen) >= limit:
            break
        fp = _footprint(r)
        if r.signal in signals or fp & used or any(c.id in r.conflicts for c in chosen):
            continue
        chosen.append(r)
        used |= fp
        signals.add(r.signal)
    return chosen


class Traversal:
    """Sets one route again and again and moves an imaginary train through it by occupying and vacating sections."""

    def __init__(self, sim: Simulation, route: Route) -> None:
        self.sim = sim
        self.route = route
        seq = list(route.approach) + list(route.sections)
        if route.beyond and _uses_beyond(route):
            seq.append(route.beyond)
        self.seq = list(dict.fromkeys(seq))
        verb = "route" if route.kind == "train" else "shunt"
        self.command = " ".join([verb, *route.buttons])
        self.state = "idle"
        self.head = self.tail = -1
        self.next_tick = 0
        self.since = 0
        self.settings = 0
        self.traversals = 0
        self.stalls = 0
        self.opened = False

    def tick(self, cycle: int) -> None:
        sim = self.sim
        if self.state == "idle":
            if (cycle >= self.next_tick and sim.route_state(self.route.id) == "released"
                    and sim.command(self.command).ok):
                self.settings += 1
                self.state, self.since = "setting", cycle
            return
        if self.state == "setting":
            if sim.route_state(self.route.id) == "open":
                self.opened = True
                self.head = self.tail = 0
                sim.field.occupy(self.seq[0])
                self.state, self.next_tick, self.since = "moving", cycle + DWELL_CYCLES, cycle
            elif cycle - self.since > 400:  # 100 s without opening: count it and start again
                self._stall()
            return
        if cycle < self.next_tick:
            return
        last = len(self.seq) - 1
        if self.tail < self.head:
            sim.field.vacate(self.seq[self.tail])
            self.tail += 1
        elif self.head < last:
            self.head += 1
            sim.field.occupy(self.seq[self.head])
        elif sim.route_state(self.route.id) == "released":
            sim.field.vacate(self.seq[self.head])
            self.traversals += 1
            self.state, self.next_tick = "idle", cycle + DWELL_CYCLES
            return
        elif cycle - self.since > 4 * DWELL_CYCLES * (last + 2) + 400:
            self._stall()
            return
        self.next_tick = cycle + DWELL_CYCLES

    def _stall(self) -> None:
        """The route did not open or release as expected: record it, clear the field and release the route."""
        self.stalls += 1
        for s in self.seq:
            self.sim.field.vacate(s)
        if self.sim.route_state(self.route.id) != "released":
            self.sim.command(f"release {self.route.signal}")
        self.state, self.next_tick = "idle", 0
