"""What the field and the trains keep from one cycle to the next never makes them see differently: the sections a
train shunts (worked out from its ends and the boundaries), a circuit left alone while a standard shunt only moves on
it, the shunts listed only when asked, and the way ahead kept while the turnouts lie as they lay. Each is checked
against the uncached path, every wheelset placed one by one at every update, through faults injected on occupied
sections, switch K, loose wheelsets and axle counters."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
from conftest import Driver

from liansuo.bench.trains import _Dispatcher, train_slots
from liansuo.circuits.shunts import Listed
from liansuo.circuits.trackcircuits import SectionCircuit, build_circuit
from liansuo.interlocking.table.build import build_table
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains.consist import Consist
from liansuo.simulation.trains.fleet import WHEEL_OHM
from liansuo.simulation.trains.movement import Position
from liansuo.simulation.trains.wheelsets import footprint
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text
from liansuo.stations.schema import CircuitType, Direction

Shunts = dict[str, list[tuple[float, float]]]
DANXIAN = Path(__file__).resolve().parent.parent / "src" / "liansuo" / "examples" / "stations" / "danxian.yaml"


class Uncached:
    """Every track circuit as the field updated it before it kept anything: at each ``set_axles`` every wheelset of
    every train placed one by one (``Track.shunts``) and a circuit updated whenever its list of shunts changed; when
    the field updates a circuit on its own (a fault, switch K, an axle reset), the same update with the same faults.
    Wired into a simulation's field, it checks after each update that every relay is the same, and every few
    updates every voltage and wheelset count; each train's sections and way ahead against a fresh computation."""

    def __init__(self, sim: Simulation, every: int = 7) -> None:
        self.sim = sim
        f = sim.field
        self.circuits = {s: build_circuit(sim.station, s, f.geometry.section_length[s]) for s in sim.station.sections}
        for c in self.circuits.values():
            c.update([])
        self.lists: Shunts = {}
        self.every = every
        self.updates = 0
        self.shunted_up = 0  # relays up under a wheelset: a fault hid it (the checks then saw a fault at work)
        real_set, real_re = f.set_axles, f._reevaluate

        def set_axles(axles: Any, groups: Any = None) -> None:
            real_set(axles, groups)
            self._set_axles(groups or {})

        def reevaluate(section: str, *, if_changed: bool = False) -> None:
            real_re(section, if_changed=if_changed)
            if not if_changed:
                self._update(section)
                self.check()

        f.set_axles = set_axles  # type: ignore[method-assign]
        f._reevaluate = reevaluate  # type: ignore[method-assign]

    def _set_axles(self, groups: Any) -> None:
        sim, f = self.sim, self.sim.field
        lists = f.geometry.shunts_of(f.axles)
        for tr in sim.fleet.trains.values():
            mine = sim.fleet.track.shunts(tr.pos, tr.consist.axle_offsets_m, f.geometry, WHEEL_OHM)
            assert groups[tr.name].sections == frozenset(mine), tr.name  # the sections, exactly
            for sec, lst in mine.items():
                lists.setdefault(sec, []).extend(lst)
            fresh = Position(list(tr.pos.moves), tr.pos.front_s)  # nothing kept on it
            assert sim.fleet.track.ahead(tr.pos, 3000.0) == sim.fleet.track.ahead(fresh, 3000.0)
            assert sim.fleet.track.moves_ahead(tr.pos, 3000.0) == sim.fleet.track.moves_ahead(fresh, 3000.0)
        old, self.lists = self.lists, lists
        for sec in set(old) | set(lists):
            if old.get(sec) != lists.get(sec):
                self._update(sec)
        self.check()

    def _update(self, section: str) -> None:
        mine, real = self.circuits[section], self.sim.field.circuits[section]
        mine.faults = copy.deepcopy(real.faults)
        mine.k_switch = real.k_switch
        if real.counter is not None and mine.counter is not None:
            mine.counter.error = real.counter.error
        mine.update(self.lists.get(section, []))

    def check(self) -> None:
        self.updates += 1
        field = self.sim.field
        for sec, mine in self.circuits.items():
            real = field.circuits[sec]
            assert real.up == mine.up, (sec, self.sim.t)
            if real.up and self.lists.get(sec):
                self.shunted_up += 1
            if self.updates % self.every == 0:
                assert field.shunts_on(sec) == self.lists.get(sec, []), sec
                assert (real.voltage, real.cab_current_mA, real.inside) == (mine.voltage, mine.cab_current_mA,
                                                                           mine.inside), (sec, self.sim.t)


