"""A train running over its own route past a closed signal inside that route (a shunting signal in a train route)
has not passed a signal at danger; one passing the route's own closed signal has."""

from __future__ import annotations

from liansuo.simulation.sim import Simulation


def run(sim: Simulation, *lines: str) -> None:
    for line in lines:
        result = sim.command(line)
        assert result.ok, (line, result.message)


def test_departure_past_shunting_signal_inside_its_route_is_no_spad() -> None:
    sim = Simulation("jiaopei")
    # SI-X runs up over 1DG and 7DG, past the up shunting signal D3 at the joint between them
    run(sim, "block-line XL request", "run 10s", "route SI X", "run 10s", "expect signal SI L",
        "occupy IG", "run 1s", "occupy 1DG", "run 1s", "occupy 7DG", "run 1s", "vacate IG", "run 1s",
        "vacate 1DG", "run 1s", "expect no-alarm passed at danger", "expect signal D3 A")


def test_entering_a_route_past_its_closed_signal_is_still_spad() -> None:
    sim = Simulation("jiaopei")
    run(sim, "occupy IAG", "run 1s", "occupy 7DG", "run 1s", "expect alarm signal X passed at danger")
