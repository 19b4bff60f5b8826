"""The benchmark and its generated hub station: every figure is there and sensible. Timings are never asserted."""

from __future__ import annotations

import json
import math
from collections import Counter
from dataclasses import replace
from pathlib import Path

import pytest

from liansuo.bench import report as bench
from liansuo.bench.busy import busy_routes
from liansuo.bench.report import Sizes, all_finite, as_text, run_bench
from liansuo.cli.main import main
from liansuo.interlocking.table.build import build_table
from liansuo.simulation.sim import Simulation
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text

STATION_KEYS = {
    "station", "turnouts", "sections", "signals", "routes", "load_s", "table_build_s", "conflicting_pairs",
    "idle_cycles", "cycle_us_idle", "realtime_factor_idle", "busy_routes", "busy_route_ids", "busy_warmup_cycles",
    "busy_cycles", "cycle_us_busy", "realtime_factor", "busy_route_settings", "busy_traversals", "busy_stalls",
    "alarms", "peak_memory_mb",
}
CLASSROOM_KEYS = {
    "station", "round_trips", "gap_ms", "memory_commands", "memory_line_chars", "memory_growth_kb", "memory_log_lines",
    *(f"{case}_rtt_ms_{s}" for case in ("quiet", "flood", "login") for s in ("median", "p95", "max")),
    "flood_sent", "flood_s", "flood_offered_per_s", "flood_read", "flood_read_per_s", "login_round_trips", "logins",
    "logins_checked", "logins_locked_out", "logins_busy", "logins_turned_away", "logins_failed", "logins_s",
}
NO_CLASSROOM = replace(Sizes.tiny(), classroom_round_trips=0)  # the command line's tests: no server to start
POSITIVE = ("turnouts", "sections", "routes", "load_s", "table_build_s", "cycle_us_idle", "cycle_us_busy",
            "realtime_factor", "realtime_factor_idle", "busy_routes", "busy_traversals", "peak_memory_mb")


@pytest.fixture(scope="module")
def report() -> dict[str, object]:
    return run_bench(Sizes.tiny())


def test_report_has_every_figure_positive_and_finite(report: dict[str, object]) -> None:
    assert json.loads(json.dumps(report)) == report  # plain JSON
    assert all_finite(report)
    machine = report["machine"]
    assert isinstance(machine, dict)
    assert {"processor", "cpu_count", "python"} <= machine.keys()
    assert report["native"] == []  # the suite runs the Python sources (tests/conftest.py), and says so
    results = report["results"]
    assert isinstance(results, dict)
    assert set(results) == {"hub", "jiaopei"}
    for res in results.values():
        assert res.keys() >= STATION_KEYS
        for key in POSITIVE:
            assert isinstance(res[key], int | float) and res[key] > 0 and math.isfinite(res[key]), (key, res[key])
        assert res["busy_stalls"] == 0  # every route opened and released as the traversal expected
        assert res["alarms"] == 0
    assert results["hub"]["turnouts"] == 20
    assert results["jiaopei"]["busy_routes"] == 2  # one train route into each end of the single-line station
    targets = report["targets"]
    assert isinstance(targets, list)
    assert {(t["station"], t["figure"]) for t in targets} >= {("jiaopei", "realtime_factor"),
                                                              ("hub20", "table_build_s")}
    # issue 13's trains ratio is judged where SUMO ran beside the kinematic engine, and only there
    trains = report["trains"]
    assert isinstance(trains, dict)
    ratio = [t for t in targets if t["figure"] == "ratio_kinematic_to_sumo"]
    if trains["ratio_kinematic_to_sumo"] is None:
        assert ratio == []
    else:
        assert ratio == [{"station": "hub20", "figure": "ratio_kinematic_to_sumo", "target": ">= 5",
                          "value": trains["ratio_kinematic_to_sumo"],
                          "met": trains["ratio_kinematic_to_sumo"] >= 5}]


def test_the_classroom_under_attack_is_measured_and_every_attack_accounted_for(report: dict[str, object]) -> None:
    """A real ``liansuo serve`` with a flooding client and a wave of wrong logins (bench/classroom.py): every figure
    is there, and every message of the attacks is accounted for; the timings themselves are not judged."""
    room = report["classroom"]
    assert isinstance(room, dict)
    assert set(room) == CLASSROOM_KEYS, room.get("skipped", room)
    sizes = Sizes.tiny()
    assert room["round_trips"] == sizes.classroom_round_trips and room["memory_commands"] == sizes.classroom_commands
    for case in ("quiet", "flood", "login"):
        median, p95, most = (room[f"{case}_rtt_ms_{s}"] for s in ("median", "p95", "max"))
        assert 0 < median <= most and p95 <= most, (case, median, p95, most)
    assert room["flood_sent"] > room["flood_read"] > 0  # the server read the flood at its own pace, not the client's
    assert room["flood_offered_per_s"] > 0 and room["flood_s"] > 0
    assert room["logins"] == sizes.classroom_logins == sum(
        room[f"logins_{k}"] for k in ("checked", "locked_out", "busy", "turned_away", "failed"))
    assert room["logins_failed"] == 0 and 1 <= room["logins_checked"] <= 5  # the lockout let at most 5 be checked
    assert room["login_round_trips"] >= 1
    assert room["memory_log_lines"] == 1000  # the seat's log at its bound
    targets = report["targets"]
    assert isinstance(targets, list)
    assert {t["figure"] for t in targets if t["station"] == "classroom"} == {
        "flood_rtt_ms_p95", "flood_offered_per_s", "login_rtt_ms_p95", "memory_growth_kb"}