def test_a_hub_full_of_trains_with_faults_injected_on_occupied_sections_mid_run() -> None:
    station = load_text(generate_hub(20, 8), "<hub20>")
    table = build_table(station)
    sim = Simulation(station, table=table)
    shadow = Uncached(sim)
    dispatchers = [_Dispatcher(sim, f"B{i + 1}", r, d) for i, (r, d) in enumerate(train_slots(table, 4))]
    faults = {150: "poor-shunt {} ohm=30", 300: "broken-rail {}", 450: "low-ballast {} ohm_km=0.05",
              600: "poor-shunt {} ohm=2", 750: "insulation {}"}
    injected: list[str] = []
    for cycle in range(1200):
        if cycle % 4 == 0:
            for d in dispatchers:
                d.tick()
        if cycle in faults and sim.fleet.trains:
            tr = sim.fleet.trains[sorted(sim.fleet.trains)[0]]
            occupied = sorted(sim.fleet.sections_of(tr))
            if faults[cycle].startswith("insulation"):
                target = next(t for t, s in station.turnout_section.items() if s in occupied) \
                    if any(s in occupied for s in station.turnout_section.values()) else None
            else:
                target = occupied[0]
            if target is not None:
                line = faults[cycle].format(target)
                assert sim.command(f"fault {line}").ok, line
                injected.append(line)
        if cycle in (300, 450, 600, 750, 900):  # each fault stays 150 cycles, then is repaired under the trains
            for line in injected:
                kind, target = line.split()[:2]
                assert sim.command(f"repair {kind} {target}").ok
            injected.clear()
        if cycle == 500 and sim.fleet.trains:  # switch K and loose wheelsets on a section a train is on
            tr = sim.fleet.trains[sorted(sim.fleet.trains)[-1]]
            sec = sim.fleet.sections_of(tr)[0]
            track = station.section_tracks[sec][0]
            lo, hi = station.track_span(track)
            assert sim.command(f"occupy {sec}").ok and sim.command(f"axles loose {track} {(lo + hi) / 2:g}").ok
        if cycle == 540:
            assert sim.command(f"vacate {sec}").ok and sim.command("axles loose clear").ok
        sim.step()
    assert sum(d.departures for d in dispatchers) >= 2
    assert shadow.updates > 1000
    assert shadow.shunted_up > 0  # a poor shunt did hide a wheelset: the faulty path was exercised


@pytest.mark.parametrize("name, lines", [
    ("jiaopei", ["route X XI", "train T1 at IAG mode=signal length=200", "run 2min", "route XI S", "run 5s",
                 "block-line SL request", "run 3min", "train T2 at IG dir=up length=100", "drive T2 3",
                 "run 90s", "stop T2", "run 10s", "reverse T2", "drive T2 5", "run 60s"]),
    ("gaotie", ["train T1 at IAG length=200", "drive T1 8", "run 3min", "drive T1 20", "run 2min"]),
    ("depot", ["train L1 at 1G kind=shunter length=60", "drive L1 4", "run 2min"]),
])
def test_bundled_stations_dead_zones_tags_and_slow_creeping(name: str, lines: list[str]) -> None:
    """Creeping trains stop with a wheelset on every kind of edge: dead zones (jiaopei, gaotie on ZPW-2000A),
    balises and RFID tags (depot)."""
    sim = Simulation(name)
    shadow = Uncached(sim, every=3)
    Driver(sim)(*lines)
    assert shadow.updates > 100


def test_axle_counters_count_every_wheelset_as_it_moves() -> None:
    text = DANXIAN.read_text(encoding="utf-8").replace("{id: 2DG, type: 25hz}", "{id: 2DG, type: axle_counter}")
    sim = Simulation(load_text(text, "danxian-counted.yaml"))
    assert any(s.type is CircuitType.axle_counter for s in sim.station.sections.values())
    shadow = Uncached(sim, every=2)
    Driver(sim)("train T2 at IIAG length=60 mode=signal", "run 1s", "fault axle-miscount IIAG", "run 1s",
                "axle-reset IIAG", "run 1s", "train T1 at IG length=100", "drive T1 10", "run 90s")
    assert shadow.updates > 50


