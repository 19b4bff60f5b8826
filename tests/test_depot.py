"""The bundled locomotive depot (机务段, Liu Huawei et al. 2021, docs/references.md): it loads cleanly, its table has
the shunting routes an automatic locomotive needs, and its markers are where the depot rules expect them."""

from __future__ import annotations

import pytest
from conftest import Driver

from liansuo.cli.main import main
from liansuo.interlocking.table.build import build_table
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load
from liansuo.stations.schema import EndKind, Lamp, SectionRole, SignalKind

DEPOT_TRACKS = {"1G": "D5", "2G": "D7", "3G": "D9", "4G": "D11"}  # depot track -> the signal that leaves it
END_BUTTONS = {"2G": "2GA", "3G": "3GA", "4G": "4GA"}


def test_depot_checks_with_no_warnings(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "depot"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("depot: 机务段 (Locomotive depot)") and "warnings     0" in out and err == ""
    station = load("depot")
    assert station.warnings == [] and station.model.description


def test_the_boundary_has_no_block_link_and_an_entry_shunting_signal() -> None:
    st = load("depot")
    assert st.ends["XB"].kind is EndKind.boundary and st.model.links == []
    d1 = st.signals["D1"]
    assert d1.at == "J-X" and d1.direction.value == "down"  # into the depot, from the boundary side
    assert st.tracks[st.signal_rear_track("D1") or ""].section == "RDG"


def test_signals_are_blue_shunting_signals_numbered_odd() -> None:
    st = load("depot")
    for s in st.model.signals:
        assert s.kind is SignalKind.shunting and set(s.lamps) == {Lamp.A, Lamp.B} and s.buttons
        assert s.id.startswith("D") and int(s.id[1:]) % 2 == 1


def test_depot_tracks_are_spurs_of_25hz_circuits_with_zd6_machines() -> None:
    st = load("depot")
    for sec in ("QXG", "1G", "1KG", "2G", "3G", "4G"):
        assert st.sections[sec].role is SectionRole.spur
    assert all(s.type.value == "25hz" for s in st.model.sections)
    assert all(t.machine.value == "ZD6" for t in st.model.turnouts)


def test_the_table_has_routes_into_every_depot_track_and_back() -> None:
    table = build_table(load("depot"))
    routes = table.routes
    assert all(r.kind == "shunt" for r in routes.values()) and len(routes) == 29
    for start in ("D1", "D3"):  # from the boundary and from the shunting neck
        for track, exit_signal in DEPOT_TRACKS.items():
            assert f"{start}-{exit_signal}" in routes  # up to the signal at the track's entrance
            if track in END_BUTTONS:
                assert f"{start}-{END_BUTTONS[track]}" in routes  # to the buffer stop
        assert f"{start}-D13" in routes  # to the servicing shed's signal
    assert "D13-1KA" in routes  # into the shed
    for exit_signal in DEPOT_TRACKS.values():  # back out: to the boundary, the neck's signal, the neck's end
        for end in ("D1", "D3", "QXA"):
            assert f"{exit_signal}-{end}" in routes
    assert routes["D1-4GA"].sections == ("1DG", "3DG", "7DG", "4G")
    assert "D3-D11" in routes["D1-D5"].conflicts


def test_markers_follow_the_depot_rules() -> None:
    st = load("depot")
    markers = st.model.markers
    by_kind: dict[str, list[str]] = {}
    for m in markers:
        by_kind.setdefault(m.kind.value, []).append(m.track)
        if m.kind.value in ("sanding", "washing"):
            assert m.speed_kmh == 3.0 and m.length_m > 0
            lo, hi = st.track_span(m.track)
            assert lo <= m.at and m.at + m.length_m <= hi  # the whole stretch lies on its track
    for track in ("t-1G", "t-1KG", "t-2G", "t-3G", "t-4G", "t-QX"):
        assert track in by_kind["one-stop"]  # before the shed, the buffer stops and the neck's end
        assert track in by_kind["rfid"]
    assert by_kind["balise"] == ["t-RDG"]
    assert {"t-1G", "t-2G"} <= set(by_kind["sanding"]) and by_kind["washing"] == ["t-1KG"]


def test_an_interlocked_run_into_the_shed() -> None:
    d = Driver(Simulation("depot"))
    d("shunt D1 D13", "run 15s", "expect signal D1 B", "expect turnout 3 normal locked",
      "shunt D13 1KA", "run 2s", "expect signal D13 B")
    d.refused("shunt D9 QXA", "conflicting route D1-D13")
    d("expect signal D9 A")
