"""Field mode (docs/field-mode.md): the interlocking in field control against ``liansuo field-sim``, a second process,
over Modbus TCP on localhost. Routes, a fault injected at the field simulator, the change-over's conditions, the
link cut every way (process killed, port closed, stale data, garbage replies) and the same event log as in
simulated control."""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest

pytest.importorskip("pymodbus", reason="the field extra (pymodbus) is not installed")

from fieldsim import STATION, FieldSim, free_port

from liansuo.fieldio import points
from liansuo.fieldio.link import ModbusLink
from liansuo.fieldio.server import FieldServer, serve
from liansuo.fieldio.yard import FieldYard
from liansuo.simulation.sim import Simulation


def interlocking(port: int, timeout_s: float = 0.5) -> Simulation:
    sim = Simulation(STATION)
    sim.attach_field(ModbusLink("127.0.0.1", port, points.from_station(sim.station, sim.rules), timeout_s=timeout_s))
    return sim


def test_routes_set_and_released_under_field_control(field: FieldSim) -> None:
    sim = interlocking(field.port)
    assert sim.control is not None and "模拟控制" in sim.control.mode
    r = sim.command("changeover field")
    assert r.ok and "QHJ up" in r.message and "modbus 127.0.0.1" in r.message, r
    assert sim.field_control and "现场控制" in sim.control.mode
    assert sim.command("route X X3")
    sim.run(8)
    assert sim.turnout_state("1") == ("reverse", True)  # the field simulator's machine moved and indicated
    assert sim.aspect("X") == "UU"
    assert sim.command("cancel X")
    sim.run(2)
    assert sim.route_state("X-X3") == "released" and sim.aspect("X") == "H"
    assert sim.turnout_state("1") == ("reverse", False)
    assert sim.sealed_uses() == {"changeover": 1}
    assert any("QHJ up" in e for e in sim.event_texts())
    sim.close()


def test_fault_injected_at_the_field_simulator_reaches_the_interlocking(field: FieldSim) -> None:
    sim = interlocking(field.port)
    assert sim.command("changeover field")
    assert sim.command("route X XI")
    sim.run(3)
    assert sim.aspect("X") == "U"
    assert "fault injected" in field.send("fault filament X lamp=U which=both", "fault injected")
    sim.run(1)
    assert sim.aspect("X") == "H"  # a dark lamp of the aspect: the signal falls to stop
    assert any("X" in a for a in sim.alarm_texts())
    # the same fault is refused at the interlocking: the field's signals are the field's
    refused = sim.command("fault filament X lamp=U")
    assert not refused and "field control" in refused.message
    sim.close()


def test_changeover_refused_while_a_route_is_locked_and_accepted_when_idle(field: FieldSim) -> None:
    sim = interlocking(field.port)
    assert sim.command("route X XI")
    sim.run(2)
    r = sim.command("changeover field")
    assert not r and "route X-XI is held" in r.message
    assert sim.command("cancel X")
    sim.run(1)
    assert sim.command("train T1 at 3G")
    r = sim.command("changeover field")
    assert not r and "train T1" in r.message
    assert sim.sealed_uses() == {}  # refused uses are not counted
    sim2 = interlocking(field.port)
    assert sim2.command("changeover field")
    assert not sim2.command("changeover field")  # already
    refused = sim2.command("train T2 at 3G")
    assert not refused and "field" in refused.message
    assert sim2.command("changeover simulated")
    assert sim2.sealed_uses() == {"changeover": 2}
    sim.close()
    sim2.close()


def _open_route(sim: Simulation) -> None:
    assert sim.command("changeover field")
    assert sim.command("route X XI")
    sim.run(3)
    assert sim.aspect("X") == "U"


def _fail_safe_in_one_cycle(sim: Simulation, what: str) -> None:
    sim.step()
    assert sim.aspect("X") == "H", "the signal closes in the cycle the link is lost"
    assert sim.section_state("IG") == "occupied" and sim.turnout_state("1")[0] is None
    lost = [a for a in sim.alarm_texts() if "field link lost" in a]
    assert lost and what in lost[0] and "1DG GJ" in lost[0], lost
    assert sim.control is not None and "LINK LOST" in sim.control.mode


def test_field_simulator_killed_fails_safe_and_nothing_reopens(field: FieldSim) -> None:
    sim = interlocking(field.port)
    _open_route(sim)
    field.kill()
    _fail_safe_in_one_cycle(sim, f"127.0.0.1:{field.port}")
    sim.run(2)
    back = FieldSim(field.port)  # the field comes back on the same port
    try:
        sim.run(5)
        assert any("field link restored" in e for e in sim.event_texts())
        assert sim.section_state("IG") != "occupied"
        assert sim.aspect("X") == "H", "a signal closed by the link loss does not reopen by itself"
    finally:
        back.stop()
        sim.close()


