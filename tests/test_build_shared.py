"""Every simulation of a station is built from what was worked out for the first one (``Station.derived``): the
track circuits' models and first evaluations, the field's plan, the interlocking's indices, the safety oracle's
tables. Nothing a user sees may change for it, and nothing one simulation does (a fault, an occupied section, a
thrown turnout, a train) may reach another simulation of the same station, built before it or after.
"""

from __future__ import annotations

import gc
import pickle
import weakref
from collections.abc import Callable
from dataclasses import fields
from itertools import zip_longest
from pathlib import Path

import pytest
from conftest import edit

from liansuo.circuits.field import Field, FieldChanges, field_plan
from liansuo.circuits.railgeometry import geometry_of
from liansuo.circuits.trackcircuits import SectionCircuit, build_circuit
from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.io import RelayBoard
from liansuo.interlocking.table.build import build_table
from liansuo.proving.oracle import Watch
from liansuo.rules import RuleSet, load_rules
from liansuo.simulation.sim import Simulation
from liansuo.simulation.wiring import Wiring
from liansuo.stations.loader import load, load_text
from liansuo.stations.station import Station

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "liansuo"
DANXIAN = str(PKG / "examples" / "stations" / "danxian.yaml")  # an axle-counter section on its line
MINIMAL = (PKG / "examples" / "stations" / "minimal.yaml").read_text(encoding="utf-8")

# what each station's harsh script does to its simulation: routes, occupancy, turnouts thrown, a train, and a fault of
# every kind the station has equipment for; the mild script is an ordinary working of the station
HARSH = {
    "jiaopei": [
        "route X XI", "run 4s", "occupy IAG", "run 2s", "fault broken-rail IG at=300", "fault poor-shunt 5DG ohm=2",
        "fault low-ballast 3G ohm_km=0.2", "fault insulation 5", "fault filament X lamp=U which=main",
        "fault filament S lamp=H", "fault no-indication 7", "fault obstruction 1 mm=6", "fault high-resistance 3",
        "throw 4 reverse", "fault squeezed 6", "run 12s", "vacate IAG",
        "train T1 at IIAG kind=emu", "drive T1 40", "run 20s", "cancel X", "run 5s",
    ],
    "gaotie": [
        "axles trolley t-3r 4569 4576", "route SII SFCK", "run 15s",  # a trolley in a dead zone: the oracle's hazard
        "route X XI", "run 4s", "fault capacitor IG n=3 mode=short", "fault capacitor IAG n=2 mode=open",
        "fault broken-rail X1LQG at=200", "fault flasher X", "fault psd-stuck P3", "fault psd-bypass P4",
        "fault filament S lamp=U which=main", "fault insulation 9", "occupy 4G", "throw 4 reverse", "run 10s",
        "train T1 at IAG kind=emu", "drive T1 30", "run 15s", "fault low-ballast IIG ohm_km=0.5", "run 5s",
    ],
    DANXIAN: [
        "throw 1 reverse", "run 8s", "throw 1 normal", "run 8s", "route X XI", "run 4s", "fault axle-miscount IIAG",
        "occupy IG", "fault broken-rail 3G", "fault no-indication 2", "run 10s", "train T1 at IAG", "drive T1 20",
        "run 15s",
    ],
}
MILD = {
    "jiaopei": ["route X XI", "run 5s", "occupy IAG", "run 3s", "vacate IAG", "route S S3", "run 20s"],
    "gaotie": ["route X XI", "run 5s", "route S SII", "run 5s", "occupy IAG", "run 3s", "vacate IAG", "run 10s"],
    DANXIAN: ["route X XI", "run 5s", "cancel X", "run 5s", "route S S3", "run 10s", "occupy IIAG", "run 3s",
              "vacate IIAG", "run 3s"],
}
STATIONS = list(HARSH)
Step = tuple[str, bool, str, dict[str, object]]  # a line, its answer (accepted, message) and what is seen after it


class Watched:
    """A simulation with the safety oracle watching it, read as a user reads it."""

    def __init__(self, station: Station, rules: RuleSet | None = None) -> None:
        self.sim = Simulation(station, rules=rules or load_rules())
        self.watch = Watch(self.sim)

    def seen(self) -> dict[str, object]:
        """Everything the console, the lineside and the oracle show."""
        sim, fld = self.sim, self.sim.field
        st = sim.station
        return {
            "sections": {s: sim.section_state(s) for s in st.sections},
            "relays": {s: (c.up, c.voltage, c.cab_current_mA, c.axle_count) for s, c in fld.circuits.items()},
            "turnouts": {t: (sim.turnout_state(t), sim.turnout_mark(t), fld.machines[t].rails) for t in st.turnouts},
            "aspects": {s: sim.aspect(s) for s in st.signals},
            "lamps": {s: sorted(fld.lit_lamps(s)) for s in st.signals},
            "doors": {k: fld.doors_relays(k) for k in fld.doors},
            "routes": {r: sim.route_state(r) for r in sim.interlocking.routes},
            "trains": sim.train_views(),
            "alarms": sim.alarm_texts(),
            "events": sim.event_texts(),
            "oracle": [v.text for v in [*self.watch.violations, *self.watch.hazards]],
        }

    def play(self, lines: list[str]) -> list[Step]:
        """Each line, its answer and what is seen after it."""
        out = []
        for line in lines:
            result = self.sim.command(line)
            out.append((line, result.ok, result.message, self.seen()))
        return out