def test_text_format_lists_every_station(report: dict[str, object]) -> None:
    text = as_text(report)
    assert "hub20" in text and "jiaopei" in text and "cycle busy (us)" in text
    assert "one client flooding" in text and "wrong logins at once" in text


def test_cli_bench_prints_json(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(bench, "run_bench",
                        lambda quick=False, scale=None, show_progress=None: run_bench(NO_CLASSROOM, quick=quick))
    assert main(["bench", "--quick"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mode"] == "quick" and set(out["results"]) == {"hub", "jiaopei"}
    assert main(["bench", "--quick", "--format", "text"]) == 0
    assert "targets:" in capsys.readouterr().out


def test_each_run_asked_for_is_appended_to_the_history(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(bench, "run_bench",
                        lambda quick=False, scale=None, show_progress=None: run_bench(NO_CLASSROOM, quick=quick))
    history = tmp_path / "history.jsonl"
    for _ in range(2):
        assert main(["bench", "--quick", "--history", str(history)]) == 0
        printed = json.loads(capsys.readouterr().out)
    lines = [json.loads(line) for line in history.read_text(encoding="utf-8").splitlines()]
    assert len(lines) == 2
    assert lines[1]["date"] >= lines[0]["date"] and lines[1]["date"].endswith("+00:00")
    assert lines[1]["commit"] is None or lines[1]["commit"].rstrip("+").isalnum()  # None when installed
    assert {k: v for k, v in lines[1].items() if k not in ("date", "commit")}.keys() == printed.keys()
    assert lines[1]["results"]["jiaopei"]["routes"] == printed["results"]["jiaopei"]["routes"]
    assert main(["bench", "--history", str(tmp_path)]) == 2  # a folder: refused before anything runs
    assert "give --history a file name" in capsys.readouterr().err


def test_a_history_that_is_not_one_is_refused_before_the_run_and_left_as_it_was(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ran: list[bool] = []
    monkeypatch.setattr(bench, "run_bench", lambda **kw: ran.append(True))
    station = tmp_path / "station.yaml"
    station.write_text("id: mine\n", encoding="utf-8")
    assert main(["bench", "--history", str(station)]) == 3
    assert capsys.readouterr().err == (f"liansuo bench: {station}:1:1: error: this is not a benchmark history (one "
                                       "JSON object a line, each with its date); give --history a new file or one "
                                       "liansuo bench wrote\n")
    assert main(["bench", "--history", str(tmp_path / "no" / "h.jsonl")]) == 2
    assert "no folder" in capsys.readouterr().err
    assert ran == [] and station.read_text(encoding="utf-8") == "id: mine\n"


@pytest.mark.parametrize(("turnouts", "tracks"), [(0, 1), (6, 4), (20, 8), (61, 24)])
def test_generated_hub_is_valid_and_exact(turnouts: int, tracks: int) -> None:
    station = load_text(generate_hub(turnouts, tracks), "<hub>")
    assert station.warnings == []
    assert len(station.turnouts) == turnouts
    assert sum(s.role.value == "station_track" for s in station.sections.values()) == tracks
    table = build_table(station)
    kinds = Counter(r.category for r in table.routes.values())
    assert kinds["receiving"] >= 2 * tracks and kinds["departure"] >= 2 * tracks and kinds["shunting"] > 0
    assert table.unselectable == []


def test_hub_200_gives_hundreds_of_routes_and_holds_20_at_once() -> None:
    station = load_text(generate_hub(200, 80), "<hub200>")
    assert station.warnings == []
    table = build_table(station)
    assert len(table.routes) >= 500
    routes = busy_routes(table, 20)
    assert len(routes) == 20
    sim = Simulation(station, table=table)
    for r in routes:
        assert sim.command(f"route {r.start} {r.end}").ok
    sim.run(60)
    assert all(sim.route_state(r.id) == "open" for r in routes)


def test_impossible_hub_is_refused() -> None:
    with pytest.raises(ValueError, match="at least"):
        generate_hub(5, 4)
    with pytest.raises(ValueError, match="cannot be laid out"):
        generate_hub(30, 4)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="the child's own peak is read from /proc (Linux)")
def test_the_tables_peak_is_its_own_whatever_the_bench_holds() -> None:
    """The table's peak memory is the child's that writes it, not the bench's: a child started by fork and exec
    reports the peak of the parent it came from in getrusage (a bench that had just verified hub200 showed 348 MB for
    a table writer that peaked at 162)."""
    from liansuo.bench.scale import _table

    held = bytearray(300 * 1024 * 1024)  # the bench holding 300 MB, every page of it resident
    for i in range(0, len(held), 4096):
        held[i] = 1
    assert 0 < _table(8)["table_hub8_peak_mb"] < 200
    del held


def test_the_scale_figures_are_reported_for_verify_soak_and_the_table() -> None:
    from liansuo.bench.scale import ScaleSizes, measure_scale

    sc = measure_scale(ScaleSizes.tiny())
    assert sc["verify_hub8"]["ok"] and sc["verify_hub8"]["pairs"] > 0 and sc["verify_hub8_s"] > 0
    assert sc["verify_speedup_hub"]["reports_identical"]  # 1 and 2 workers: the same report
    assert 0 < sc["table_hub8_peak_mb"] < 1000 and sc["table_hub8_json_mb"] > 0
    assert sc["soak_steps_per_s_per_worker"]["here"] > 0 and sc["soak_steps_per_s_per_worker"]["two_workers"] > 0
    assert {t["figure"] for t in sc["targets"]} == {"verify_speedup"}  # the hub sizes of the targets are not run