def test_port_closed_refuses_the_changeover_and_fails_safe_under_field_control(field: FieldSim) -> None:
    sim = interlocking(free_port())
    r = sim.command("changeover field")
    assert not r and "does not answer" in r.message and "no connection" in r.message
    sim2 = interlocking(field.port)
    _open_route(sim2)
    field.stop()  # the port closes
    _fail_safe_in_one_cycle(sim2, "127.0.0.1")
    sim.close()
    sim2.close()


class _Frozen(FieldServer):
    """A field whose program has stopped: the Modbus server answers, the inputs and the echo never change."""

    frozen = False

    def heartbeat(self, beat: int) -> None:
        if not self.frozen:
            super().heartbeat(beat)


def _in_thread(coro_factory) -> threading.Thread:  # type: ignore[no-untyped-def]
    t = threading.Thread(target=lambda: asyncio.run(coro_factory()), daemon=True)
    t.start()
    return t


def test_stale_inputs_fail_safe_in_one_cycle() -> None:
    port = free_port()
    sim = interlocking(port, timeout_s=0.2)
    yard = FieldYard(sim.station, sim.rules)
    server = _Frozen(yard, points.from_station(sim.station, sim.rules), log=lambda line: None)
    ready = threading.Event()

    async def run() -> None:
        task = asyncio.create_task(serve(server, "127.0.0.1", port, ready=ready.set))
        while not stop.is_set():
            await asyncio.sleep(0.02)
        task.cancel()

    stop = threading.Event()
    _in_thread(run)
    assert ready.wait(10)
    try:
        _open_route(sim)
        server.frozen = True
        _fail_safe_in_one_cycle(sim, "stale inputs")
    finally:
        stop.set()
        sim.close()


@pytest.mark.parametrize("reply", ["garbage", "silence"])
def test_garbage_replies_and_no_reply_fail_safe_in_one_cycle(field: FieldSim, reply: str) -> None:
    sim = interlocking(field.port)
    _open_route(sim)
    # the field's address now answers with noise, or reads and never answers (a timeout)
    assert sim.control is not None
    port = free_port()
    stop = threading.Event()
    listening = threading.Event()

    def garbage() -> None:
        with socket.socket() as srv:
            srv.bind(("127.0.0.1", port))
            srv.listen()
            srv.settimeout(0.1)
            listening.set()
            while not stop.is_set():
                try:
                    conn, _ = srv.accept()
                except TimeoutError:
                    continue
                conn.settimeout(0.1)
                while not stop.is_set():
                    try:
                        if not conn.recv(256):
                            break
                    except TimeoutError:
                        continue
                    except OSError:
                        break
                    if reply == "garbage":
                        conn.sendall(os.urandom(3) + b"\x00\x07\xff\x01\x02garbage")
                conn.close()

    threading.Thread(target=garbage, daemon=True).start()
    assert listening.wait(5)
    link = sim.control.link
    assert isinstance(link, ModbusLink)
    link.close()
    link.client = type(link.client)("127.0.0.1", port=port, timeout=0.2, retries=0, reconnect_delay=0)
    link.port = port
    try:
        _fail_safe_in_one_cycle(sim, f"127.0.0.1:{port}")
    finally:
        stop.set()
        sim.close()


SESSION = """route X XI
run 1s
route XI S
block-line SL request
run 5s
throw 2/4 reverse
route X X3
run 6s
cancel X
run 2s
lock 1
route X XI
unlock 1
cancel XI
run 3s
block 3
route S SI
run 5s
cancel S
run 2s
unblock 3
guide-lock X
run 1s
guide-unlock X
run 2s""".splitlines()


def _events(sim: Simulation) -> list[tuple[float, str, str]]:
    return [(e.t, e.kind, e.text) for e in sim.view.events()]


def test_event_log_of_a_session_is_the_same_in_field_and_simulated_control(field: FieldSim) -> None:
    simulated = Simulation(STATION)
    in_field = interlocking(field.port)
    assert in_field.command("changeover field")
    for line in SESSION:
        a, b = simulated.command(line), in_field.command(line)
        assert (a.ok, a.message) == (b.ok, b.message), line
    assert len(_events(simulated)) > 20
    assert _events(simulated) == _events(in_field)
    in_field.close()


def test_field_simulator_watchdog_de_energises_when_heartbeats_stop_and_the_interlocking_hears_of_it() -> None:
    field = FieldSim(free_port(), "--watchdog", "0.3")
    try:
        sim = interlocking(field.port)
        _open_route(sim)
        seen = len(field.lines)  # the interlocking stops: no more heartbeats
        line = field.wait_for("no heartbeat from the interlocking", seen, timeout=5)
        assert "de-energised" in line
        _fail_safe_in_one_cycle(sim, "watchdog de-energised its outputs")
        sim.run(3)
        assert any("field link restored" in e for e in sim.event_texts())
        assert sim.aspect("X") == "H", "the outputs the field dropped do not come back by themselves"
        sim.close()
    finally:
        field.stop()


