"""Shared helpers: drive a simulation through the command language, as a user would."""

from __future__ import annotations

import pytest

from liansuo.simulation.sim import Simulation


class Driver:
    """Runs command lines; plain commands must be accepted, ``expect`` lines must hold."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim

    def __call__(self, *lines: str) -> Driver:
        for line in lines:
            result = self.sim.command(line)
            assert result.ok, f"{line!r}: {result.message}"
        return self

    def refused(self, line: str, text: str) -> str:
        result = self.sim.command(line)
        assert not result.ok, f"{line!r} was accepted: {result.message}"
        assert text.lower() in result.message.lower(), f"{line!r} refused with {result.message!r}"
        return result.message

    def aspect(self, signal: str) -> str:
        return self.sim.aspect(signal)


@pytest.fixture
def jiaopei() -> Driver:
    return Driver(Simulation("jiaopei"))
