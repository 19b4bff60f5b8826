"""What the station format says beyond the track layout, and what each statement does: the profile and the overlaps
it calls for, driven turnouts, a turnout's own diverging speed, fouling points tied to their turnout, added enemy
routes, and the coded-length rule at the speed trains really run. Each is used by a bundled or example station."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
from conftest import Driver, edit

from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.interlocking.table.schema import TABLE_SCHEMA
from liansuo.interlocking.table.text import as_json
from liansuo.kit.source import StationError
from liansuo.proving.verify import verify_station
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load, load_text
from liansuo.stations.rules import design_rules

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
EXAMPLES = PKG / "examples" / "stations"
DANXIAN = (EXAMPLES / "danxian.yaml").read_text(encoding="utf-8")
MINIMAL = (EXAMPLES / "minimal.yaml").read_text(encoding="utf-8")
SHUANGXIAN = (EXAMPLES / "shuangxian.yaml").read_text(encoding="utf-8")



def table(text: str) -> InterlockingTable:
    return build_table(load_text(text, "s.yaml"))


def overlap(t: InterlockingTable, route: str) -> tuple[tuple[str, ...], dict[str, str]]:
    r = t.routes[route]
    return r.overlap_sections, {x.id: x.position.value for x in r.overlap_turnouts}


def driver(tmp_path: Path, text: str) -> Driver:
    path = tmp_path / "station.yaml"
    path.write_text(text, encoding="utf-8")
    return Driver(Simulation(str(path)))


# ---- the profile and the overlaps it calls for ----------------------------------------------------------------
def test_danxian_profile_gives_an_overlap_beyond_every_receiving_track_on_a_falling_approach() -> None:
    t = table(DANXIAN)
    assert overlap(t, "X-XI") == (("2DG",), {"2": "normal"})
    assert overlap(t, "S-SI") == (("1DG",), {"1": "normal"})
    # the siding's end signals face the same fall: their overlap runs through the turnout the way it leads
    assert overlap(t, "X-X3") == (("2DG",), {"2": "reverse"})
    assert overlap(t, "S-S3") == (("1DG",), {"1": "reverse"})
    assert all(t.routes[r].overlap_release_s == 180 for r in ("X-XI", "S-S3"))
    assert not any(r.overlap_sections for r in t.routes.values() if r.category == "departure")
    # a departure over the overlap of the other throat's receiving route is its enemy; the through movement is not
    assert "X-X3" in t.routes["XI-S"].conflicts and "X-X3" not in t.routes["X3-S"].conflicts


X_APPROACH = "{from: 0, to: 720, per_mille: -9}"  # X at 600 m: 800 m of braking distance at 100 km/h, 600 m of it here


@pytest.mark.parametrize(("per_mille", "overlaps"), [(0, False), (-8, False), (-8.2, True), (9, False)])
def test_only_an_approach_falling_more_than_six_per_mille_calls_for_an_overlap(per_mille: float,
                                                                               overlaps: bool) -> None:
    """The mean over the braking distance outside X: 600 m at ``per_mille``, 200 m beyond the model level."""
    text = edit(DANXIAN, (X_APPROACH, f"{{from: 0, to: 720, per_mille: {per_mille}}}"))
    assert bool(table(text).routes["X-XI"].overlap_sections) is overlaps
    assert bool(table(text).routes["S-SI"].overlap_sections)  # the other approach is unchanged


def test_the_gradient_that_counts_is_outside_the_home_signal_over_the_braking_distance() -> None:
    # the old reading: the throat beyond the end signal falls, the approach is level: no overlap
    beyond = edit(DANXIAN, (X_APPROACH, "{from: 0, to: 720, per_mille: 0}"),
                  ("{from: 1680, to: 2400, per_mille: 9}", "{from: 1680, to: 2400, per_mille: -12}"))
    assert not table(beyond).routes["X-XI"].overlap_sections
    # a faster line brakes over a longer distance: 1400 m at 160 km/h, of which only 600 m fall here
    fast = edit(DANXIAN, ("line_speed_kmh: 100", "line_speed_kmh: 160"))
    assert not table(fast).routes["X-XI"].overlap_sections
    steeper = edit(fast, (X_APPROACH, "{from: 0, to: 720, per_mille: -15}"))  # 600 * 15 / 1400 = 6.4
    assert table(steeper).routes["X-XI"].overlap_sections == ("2DG",)


def test_without_a_profile_there_is_no_overlap_and_an_overlaps_entry_replaces_the_derived_one() -> None:
    level = edit(DANXIAN, ("  - {from: 1680, to: 2400, per_mille: 9}\n", ""),
                 (f"  - {X_APPROACH}\n", ""))
    assert not any(r.overlap_sections for r in table(level).routes.values())
    own = DANXIAN + ("\noverlaps:\n  - {end_signal: XI, sections: [2DG], "
                     "turnouts: [{turnout: \"2\", position: normal}], release_s: 60}\n")
    t = table(own)
    assert overlap(t, "X-XI") == (("2DG",), {"2": "normal"}) and t.routes["X-XI"].overlap_release_s == 60
    assert t.routes["X-X3"].overlap_release_s == 180  # X3 keeps the derived one


def test_the_interlocking_locks_the_derived_overlap_and_lets_the_through_movement_over_it() -> None:
    d = Driver(Simulation(str(EXAMPLES / "danxian.yaml")))
    d("route X XI", "run 6s", "expect route X-XI open", "expect section 2DG locked", "expect turnout 2 normal locked")
    d.refused("route S S3", "conflicting route X-XI is locked")
    # receiving onto the siding drives the overlap's turnout 2 reverse; the onward departure over the same overlap
    # may be set at once and waits for it
    d2 = Driver(Simulation(str(EXAMPLES / "danxian.yaml")))
    d2("route X X3", "route X3 S", "run 20s", "expect route X-X3 open",
       "expect route X3-S open", "expect turnout 2 reverse locked")


def test_alternative_overlaps_are_chosen_by_the_overlap_end_button() -> None:
    t = build_table(load(str(EXAMPLES / "shuangxian.yaml")))
    basic, alt = t.routes["X-XI"], t.routes["X-XI+XFK2"]
    assert overlap(t, "X-XI") == (("10DG", "2-8DG"), {"10": "normal", "2": "normal", "8": "normal", "4": "normal",
                                                      "6": "normal"})
    assert overlap(t, "X-XI+XFK2") == (("10DG", "2-8DG", "4-6DG"), {"10": "normal", "2": "reverse", "4": "reverse"})
    assert (basic.overlap_end, basic.overlap_alternative, alt.overlap_alternative) == ("XFCK", False, True)
    assert alt.buttons == ("X", "XI", "XFK2") and basic.buttons == ("X", "XI")
    assert "X-XI" in alt.conflicts  # one signal, one route at a time
    data = json.loads(as_json(t))
    jsonschema.validate(data, TABLE_SCHEMA)
    row = next(r for g in data["groups"] for r in g["rows"] if r["id"] == "X-XI+XFK2")
    assert row["mode"] == "变更延续" and row["buttons"].split()[-1] == "XFK2" and "延续进路 至 XFK2" in row["other"]
    assert next(r for r in data["routes"] if r["id"] == "X-XI+XFK2")["overlap"]["alternative"] is True
    d = Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))
    d("line-direction SL-II out", "route X XI XFK2", "run 15s", "expect route X-XI+XFK2 open",
      "expect turnout 2 reverse locked", "expect section 4-6DG locked")
    d.refused("route XI XFCK", "conflicting route X-XI+XFK2")  # straight on needs 2 normal, the overlap reverse
    d("route XI XFK2", "run 15s", "expect route XI-XFK2 locked")  # the through movement over the alternative
    d2 = Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))
    d2("route X XI", "run 15s", "expect route X-XI open", "expect turnout 2 normal locked", "expect section 4-6DG free")
    d3 = Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))
    d3("route X XI XFCK", "run 15s", "expect route X-XI open")  # the basic overlap's own button selects it too


@pytest.mark.parametrize(("change", "what"), [
    (("    end: XFK2\n", ""), "signal XI has 2 overlaps; each alternative needs its 'end'"),
    (("    end: XFK2\n", "    end: XFCK\n"), "signal XI has two overlaps ending at 'XFCK'"),
    (("    end: XFK2\n", "    end: NOPE\n"), "overlap end button 'NOPE' is not a signal or button"),
])
def test_alternative_overlaps_without_distinct_end_buttons_are_refused(change: tuple[str, str], what: str) -> None:
    with pytest.raises(StationError) as info:
        load_text(edit(SHUANGXIAN, change), "s.yaml")
    d = next(d for d in info.value.diagnostics if what in d.message)
    assert d.file == "s.yaml" and d.line > 1 and d.hint


@pytest.mark.parametrize(("stretches", "what"), [
    ("  - {from: 900, to: 400, per_mille: 3}\n", "profile stretch 1 runs from 900 m to 400 m"),
    ("  - {from: 0, to: 500, per_mille: 3}\n  - {from: 400, to: 900, per_mille: 1}\n",
     "profile stretch 2 (400 m on) overlaps stretch 1"),
])
def test_a_broken_profile_is_refused_with_file_and_line(stretches: str, what: str) -> None:
    text = MINIMAL + "\nprofile:\n" + stretches
    with pytest.raises(StationError) as info:
        load_text(text, "p.yaml")
    d = next(d for d in info.value.diagnostics if what in d.message)
    assert d.file == "p.yaml" and d.line > MINIMAL.count("\n") and d.hint


# ---- driven turnouts and diverging speed -------------------------------------------------------------------------
def test_depot_routes_to_4g_drive_turnout_5_normal_and_prove_it_before_the_signal_opens() -> None:
    t = build_table(load("depot"))
    driven = {(x.id, x.position.value) for x in t.routes["D1-D11"].turnouts if x.role == "driven"}
    assert driven == {("5", "normal")}
    assert not any(x.role == "driven" for x in t.routes["D1-D9"].turnouts)  # 7 normal drives nothing
    d = Driver(Simulation("depot"))
    d("throw 5 reverse", "run 8s", "expect turnout 5 reverse")
    d("shunt D1 D11", "run 10s", "expect turnout 5 normal locked", "expect turnout 7 reverse locked",
      "expect signal D1 B")
    d2 = Driver(Simulation("depot"))
    d2("throw 5 reverse", "run 8s", "occupy 5DG")  # a driven turnout that must move cannot, under a vehicle
    d2.refused("shunt D1 D11", "turnout 5 cannot move: section 5DG is occupied")


def test_a_drive_is_checked_against_the_turnouts() -> None:
    for drives, what in (('[{turnout: "9", position: normal, when: reverse}]', "drives unknown turnout '9'"),
                         ('[{turnout: "1", position: normal, when: reverse}]', "turnout 1 drives itself")):
        text = edit(MINIMAL, ('{id: "1", at: 250, number: 12, machine: ZD6}',
                              f'{{id: "1", at: 250, number: 12, machine: ZD6, drives: {drives}}}'))
        with pytest.raises(StationError) as info:
            load_text(text, "d.yaml")
        assert any(what in d.message for d in info.value.diagnostics), str(info.value)


def test_a_turnouts_own_diverging_speed_decides_usu(tmp_path: Path) -> None:
    assert build_table(load(str(EXAMPLES / "shuangxian.yaml"))).routes["X-X3"].aspects == ("UU", "USU")
    slow = edit(SHUANGXIAN, ('{id: "1", at: 3100, number: 18, machine: S700K}',
                             '{id: "1", at: 3100, number: 18, machine: S700K, diverging_speed_kmh: 60}'))
    assert table(slow).routes["X-X3"].aspects == ("UU",)
    # the onward route over the No. 12 scissors holds the home signal at UU, unless the scissors allow 80 km/h
    steps = ("line-direction SL-II out", "route X X3", "route X3 XFK2", "run 20s")
    Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))(*steps, "expect signal X UU")
    fast = SHUANGXIAN
    for t in ("2", "4"):
        old = next(line for line in SHUANGXIAN.splitlines() if line.startswith(f'  - {{id: "{t}", at:'))
        fast = edit(fast, (old, old.replace("pair: 2/4}", "pair: 2/4, diverging_speed_kmh: 80}")))
    driver(tmp_path, fast)(*steps, "expect signal X USU")


def test_danxian_turnouts_carry_their_own_diverging_speed() -> None:
    st = load(str(EXAMPLES / "danxian.yaml"))
    assert st.diverging_speed_kmh("1", design_rules()) == 50  # its No. 12 figure would be 45


# ---- fouling points tied to their turnout -------------------------------------------------------------------------
TIED = edit(MINIMAL, ("{id: FP1, track: t-1b, at: 290}", '{id: FP1, turnout: "1", tracks: [t-1b, t-3G], at: 290}'),
            ("{id: J-13, at: 310}", "{id: J-13, at: 270}"))


def test_a_joint_inside_the_fouling_limit_makes_the_section_beyond_a_fouling_section() -> None:
    fouling = table(TIED).routes["X-XI"].fouling
    assert [(f.section, f.turnout, f.position.value) for f in fouling] == [("3G", "1", "normal")]
    # the joint 60 m from the turnout lies past the fouling point (40 m) plus the clearance: nothing to check
    clear = edit(TIED, ("{id: J-13, at: 270}", "{id: J-13, at: 310}"),
                 ("tracks: [t-1b, t-3G]", "tracks: [t-1b, t-1c]"))
    assert table(clear).routes["X-XI"].fouling == ()


def test_the_route_waits_for_the_fouling_section_and_verify_agrees(tmp_path: Path) -> None:
    d = driver(tmp_path, TIED)
    d("occupy 3G")
    d.refused("route X XI", "section 3G is occupied")
    report = verify_station(load(str(tmp_path / "station.yaml")))
    assert report.failures == [], [str(f) for f in report.failures]


@pytest.mark.parametrize(("fp", "what"), [
    ('{id: FP1, track: t-1b, turnout: "1", tracks: [t-1b, t-1c], at: 290}', "not both"),
    ('{id: FP1, turnout: "1", at: 290}', "names its turnout but not its tracks"),
    ('{id: FP1, turnout: "7", tracks: [t-1b, t-1c], at: 290}', "unknown turnout '7'"),
    ('{id: FP1, turnout: "1", tracks: [t-1c, t-1b], at: 290}', "track 't-1c' is not reached from the normal leg"),
])
def test_a_badly_tied_fouling_point_is_refused(fp: str, what: str) -> None:
    text = edit(MINIMAL, ("{id: FP1, track: t-1b, at: 290}", fp))
    with pytest.raises(StationError) as info:
        load_text(text, "f.yaml")
    d = next((d for d in info.value.diagnostics if what in d.message), None)
    assert d is not None, str(info.value)
    assert d.line == text[:text.index("{id: FP1")].count("\n") + 1 and d.hint


def test_the_fouling_rule_measures_a_tied_point_along_the_turnout_legs() -> None:
    signal = "  - {id: SI, kind: starting, at: J-1I, direction: up, lamps: [L, U, H], buttons: [train]}\n"
    base = edit(MINIMAL, ("\nbuttons:", signal + "\nbuttons:"))
    near = edit(base, ("{id: FP1, track: t-1b, at: 290}", '{id: FP1, turnout: "1", tracks: [t-1b, t-1c], at: 298}'))
    warnings = load_text(near, "w.yaml").warnings
    assert [w.message for w in warnings] == [
        "fouling point FP1 is 2 m ahead of the joint of starting signal SI (need >= 3.5 m)"]
    far = edit(near, ("at: 298}", "at: 296}"))
    assert load_text(far, "w.yaml").warnings == []


# ---- added enemies -------------------------------------------------------------------------------------------------
def test_shuangxian_added_enemies_are_listed_and_never_locked_together() -> None:
    t = build_table(load(str(EXAMPLES / "shuangxian.yaml")))
    assert t.routes["X-X3"].conflicts["XI-XFCK"].endswith("3G has no isolating device at its S end")
    assert "X-X3" in t.routes["XI-XFK2"].conflicts
    d = Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))
    d("route X X3")
    d.refused("route XI XFCK", "an enemy the station file adds: 3G has no isolating device at its S end")
    d2 = Driver(Simulation(str(EXAMPLES / "shuangxian.yaml")))
    d2("route XI XFCK")
    d2.refused("route X X3", "conflicting route XI-XFCK is locked")


@pytest.mark.parametrize(("entry", "what"), [
    ("{route: X-X3, enemy: XI-XQ}", "added enemy names route 'XI-XQ', which does not exist"),
    ("{route: X-X3, enemy: X-X3}", "route X-X3 is named as its own enemy"),
    ("{route: X-X3, enemy: X-XI}", "routes X-X3 and X-XI are already enemies"),
])
def test_a_wrong_added_enemy_is_refused_at_its_line(entry: str, what: str) -> None:
    text = edit(SHUANGXIAN, ("    - {route: X-X3, enemy: XI-XFK2, why: \"3G has no isolating device at its S end\"}",
                             f"    - {entry}"))
    with pytest.raises(StationError) as info:
        table(text)
    d = next((d for d in info.value.diagnostics if what in d.message), None)
    assert d is not None, str(info.value)
    assert d.line == text[:text.index(entry)].count("\n") + 1


# ---- the coded-length rule at the speed trains run -----------------------------------------------------------
def test_a_coded_main_line_section_is_measured_at_line_speed() -> None:
    fast = edit(MINIMAL, ("line_speed_kmh: 80", "line_speed_kmh: 160"), ("{id: 1DG, type: 25hz}",
                                                                          "{id: 1DG, type: 25hz, coded: true}"))
    [w] = load_text(fast, "c.yaml").warnings
    assert "coded section '1DG' is 110 m long; at 160 km/h (line speed on the main line)" in w.message
    assert load_text(edit(fast, ("line_speed_kmh: 160", "line_speed_kmh: 80")), "c.yaml").warnings == []


def test_a_short_coded_siding_is_measured_at_the_speed_of_the_turnout_onto_it() -> None:
    # a 65 m coded siding behind a No. 12 turnout on a 160 km/h line: 45 km/h needs 51.25 m, so no warning
    siding = edit(MINIMAL, ("line_speed_kmh: 80", "line_speed_kmh: 160"), ("{id: B-3, kind: buffer, at: 600}",
                  "{id: B-3, kind: buffer, at: 375}"), ("{id: 3G, type: 25hz, role: spur}",
                                                        "{id: 3G, type: 25hz, role: spur, coded: true}"))
    assert load_text(siding, "c.yaml").warnings == []
    fast_turnout = edit(siding, ('machine: ZD6}', 'machine: ZD6, diverging_speed_kmh: 80}'))
    [w] = load_text(fast_turnout, "c.yaml").warnings
    assert "at 80 km/h (side line, over turnout 1)" in w.message