@pytest.mark.parametrize("name", STATIONS)
def test_the_scripts_do_what_they_say(name: str) -> None:
    """Every command of the scripts above is accepted: a refused one would test nothing."""
    for script in (HARSH[name], MILD[name]):
        refused = [(line, msg) for line, ok, msg, _ in Watched(load(name)).play(script) if not ok]
        assert refused == []


def _long_25hz() -> Station:
    """minimal.yaml with its main track IG 2500 m long: past the 25 Hz model's range, held occupied."""
    return load_text(edit(MINIMAL, ("{id: J-XI, at: 900}", "{id: J-XI, at: 2800}"),
                          ("{id: SB, kind: boundary, at: 1200}", "{id: SB, kind: boundary, at: 3100}")), "long25.yaml")


@pytest.mark.parametrize("make", [lambda: load("jiaopei"), lambda: load("gaotie"), lambda: load(DANXIAN), _long_25hz],
                         ids=["jiaopei", "gaotie", "danxian", "long25"])
def test_a_settled_circuit_is_a_circuit_built_and_evaluated_with_nothing_on_it(make: Callable[[], Station]) -> None:
    """What a field used to do for every section of every simulation (build the circuit, evaluate it with no shunt)
    is what its shared spec gives: the same relay, voltage, cab current, count and hold."""
    station, rules = make(), load_rules()
    plan = field_plan(station, rules)
    lengths = geometry_of(station).section_length  # as the field used to measure them
    for section, spec in plan.circuits.items():
        old = build_circuit(station, section, lengths[section], rules.design.phase25hz_max_length_m)
        old.update([])
        new = SectionCircuit.settled(spec)
        assert (new.up, new.voltage, new.cab_current_mA, new.axle_count, new.inside, new.held_down, new.kind,
                new.length_m, new.shunted_down) == (old.up, old.voltage, old.cab_current_mA, old.axle_count,
                                                    old.inside, old.held_down, old.kind, old.length_m,
                                                    old.shunted_down), section


@pytest.mark.parametrize("name", STATIONS)
def test_what_one_simulation_does_never_reaches_another(name: str) -> None:
    """Simulations of one station side by side: while one goes through the harsh script (faults of every kind,
    occupied sections, turnouts thrown, a train), another works the station as usual, line for line with it, and
    each sees just what a simulation of a station loaded afresh sees; so do two going through the harsh script in
    step, and one built after all that. The same faults on the shared models give the same figures again."""
    station = load(name)
    first, second = Watched(station), Watched(station)
    assert second.seen() == Watched(load(name)).seen()
    harsh, mild = Watched(load(name)).play(HARSH[name]), Watched(load(name)).play(MILD[name])
    rough: list[Step] = []
    usual: list[Step] = []
    for rough_line, usual_line in zip_longest(HARSH[name], MILD[name]):
        rough += first.play([rough_line] if rough_line else [])
        usual += second.play([usual_line] if usual_line else [])
    assert usual == mild
    assert rough == harsh
    third, fourth = Watched(station), Watched(station)  # built after all that
    assert third.seen() == Watched(load(name)).seen()
    in_step = [(third.play([line]), fourth.play([line])) for line in HARSH[name]]
    assert [a for a, _ in in_step] == [[step] for step in harsh]
    assert [b for _, b in in_step] == [[step] for step in harsh]


