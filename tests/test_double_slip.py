"""A double slip (复式交分道岔) in the station file, as a user meets it: the example station
(examples/stations/doubleslip.yaml) checks clean, its interlocking table has routes over each of the four roads with
the pairs printed like crossovers, the straight roads cross at the diamond, ``verify`` passes, trains run over it under
the safety oracle, the console draws it, and a broken entry is refused at its line with a hint."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import Driver, edit, position

from liansuo.cli.main import main
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.interlocking.table.signed import SignedRow, signed_table
from liansuo.kit.source import StationError
from liansuo.proving.oracle import Watch
from liansuo.proving.verify import verify_station
from liansuo.rules import load_rules
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load, load_text
from liansuo.tui.layout import build_layout

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
EXAMPLE = PKG / "examples" / "stations" / "doubleslip.yaml"
TEXT = EXAMPLE.read_text(encoding="utf-8")
ENTRY = "  - {id: 21-27, at: 740, length: 34, number: 9, machine: ZD6, section: 21-27DG, slips: [[21, 23], [25, 27]]}"




@pytest.fixture(scope="module")
def table() -> InterlockingTable:
    return build_table(load(str(EXAMPLE)))


@pytest.fixture(scope="module")
def rows(table: InterlockingTable) -> dict[str, SignedRow]:
    return {r.route: r for g in signed_table(table).groups for r in g.rows}


# ---- the example checks clean --------------------------------------------------------------------------------------
def test_check_lists_the_double_slip_with_its_two_pairs_and_no_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    assert "turnouts     7 (crossover pairs 21/23, 25/27)" in out
    assert "double slips 21-27" in out
    assert "warnings     0" in out


def test_the_four_turnouts_face_outwards_and_stand_at_the_ends() -> None:
    st = load(str(EXAMPLE))
    assert {t: st.turnouts[t].at for t in ("21", "23", "25", "27")} == {"21": 723, "23": 757, "25": 723, "27": 757}
    # the low-end turnouts are facing for down movements, the high-end ones for up movements
    assert [st.turnout_points_down(t) for t in ("21", "23", "25", "27")] == [True, False, True, False]
    assert st.pairs == {"21/23": ["21", "23"], "25/27": ["25", "27"]}


# ---- the interlocking table ----------------------------------------------------------------------------------------
# route -> (turnouts cell, the inner track it runs over): two routes over each of the four roads
ROADS = {
    "X-X3": ("(1) (21/23) [(25/27)]", "21-27_21-23"),  # slip road 21-23
    "S3-X": ("(21/23) (1) [(25/27)]", "21-27_21-23"),
    "X-X4": ("(1) 21/23 25/27", "21-27_21-27"),  # straight road 21-27
    "S4-X": ("25/27 21/23 (1)", "21-27_21-27"),
    "D1-S3": ("25/27 21/23", "21-27_25-23"),  # straight road 25-23
    "S3-D1": ("21/23 25/27", "21-27_25-23"),
    "D1-S4": ("(25/27) [(21/23)]", "21-27_25-27"),  # slip road 25-27
    "S4-D1": ("(25/27) [(21/23)]", "21-27_25-27"),
}


@pytest.mark.parametrize("route", sorted(ROADS))
def test_each_road_has_routes_with_the_pairs_printed_like_crossovers(table: InterlockingTable,
                                                                     rows: dict[str, SignedRow], route: str) -> None:
    turnouts, road = ROADS[route]
    assert rows[route].cells["turnouts"] == turnouts
    assert "21-27DG" in rows[route].cells["sections"].split()
    assert road in table.routes[route].path.tracks
    # over a slip road the other pair lies reverse as flank protection; over a straight road all four lie normal
    slip = road in ("21-27_21-23", "21-27_25-27")
    lie = {t.id: t.position.value for t in table.routes[route].turnouts if t.id != "1"}
    assert lie == dict.fromkeys(("21", "23", "25", "27"), "reverse" if slip else "normal")


def test_the_main_line_keeps_off_the_double_slip(table: InterlockingTable, rows: dict[str, SignedRow]) -> None:
    assert rows["X-XI"].cells["route"] == "至 IG" and rows["X-XI"].cells["turnouts"] == "1"
    assert rows["SI-X"].cells["turnouts"] == "1" and "21-27DG" not in rows["SI-X"].cells["sections"]
    # a receiving route onto the main line may be set while a shunting movement uses the double slip
    assert "D1-S4" not in table.routes["X-XI"].conflicts


def test_the_straight_roads_cross_at_the_diamond_and_are_enemies(table: InterlockingTable,
                                                                  rows: dict[str, SignedRow]) -> None:
    straight = ("X-X4", "S4-X", "D1-S3", "S3-D1")
    for r in ROADS:
        assert table.routes[r].diamonds == (("21-27",) if r in straight else ())
        assert ("菱形交叉 21-27" in rows[r].cells["other"]) is (r in straight)
    assert "D1-S3" in table.routes["X-X4"].conflicts and "X" in rows["D1-S3"].cells["enemies"].split()
    assert "S4-X" in table.routes["S3-D1"].conflicts


def test_the_slip_roads_lie_in_one_track_circuit_so_they_are_never_set_together(table: InterlockingTable) -> None:
    # the two slip roads do not cross and need the same turnout positions, but the whole double slip is one section
    assert table.routes["X-X3"].conflicts["D1-S4"] == "section 21-27DG"
    assert table.routes["S3-X"].conflicts["S4-D1"] == "section 21-27DG"


def test_verify_passes_on_the_example() -> None:
    report = verify_station(load(str(EXAMPLE)))
    assert report.failures == [], [str(f) for f in report.failures]
    assert report.ok


# ---- running trains over it --------------------------------------------------------------------------------------
def test_a_train_runs_over_the_slip_road_then_a_shunt_over_the_straight_road() -> None:
    sim = Simulation(str(EXAMPLE))
    watch = Watch(sim)
    d = Driver(sim)
    d("route X X3", "run 10s", "expect route X-X3 open", "expect signal X UU", "expect turnout 1 reverse locked",
      "expect turnout 21 reverse locked", "expect turnout 23 reverse locked",
      "expect turnout 25 reverse locked", "expect turnout 27 reverse locked")  # 25/27 as flank protection
    d.refused("shunt D1 S3", "conflicting route X-X3 is locked")
    d("train T1 at IAG mode=signal length=120")
    heads: list[str] = []
    for _ in range(40):
        d("run 2s")
        heads += [v.head_track for v in sim.train_views()]
    assert "21-27_21-23" in heads and "21-27_21-27" not in heads  # over the slip road, not the straight road
    d("expect section 3G occupied", "expect section 21-27DG free", "expect route X-X3 released")
    # the straight road 25-23 crosses 21-27: the two pairs move back to normal together
    d("shunt D1 S3", "run 10s", "expect signal D1 B", "expect turnout 21 normal locked", "expect turnout 23 normal",
      "expect turnout 25 normal locked", "expect turnout 27 normal")
    d.refused("route X X4", "conflicting route D1-S3 is locked")
    d("route X XI", "run 10s", "expect route X-XI open")  # the main line is free of it
    assert watch.violations == []


# ---- the console draws it ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("lpr", [2, 3])
def test_the_console_draws_the_crossing_with_the_numbers_outside(lpr: int) -> None:
    lay = build_layout(load(str(EXAMPLE)), load_rules().lamps, lpr=lpr)
    top = lay.targets[next(r for r in lay.targets if r.kind == "turnout" and r.id == "21")][1]
    bottom = lay.targets[next(r for r in lay.targets if r.kind == "turnout" and r.id == "25")][1]
    labels = {g.ref.id: y for y, row in enumerate(lay.grid) for g in row
              if g is not None and g.role == "tlabel" and g.ref is not None}
    assert labels["21"] == labels["23"] == top - 1  # above slip road 21-23
    assert labels["25"] == labels["27"] == bottom + 1  # below slip road 25-27
    inside = [g for row in lay.grid[top + 1:bottom] for g in row if g is not None and g.section == "21-27DG"]
    assert {g.ch for g in inside} >= {"╲", "╱"} or "╳" in {g.ch for g in inside}


# ---- broken entries are refused at their line ----------------------------------------------------------------------
BROKEN = [
    ("a turnout number already declared", (('{id: "2", at: 1750', '{id: "23", at: 1750'),),
     "double slip 21-27: turnout id '23' is already used by turnout 23 under 'turnouts:'", "[[21, ^23]", "declares"),
    ("an unknown section", (("section: 21-27DG, slips", "section: 21-29DG, slips"),),
     "double slip 21-27 lies in section '21-29DG', which is not declared", "section: ^21-29DG", "sections:"),
    ("a turnout named twice", (("slips: [[21, 23], [25, 27]]", "slips: [[21, 23], [25, 21]]"),),
     "double slip 21-27 names turnout 21 twice", "[25, ^21]]", "four turnouts"),
    ("three slip roads", (("slips: [[21, 23], [25, 27]]", "slips: [[21, 23], [25, 27], [29, 31]]"),),
     "List should have at most 2 items", "slips: ^[[", "remove items"),
    ("an inner track id taken", (("{id: t-IG,", "{id: 21-27_21-23,"),),
     "the id '21-27_21-23' of its inner track is already used", "{id: ^21-27, at: 740", "ID_LOW-HIGH"),
    ("a track on a leg inside it", (("from: 23.point, to: J-3G", "from: 23.normal, to: J-3G"),),
     "track 't-23a' attaches to '23.normal', inside double slip 21-27", "{id: t-23a, from: ^23.", "23.point"),
    ("a point track in another section", (("to: 21.point, section: 21-27DG", "to: 21.point, section: IAG"),),
     "track 't-21a' at 21.point is in section 'IAG'", "to: 21.point, section: ^IAG", "inside one section"),
    ("a point track leading back into it", (("  - {id: J-3G, at: 800}", "  - {id: J-3G, at: 750}"),),
     "track 't-23a' leaves 23.point (757 m) towards lower positions", "{id: t-23a, from: ^23.", "higher ones"),
    # a cross-check on a generated turnout: the message names it, the place is the double slip's entry
    ("a point with no track", (("from: 23.point, to: J-3G", "from: 27.point, to: J-3G"),),
     "turnout 23: its point leg has 0 tracks attached", "[[21, ^23]", "23.point"),
]


@pytest.mark.parametrize(("name", "edits", "message", "where", "hint"), BROKEN, ids=[b[0] for b in BROKEN])
def test_a_broken_double_slip_is_refused_at_its_line(name: str, edits: tuple[tuple[str, str], ...], message: str,
                                                     where: str, hint: str) -> None:
    text = edit(TEXT, *edits)
    with pytest.raises(StationError) as info:
        load_text(text, "ds.yaml")
    found = [d for d in info.value.diagnostics if message in d.message]
    assert found, str(info.value)
    d = found[0]
    assert (d.file, d.line, d.column) == ("ds.yaml", *position(text, where))
    assert hint in d.hint


def test_check_refuses_a_bad_file_without_a_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(edit(TEXT, ("section: 21-27DG, slips", "section: 21-29DG, slips")), encoding="utf-8")
    assert main(["check", str(path)]) == 3  # a bad input file
    err = capsys.readouterr().err
    line = TEXT[:TEXT.index(ENTRY)].count("\n") + 1
    assert f"{path}:{line}:" in err and "Traceback" not in err
    assert err.rstrip().endswith("1 error; the station was not loaded")


def test_the_docs_explain_it() -> None:
    glossary = (ROOT / "docs" / "glossary.md").read_text(encoding="utf-8")
    assert any(line.startswith("| 复式交分道岔 |") for line in glossary.splitlines())
    doc = (ROOT / "docs" / "station-format.md").read_text(encoding="utf-8")
    assert "## double_slips" in doc and ENTRY.strip() in doc  # the example's entry, as the format page shows it
