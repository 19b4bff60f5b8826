"""`liansuo verify`: the automatic interlocking test passes on the bundled stations, fails on broken station files and
on a broken interlocking, and says which check failed with the steps that show it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.selection import Selection
from liansuo.proving.scripts import Script, ScriptTest, Step, run_test
from liansuo.proving.verify import verify_station
from liansuo.stations.library import bundled
from liansuo.stations.loader import load

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "liansuo"
BROKEN = PKG / "examples" / "broken" / "gaotie-no-diamond-protection.yaml"
MINIMAL = (PKG / "examples" / "stations" / "minimal.yaml").read_text(encoding="utf-8")


@pytest.mark.parametrize("name", sorted(bundled()))
def test_every_bundled_station_passes(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify", name, "--format", "json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["station"] == name and rep["failures"] == []
    assert rep["routes_tested"] == rep["routes"] > 0
    assert rep["pairs_tested"] == rep["routes"] * (rep["routes"] - 1) // 2
    assert rep["checks"] > 20 * rep["routes"]


def test_text_report_lists_routes_pairs_and_the_verdict(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify", "jiaopei"]) == 0
    out = capsys.readouterr().out
    assert "X-XI" in out and "aspects U" in out and "of L/U" in out
    assert "300 tested" in out
    assert out.strip().splitlines()[-1].startswith("PASS: ")


def test_the_broken_station_fails_on_flank_protection(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(BROKEN)]) == 0  # the file itself is valid
    capsys.readouterr()
    assert main(["verify", str(BROKEN), "--format", "json", "--no-pairs", "--route", "X-XI(BA1)"]) == 1
    rep = json.loads(capsys.readouterr().out)
    found = {(f["check"], f["subject"]) for f in rep["failures"]}
    # the table held against the oracle finds it; the running route happens to be safe as long as 5/7 lie normal,
    # since they stand in sections the route locks (tests/test_oracle.py sets them reverse first)
    assert found == {("flank-protection", "X-XI(BA1)")}
    assert any("turnout 5 must protect the route lying normal" in f["detail"] for f in rep["failures"])
    assert any("turnout 7 must protect the route lying normal" in f["detail"] for f in rep["failures"])


def test_design_warnings_are_reported_and_fail_only_with_strict() -> None:
    rep = verify_station("gaotie", routes=["X-XI"], pairs=False)
    kinds = {w.check for w in rep.warnings}
    assert {"dead-zone", "unselectable-path"} <= kinds and rep.ok
    assert not verify_station("gaotie", routes=["X-XI"], pairs=False, strict=True).ok


def test_short_coded_section_fails(tmp_path: Path) -> None:
    f = tmp_path / "short.yaml"
    f.write_text(MINIMAL.replace("{id: 1DG, type: 25hz}", "{id: 1DG, type: 25hz, coded: true, speed_kmh: 400}"),
                 encoding="utf-8")
    rep = verify_station(f, pairs=False)
    assert [(x.check, x.subject) for x in rep.failures] == [("coded-length", "1DG")]


def test_overlap_is_locked_with_the_route_and_released_by_its_timer(tmp_path: Path) -> None:
    f = tmp_path / "overlap.yaml"
    f.write_text(MINIMAL.replace("\nlinks:", "\noverlaps:\n  - {end_signal: XI, sections: [1LQG], release_s: 60}\n"
                                 "\nlinks:"), encoding="utf-8")
    rep = verify_station(f)
    assert rep.ok, [x.detail for x in rep.failures]
    xi = next(r for r in rep.results if r.id == "X-XI")
    assert "overlap" not in xi.not_applicable and "doors" not in xi.not_applicable


def test_a_broken_interlocking_fails_with_a_script_that_replays_it(monkeypatch: pytest.MonkeyPatch) -> None:
    # an interlocking that forgets approach locking (接近锁闭): cancel is granted with a train approaching
    monkeypatch.setattr(RouteLifecycle, "approach_locked", lambda self, rs: False)
    rep = verify_station("jiaopei", routes=["X-XI"], pairs=False)
    fail = next(f for f in rep.failures if f.check == "approach-locking")
    assert fail.subject == "X-XI" and "'cancel X' with approach IAG occupied was accepted" in fail.detail
    assert fail.steps[0] == "route X XI" and "occupy IAG" in fail.steps and fail.steps[-1] == "cancel X"
    # the steps replay as a test script: the route is released while the train approaches
    steps = [*fail.steps, "expect route X XI locked"]
    script = Script("replay.yaml", "jiaopei", [ScriptTest("replay", [Step(s, i + 1) for i, s in enumerate(steps)],
                                                          1)])
    station = load("jiaopei")
    from liansuo.interlocking.table.build import build_table

    outcome = run_test(script, script.tests[0], station, build_table(station))
    assert not outcome.passed and "route X-XI is released, expected locked" in outcome.failure


def test_a_conflict_the_interlocking_lets_through_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Selection, "route_blocker", lambda self, r, run_on=None: "")
    rep = verify_station("jiaopei", routes=["X-XI"])
    fail = next(f for f in rep.failures if f.check == "conflict")
    assert "conflicts with" in fail.detail and len([s for s in fail.steps if s.startswith(("route", "shunt"))]) == 2


def test_waiting_for_nothing_to_happen_lasts_until_the_turnouts_stood_still() -> None:
    # verify's "the signal stays closed" checks wait until the turnouts have been at rest for REST_S: a wait that
    # ended while they still moved would look at a signal that could not have opened yet
    from liansuo.interlocking.table.build import build_table
    from liansuo.proving.verify.probe import REST_S, Context, Probe
    from liansuo.rules import load_rules

    station, rules = load("jiaopei"), load_rules("china")
    ctx = Context(station, build_table(station, rules), rules)
    p = Probe(ctx)
    p.settle()
    assert p.sim.t == REST_S  # nothing moves: the rest alone
    p = Probe(ctx)
    p.do("route X X3")  # turnouts 1 and 3 go reverse
    p.settle()
    assert p.sim.turnout_state("1")[0] == "reverse" and p.sim.turnout_state("3")[0] == "reverse"
    assert p.sim.t < 20.0 and p.script()[-1] == f"run {p.sim.t:g}s"
    q = Probe(ctx)  # the same again, looked at REST_S before the wait ended: the turnouts were still on their way
    q.do("route X X3")
    q.run(p.sim.t - REST_S)
    assert q.sim.turnout_state("1")[0] is None and q.sim.turnout_state("3")[0] is None


def test_a_signal_opening_over_a_turnout_without_indication_is_caught_by_its_own_check(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # an interlocking that takes a turnout whose machine stopped for one in position, and opens without its
    # indication: the signal opens a cycle after the machines stop, which the wait before the check must see
    from liansuo.interlocking.state import RouteStage
    from liansuo.proving.mutation.mutants import MUTANTS

    def setting(self: RouteLifecycle, rs: object) -> None:
        il = self.core
        if il.now - rs.since > 1.0 and not any(t.id in il.moving or t.id in il.queue  # type: ignore[attr-defined]
                                               for t in rs.all_turnouts):  # type: ignore[attr-defined]
            rs.stage = RouteStage.locked  # type: ignore[attr-defined]
            self._locked(rs)  # type: ignore[arg-type]

    monkeypatch.setattr(RouteLifecycle, "_setting", setting)
    blind = next(m for m in MUTANTS if m.name == "blind-to-indication")
    with blind.applied():
        rep = verify_station("jiaopei", routes=["X-X3"], pairs=False)
    fails = [f for f in rep.failures if f.check == "no-indication" and "without indication" in f.detail]
    assert {f.detail.split()[1] for f in fails} == {"7", "1", "3", "5"}  # every turnout of the route
    assert all(f.steps[0] == f"fault no-indication {f.detail.split()[1]}" for f in fails)
