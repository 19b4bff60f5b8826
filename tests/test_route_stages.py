"""The route state machine as one table (interlocking/lifecycle.py, ``STAGES``): every stage has its handler, a move
the table does not list is refused, and every move the table lists is made by the interlocking test, the bundled
scripts or a sequence written for it (so the table is no looser than the code)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from liansuo.interlocking.lifecycle import STAGES, RouteLifecycle
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.proving.scripts import parse_script, run_script
from liansuo.proving.verify import verify_station
from liansuo.simulation.sim import Simulation

PKG = Path(__file__).resolve().parents[1] / "src" / "liansuo"
TESTS = Path(__file__).resolve().parent / "scripts"


def test_every_stage_has_its_handler_and_its_moves() -> None:
    assert set(STAGES) == set(RouteStage)
    for stage, (handler, moves) in STAGES.items():
        assert callable(getattr(RouteLifecycle, handler)), stage
        assert stage not in moves, f"{stage} -> {stage} is no move"


def test_a_move_the_table_does_not_list_is_refused() -> None:
    sim = Simulation("jiaopei")
    assert sim.command("route X XI").ok
    rs = sim.interlocking.core.routes["X-XI"]
    assert rs.stage is RouteStage.setting
    with pytest.raises(RuntimeError, match="no move from setting to open"):
        sim.interlocking.lifecycle.to(rs, RouteStage.open)
    assert rs.stage is RouteStage.setting


def _stage(sim: Simulation, rid: str) -> str | None:
    rs = sim.interlocking.core.routes.get(rid)
    return rs.stage.value if rs is not None else None


def _moves_verify_leaves_out() -> None:
    """Three moves neither verify nor the bundled scripts make, on jiaopei's X-XI (approach IAG; 7DG, 1DG, IG)."""
    sim = Simulation("jiaopei")  # a movement passes the closed signal of a route that could not open
    for line in ("route X XI", "occupy IG"):
        assert sim.command(line).ok
    sim.run(1)
    assert _stage(sim, "X-XI") == "locked"
    for line in ("occupy IAG", "occupy 7DG"):
        assert sim.command(line).ok
    sim.run(1)
    assert _stage(sim, "X-XI") == "in_use"
    sim = Simulation("jiaopei")  # the guide aspect given while the route is still setting
    assert sim.command("route X XI").ok and sim.command("guide X").ok
    assert _stage(sim, "X-XI") == "guide"
    sim = Simulation("jiaopei")  # the train enters during the manual time release
    assert sim.command("route X XI").ok
    sim.run(2)
    assert sim.command("occupy IAG").ok
    sim.run(1)
    assert sim.command("release X").ok
    sim.run(1)
    assert _stage(sim, "X-XI") == "time_release"
    assert sim.command("occupy 7DG").ok
    sim.run(1)
    assert _stage(sim, "X-XI") == "in_use"


@pytest.fixture(scope="module")
def moves_made() -> Iterator[set[tuple[RouteStage, RouteStage]]]:
    """Every move of stage made by the interlocking test of three stations, the bundled test scripts (examples and
    the suite's), and three sequences written for the moves those leave out."""
    seen: set[tuple[RouteStage, RouteStage]] = set()
    real = RouteLifecycle.to

    def to(self: RouteLifecycle, rs: RouteState, stage: RouteStage) -> None:
        seen.add((rs.stage, stage))
        real(self, rs, stage)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(RouteLifecycle, "to", to)
        for station in ("jiaopei", "gaotie", str(PKG / "examples" / "stations" / "danxian.yaml")):
            assert verify_station(station).ok
        for path in [*sorted((PKG / "examples" / "scripts").glob("*.yaml")), *sorted(TESTS.glob("*.yaml"))]:
            assert all(o.passed for o in run_script(parse_script(path))), path.name
        _moves_verify_leaves_out()
        yield seen


def test_the_interlocking_test_makes_every_move_the_table_lists(moves_made: set[tuple[RouteStage, RouteStage]]
                                                                 ) -> None:
    """A move listed and never made would be a door the code has not got (or one verify never opens)."""
    listed = {(stage, to) for stage, (_, moves) in STAGES.items() for to in moves}
    assert moves_made <= listed
    assert listed - moves_made == set()
