"""The SUMO engine's own promises: the exported network is the station's topology, and a SUMO failure is an alarm
in the simulation, never a crash of the simulator. Skipped, saying why, only without the ``sumo`` extra."""

from __future__ import annotations

import os
import signal
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from conftest import Driver

from liansuo.cli.main import main as cli_main
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains import sumo as sumo_module
from liansuo.simulation.trains.sumo import SumoEngine, SumoEngineError, sumo_installed
from liansuo.simulation.trains.sumo_export import (
    EXIT_LENGTH_M,
    SumoExportError,
    SumoUnavailable,
    build_network,
    export_plain,
    run_netconvert,
)
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
SUMO_MISSING = sumo_installed()
needs_sumo = pytest.mark.skipif(bool(SUMO_MISSING), reason=f"needs the sumo extra: {SUMO_MISSING}")


def test_plain_export_has_two_edges_per_track_with_our_lengths_and_lights_at_signal_joints(tmp_path: Path) -> None:
    st = load("jiaopei")
    net = export_plain(st, tmp_path)
    edges = ET.parse(tmp_path / "station.edg.xml").getroot()
    lengths = {e.get("id"): float(e.get("length", "0")) for e in edges}
    for tid in st.tracks:
        for d in ("d", "u"):
            assert lengths[f"{tid}.{d}"] == pytest.approx(st.track_length(tid))
    assert all(e.get("allow") == "rail" for e in edges)
    nodes = {n.get("id"): n.get("type") for n in ET.parse(tmp_path / "station.nod.xml").getroot()}
    signal_joints = {s.at for s in st.model.signals if s.at in st.joints}
    assert {n for n, t in nodes.items() if t == "traffic_light"} == signal_joints
    assert sorted(net.exits) == ["SB", "XB"]
    assert "rail_signal" not in (tmp_path / "station.nod.xml").read_text(encoding="utf-8")


@needs_sumo
def test_built_network_connects_only_what_the_topology_allows() -> None:
    st = load("jiaopei")
    net = build_network(st)
    assert net.net_file is not None
    root = ET.parse(net.net_file).getroot()
    lanes = {lane.get("id"): float(lane.get("length", "0")) for e in root.iter("edge") for lane in e.iter("lane")}
    for move, eid in net.edges.items():
        assert lanes[eid + "_0"] == pytest.approx(st.track_length(move[0]), abs=1e-3)
    got = {(c.get("from"), c.get("to")) for c in root.iter("connection")}
    want = {(net.edges[a], net.edges[b]) for a, b in st.topology.graph.edges()}
    boundary_moves = {(t, d) for t in ("t-IAG", "t-IIAG") for d in ("down", "up")}
    want |= {(net.edges[m], net.exits[e]) for m in net.edges if (m[0], m[1].value) in boundary_moves
             for e in net.exits if st.topology.far_node(m) == e}
    assert got == want
    # through turnout 1: point <-> normal and point <-> reverse only, never normal <-> reverse
    assert ("t-1b.u", "t-1c.d") not in got and ("t-1c.u", "t-1b.d") not in got
    assert lanes[net.exits["SB"] + "_0"] == EXIT_LENGTH_M
    assert {t.get("id") for t in root.iter("tlLogic")} == {s.at for s in st.model.signals if s.at in st.joints}
    assert all(t.get("type") == "static" for t in root.iter("tlLogic"))


@needs_sumo
def test_netconvert_failure_is_reported_with_its_own_words(tmp_path: Path) -> None:
    net = export_plain(load("jiaopei"), tmp_path)
    edg = tmp_path / "station.edg.xml"
    edg.write_text(edg.read_text(encoding="utf-8").replace('from="XB"', 'from="NOWHERE"'), encoding="utf-8")
    with pytest.raises(SumoExportError, match="netconvert failed"):
        run_netconvert(net)


@needs_sumo
def test_a_killed_sumo_worker_raises_the_alarm_and_the_trains_go_on() -> None:
    sim = Simulation("jiaopei", engine="sumo")
    engine = sim.fleet.engine
    assert isinstance(engine, SumoEngine)
    d = Driver(sim)
    d("train T1 at IAG mode=signal length=200", "route X XI", "run 20s")
    assert engine.active == "sumo" and sim.train_views()[0].speed_kmh > 0
    pid = engine.process.pid
    assert pid is not None
    os.kill(pid, signal.SIGKILL)
    engine.process.join(5)
    d("run 100s")  # no exception: the kinematic engine takes over from the speeds the trains had
    failed = [a for a in sim.alarm_texts() if "SUMO engine failed" in a]
    assert failed and "SIGKILL" in failed[0] and "kinematic engine" in failed[0]
    v = sim.train_views()[0]
    assert v.speed_kmh == 0.0 and 1000.0 < v.head_m < 1020.0  # still stopped short of XI
    d("expect route X XI released")
    assert engine.active == "kinematic"
    sim.close()


@needs_sumo
def test_an_error_raised_inside_sumo_is_an_alarm_too(monkeypatch: pytest.MonkeyPatch) -> None:
    sim = Simulation("jiaopei", engine="sumo")
    engine = sim.fleet.engine
    assert isinstance(engine, SumoEngine)
    d = Driver(sim)
    d("train T1 at IAG mode=signal length=200", "route X XI", "run 5s")
    monkeypatch.setattr(engine, "_light_changes", lambda fleet: {"no-such-light": "G"})
    d("run 5s")
    failed = [a for a in sim.alarm_texts() if "SUMO engine failed" in a]
    assert failed and "no-such-light" in failed[0]
    assert not engine.process.is_alive()  # the worker is stopped, not left behind
    sim.close()


@needs_sumo
def test_without_fallback_a_sumo_failure_is_a_dedicated_exception() -> None:
    st = load("jiaopei")
    engine = SumoEngine(st, fallback=False)
    sim = Simulation(st, engine=engine)
    Driver(sim)("train T1 at IAG mode=signal length=200", "route X XI", "run 5s")
    engine.process.kill()
    engine.process.join(5)
    with pytest.raises(SumoEngineError, match="SUMO engine failed"):
        sim.run(1)
    assert any("SUMO engine failed" in a for a in sim.alarm_texts())
    sim.close()


def test_without_the_extra_the_sumo_engine_says_how_to_install_it(monkeypatch: pytest.MonkeyPatch,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(sumo_module, "sumo_installed", lambda: "libsumo not installed (pip install 'liansuo[sumo]')")
    with pytest.raises(SumoUnavailable, match=r"liansuo\[sumo\]"):
        Simulation("jiaopei", engine="sumo")
    scenario = PKG / "examples" / "scenarios" / "jiaopei-receive-depart.yaml"
    assert cli_main(["run", str(scenario), "--engine", "sumo"]) == 2
    assert "liansuo[sumo]" in capsys.readouterr().err


@needs_sumo
def test_cli_runs_a_scenario_on_sumo(capsys: pytest.CaptureFixture[str]) -> None:
    scenario = PKG / "examples" / "scenarios" / "jiaopei-receive-depart.yaml"
    assert cli_main(["run", str(scenario), "--engine", "sumo"]) == 0
    out = capsys.readouterr().out
    assert "train T1 has left the station" in out and "engine failed" not in out