def test_field_simulator_refuses_the_signallers_commands(field: FieldSim) -> None:
    assert "signaller" in field.send("route X XI", "refused")
    assert "interlocking's cycles" in field.send("run 5s", "refused")


def test_field_sim_command_line_errors() -> None:
    bad = subprocess.run([sys.executable, "-m", "liansuo", "field-sim", STATION, "--modbus", "nowhere"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "HOST:PORT" in bad.stderr
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        busy = subprocess.run([sys.executable, "-m", "liansuo", "field-sim", STATION, "--modbus",
                               f"127.0.0.1:{port}"], capture_output=True, text=True, timeout=60,
                              stdin=subprocess.DEVNULL)
    assert busy.returncode == 2 and "cannot listen" in busy.stderr and "Traceback" not in busy.stderr


def test_point_map_checked_against_the_station(tmp_path: Path) -> None:
    text = subprocess.run([sys.executable, "-m", "liansuo", "field-map", STATION], capture_output=True, text=True,
                          timeout=60, check=True).stdout
    good = tmp_path / "good.yaml"
    good.write_text(text)
    ok = subprocess.run([sys.executable, "-m", "liansuo", "check", STATION, "--points", str(good)],
                        capture_output=True, text=True, timeout=60)
    assert ok.returncode == 0 and "field control of 16 sections, 7 turnouts, 11 signals" in ok.stdout
    lines = text.splitlines()
    gj = next(i for i, line in enumerate(lines) if "element: 1DG, relay: GJ" in line)
    lines[gj] = lines[gj].replace("1DG", "1DGX")
    bad = tmp_path / "bad.yaml"
    bad.write_text("\n".join(lines) + "\n")
    r = subprocess.run([sys.executable, "-m", "liansuo", "check", STATION, "--points", str(bad)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 3
    assert f"{bad}:{gj + 1}:" in r.stderr and "no section '1DGX'" in r.stderr and "Traceback" not in r.stderr


def test_elements_left_out_of_the_map_stay_simulated() -> None:
    """Per element, as the teaching base wires only part of its yard to the field: IG left out of the map stays on
    the simulation panel (its occupancy switch works at the interlocking), 3G is the field's."""
    port = free_port()
    sim = Simulation(STATION)
    whole = points.generate(sim.station, sim.rules)
    part = whole.model_copy(update={"inputs": [p for p in whole.inputs if p.element != "IG"],
                                    "outputs": [p for p in whole.outputs if p.element != "IG"],
                                    "codes": [p for p in whole.codes if p.section != "IG"]})
    pm = points.PointMap(part, points.elements_of(part))
    assert "IG" not in pm.elements.tracks and "3G" in pm.elements.tracks
    sim.attach_field(ModbusLink("127.0.0.1", port, pm))
    server = FieldServer(FieldYard(sim.station, sim.rules), pm, log=lambda line: None)
    ready, stop = threading.Event(), threading.Event()

    async def run() -> None:
        task = asyncio.create_task(serve(server, "127.0.0.1", port, ready=ready.set))
        while not stop.is_set():
            await asyncio.sleep(0.02)
        task.cancel()

    threading.Thread(target=lambda: asyncio.run(run()), daemon=True).start()
    assert ready.wait(10)
    try:
        assert sim.command("changeover field")
        assert sim.command("occupy IG")
        sim.run(1)
        assert sim.section_state("IG") == "occupied"
        refused = sim.command("occupy 3G")
        assert not refused and "section 3G is under field control" in refused.message
        server.yard.command("occupy 3G")  # at the field
        sim.run(1)
        assert sim.section_state("3G") == "occupied"
    finally:
        stop.set()
        sim.close()


def test_tui_field_options_are_checked_before_a_console_starts(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "LIANSUO_CHANGEOVER_PASSWORD"}
    cases = [(["--field", "127.0.0.1:1"], "no change-over password"),
             (["--points", "x.yaml"], "goes with --field"),
             (["--field", "nowhere"], "HOST:PORT")]
    for extra, said in cases:
        r = subprocess.run([sys.executable, "-m", "liansuo", "tui", STATION, *extra], capture_output=True, text=True,
                           timeout=60, env=env, stdin=subprocess.DEVNULL)
        assert r.returncode == 2 and said in r.stderr and "Traceback" not in r.stderr, (extra, r.stderr)


def test_a_train_at_the_field_simulator_runs_through_a_route_the_interlocking_sees_by_relays(field: FieldSim) -> None:
    """The interlocking needs nothing but relay states: a train placed at the field simulator runs in on X-XI, and
    the route releases section by section behind it, as in simulated control."""
    sim = interlocking(field.port)
    assert sim.command("changeover field")
    assert "placed" in field.send("train T1 at IAG mode=signal", "T1 placed")
    assert sim.command("route X XI")
    sim.run(60)
    assert sim.route_state("X-XI") == "released"
    assert sim.section_state("IG") == "occupied" and sim.section_state("1DG") == "free"
    texts = sim.event_texts()
    assert any("X-XI" in t and "released" in t for t in texts)
    sim.close()