@pytest.mark.parametrize("name", STATIONS)
def test_no_piece_a_simulation_changes_is_shared(name: str) -> None:
    """The equipment, the relay board, the interlocking's state and the oracle's memo are each simulation's own."""
    station = load(name)
    a, b = Watched(station), Watched(station)

    def pieces(w: Watched) -> list[object]:
        fld, core = w.sim.field, w.sim.interlocking.core
        out: list[object] = [fld, core, core.board, core.out, core.locks, w.watch.oracle, w.watch.oracle.flank]
        board = core.board  # read at power-on from the first simulation's board (``Wiring.power_on``)
        out += [board.track, board.dbj, board.fbj, board.lamps, *board.lamps.values(), board.flasher,
                board.filament_alarm, board.pdkj, board.pdqcj, board.changed_tracks, board.changed_signals]
        for c in fld.circuits.values():
            out += [c, c.faults, c.faults.capacitors]
            if c.counter is not None:
                out.append(c.counter)
        for m in fld.machines.values():
            out += [m, m.faults]
        for lamps in fld.lamps.values():
            out += [lamps, lamps.commanded, *lamps.lamps.values(), *(lamp.dj for lamp in lamps.lamps.values())]
        out += [*fld.flashers.values(), *fld.doors.values(), *(d.faults for d in fld.doors.values())]
        out += [*core.turnouts.values(), *core.signals.values(), *core.links.values(), *core.station_links.values()]
        return out

    mine = {id(p) for p in pieces(a)}
    assert [p for p in pieces(b) if id(p) in mine] == []


@pytest.mark.parametrize("name", [*STATIONS, "depot"])
def test_power_on_reads_the_field_as_it_is_built(name: str) -> None:
    """Every simulation's board at power-on holds what reading every relay of a field just built and lit shows, the
    first one's (which reads the field) and the later ones' (which copy it), changes waiting included; the field's
    changes are taken, as a reading takes them."""
    station, rules = load(name), load_rules()
    table = build_table(station, rules)

    def powered_on() -> tuple[RelayBoard, RelayBoard]:
        out = Interlocking(table, rules).core.out
        wiring, board = Wiring(station, rules, Field(station, rules=rules)), RelayBoard()
        wiring.power_on(board, out)
        assert wiring.field.take_changes() == FieldChanges() and wiring.field.stamp == 1
        by_hand = Wiring(station, rules, Field(station, rules=rules))
        by_hand.field.light(by_hand.commands_from(out))
        read = RelayBoard()
        by_hand.publish(read, everything=True)
        return board, read

    for _ in range(2):
        board, read = powered_on()
        assert board == read
        assert set(board.track) == set(station.sections) and board.changed_tracks == set(station.sections)


def test_a_copied_relay_board_is_its_own() -> None:
    """``RelayBoard.copy`` copies every relay and every change waiting, and shares nothing it could change."""
    board = RelayBoard()
    for f in fields(RelayBoard):
        value = getattr(board, f.name)
        if isinstance(value, set):
            value.add(f"{f.name}-x")
        elif f.name == "lamps":
            value["S"] = {"H": True}
        elif f.name == "line_in":
            value["L"] = {"msg"}
        else:
            value[f"{f.name}-x"] = True
    copy = board.copy()
    assert copy == board
    for f in fields(RelayBoard):
        value = getattr(copy, f.name)
        assert value is not getattr(board, f.name)
        if isinstance(value, set):
            value.clear()
        else:
            for inner in value.values():
                if isinstance(inner, (set, dict)):
                    inner.clear()
            value.clear()
    assert copy != board and board.lamps == {"S": {"H": True}} and board.line_in == {"L": {"msg"}}
    assert all(getattr(board, f.name) for f in fields(RelayBoard))


def _short_25hz(rules: RuleSet) -> RuleSet:
    """``rules`` with the 25 Hz model's range cut to 300 m: longer sections are held occupied."""
    return rules.model_copy(update={"design": rules.design.model_copy(update={"phase25hz_max_length_m": 300.0})})


def test_each_rule_set_gets_the_field_it_calls_for() -> None:
    """What is worked out for one rule set is never used under another: the same station under a rule set with a
    shorter 25 Hz range holds its long sections occupied, and under the default again it does not."""
    station, rules = load("jiaopei"), load_rules()
    short = _short_25hz(rules)
    plain = Watched(station, rules).seen()
    held = Watched(station, short)
    assert any("past the track-circuit model's range" in text for text in held.sim.alarm_texts())
    assert "occupied" in [held.sim.section_state(s) for s in station.sections]
    assert Watched(station, rules).seen() == plain
    assert Watched(station, short).seen() == held.seen() == Watched(load("jiaopei"), short).seen()


def test_a_station_is_freed_with_its_simulations_and_pickled_without_what_they_derived() -> None:
    """What the simulations and oracles derive is kept with the station, not for ever: the station goes when they go;
    a pickled copy (a Dask worker's) carries none of it and works it out again, to the same result."""
    refs = []
    for _ in range(2):
        station = load("gaotie")
        w = Watched(station)
        w.play(["route X XI", "run 3s"])
        refs.append(weakref.ref(station))
        del w, station
    gc.collect()
    assert [r() for r in refs] == [None, None]
    station = load("gaotie")
    before = Watched(station).play(MILD["gaotie"])
    copy = pickle.loads(pickle.dumps(station))
    assert copy._derived == {}
    assert Watched(copy).play(MILD["gaotie"]) == before