@pytest.mark.parametrize("offsets", [(0.5,), (0.5, 4.5), (4.5, 0.5, 2.0), (0.0, 0.0, 3.0)])
def test_the_sections_of_any_wheelsets_creeping_over_every_joint(offsets: tuple[float, ...]) -> None:
    """A wheelset alone (whose section disappears in a dead zone), two, unordered ones (placed one by one), two at
    the same place: moved on a few centimetres at a time, the sections and how far they hold are never wrong."""
    sim = Simulation("jiaopei")
    track = sim.fleet.track
    geometry = sim.field.geometry
    pos = track.place("IAG", Direction.down, max(offsets) + 1.0, 1.0)
    assert not isinstance(pos, str)
    fp = footprint(track, pos, offsets, geometry)
    for _ in range(40_000):
        whole = frozenset(track.shunts(pos, offsets, geometry, WHEEL_OHM))
        if not fp.holds(pos, offsets):
            fp = footprint(track, pos, offsets, geometry, fp)
        assert fp.sections == whole, (pos.moves[-1], pos.front_s)
        _, stop = track.advance("t", pos, 0.037, lambda kind, text: None)
        if stop or pos.moves[-1][0] == "@outside":
            break
        track.trim(pos, max(offsets) + 1.0)
    assert pos.moves[-1][0] != "IAG"  # it went a long way


def test_a_train_of_unordered_wheelsets_is_seen_the_same() -> None:
    sim = Simulation("jiaopei")
    shadow = Uncached(sim, every=1)
    fleet = sim.fleet
    assert fleet.place("U1", Consist((30.0, 1.0, 15.0, 2.0), 32.0, 50.0, 40.0), "IAG", Direction.down, "manual") == ""
    Driver(sim)("drive U1 15", "run 60s")
    assert shadow.updates > 200


def test_the_way_ahead_follows_the_turnouts_as_they_are_thrown() -> None:
    """The way kept on a train's position is dropped when a turnout it passes facing moves: while it moves the way
    ends there, then it follows the other leg."""
    d = Driver(Simulation("jiaopei"))
    d("train T1 at IAG mode=signal length=100 back=100")
    fleet = d.sim.fleet
    tr = fleet.trains["T1"]

    def both() -> tuple[Any, Any]:
        fresh = Position(list(tr.pos.moves), tr.pos.front_s)
        kept = (fleet.track.ahead(tr.pos, 2000.0), fleet.track.moves_ahead(tr.pos, 2000.0))
        assert kept == (fleet.track.ahead(fresh, 2000.0), fleet.track.moves_ahead(fresh, 2000.0))
        return kept

    first = both()
    ways = {str(first)}
    for _ in range(3):
        for position in ("reverse", "normal"):
            d(f"throw 1 {position}")
            for _ in range(40):  # the switch machine moves over a few seconds
                d.sim.step()
                ways.add(str(both()))
    assert len(ways) >= 3  # along the normal leg, ended at the moving turnout, along the reverse leg


def test_a_circuit_reads_a_list_and_the_fields_live_view_alike() -> None:
    sim = Simulation("jiaopei")
    d = Driver(sim)
    d("train T1 at IG length=100")
    real = sim.field.circuits["IG"]
    listed = SectionCircuit("IG", real.kind, real.length_m, real.model)
    listed.update(sim.field.shunts_on("IG"))
    assert real.shunted_down and listed.shunted_down
    assert (real.up, real.voltage, real.inside) == (listed.up, listed.voltage, listed.inside)
    d("fault poor-shunt IG ohm=50")
    assert not real.shunted_down  # a fault: solved in full from now on
    listed.faults.poor_shunt_ohm = 50.0
    listed.update(Listed(sim.field.shunts_on("IG")))
    assert (real.up, real.voltage, real.inside) == (listed.up, listed.voltage, listed.inside)
