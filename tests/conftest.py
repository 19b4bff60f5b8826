"""Shared helpers: drive a simulation through the command language, as a user would."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

import liansuo

# The suite runs the Python sources, in a native build too (setup.py): its doubles replace methods at run time, which
# compiled classes do not allow. tests/test_native.py compares the compiled modules with them (pytest -m native).
liansuo.use_pure()

from fieldsim import FieldSim, free_port  # noqa: E402

from liansuo.simulation.sim import Simulation  # noqa: E402


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


# a script of two tests, one passing and one failing (its aspect is wrong): for the reports of `liansuo test`
TWO_TESTS_SCRIPT = """\
station: jiaopei
tests:
  - name: receiving route opens
    steps:
      - route X XI
      - run 2s
      - expect signal X U
  - name: wrong aspect
    steps:
      - route X XI
      - run 2s
      - expect signal X L
"""


def edit(text: str, *pairs: tuple[str, str]) -> str:
    """A station or script text with each ``old`` (which must occur exactly once) replaced by ``new``."""
    for old, new in pairs:
        assert text.count(old) == 1, f"{old!r} occurs {text.count(old)} times"
        text = text.replace(old, new)
    return text


def position(text: str, needle: str) -> tuple[int, int]:
    """1-based line and column of the (unique) ``needle`` in ``text``; a ``^`` in the needle marks the spot."""
    offset = needle.index("^") if "^" in needle else 0
    needle = needle.replace("^", "")
    assert text.count(needle) == 1, f"{needle!r} occurs {text.count(needle)} times"
    before = text[: text.index(needle) + offset]
    return before.count("\n") + 1, len(before) - (before.rfind("\n") + 1) + 1


@pytest.fixture
def jiaopei() -> Driver:
    return Driver(Simulation("jiaopei"))


@pytest.fixture
def field() -> Iterator[FieldSim]:
    """``liansuo field-sim jiaopei`` in a second process on a free port (tests/fieldsim.py)."""
    fs = FieldSim(free_port())
    yield fs
    fs.stop()
