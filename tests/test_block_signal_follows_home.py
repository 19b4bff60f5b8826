"""Regressions (found by `liansuo soak`): the automatic block signal in rear of a home signal must never show a
more permissive aspect than the home signal ahead allows.

- an aspect changed by an operator command between cycles (cancel, guide, reopen) reached the block signals only
  with the next track-circuit change, so 1231 kept showing L in front of a home signal cancelled to H;
- a guide aspect ahead (HB: the red lamp with the moon-white) was followed as a proceed aspect: L in front of it.
"""

from __future__ import annotations

from conftest import Driver

from liansuo.simulation.sim import Simulation


def test_block_signal_in_rear_follows_a_cancelled_home_signal() -> None:
    gaotie = Driver(Simulation("gaotie"))
    gaotie("route X XI", "route XI XFCK", "run 10s", "expect signal X L", "expect signal 1231 L", "cancel X",
           "run 250ms", "expect signal X H", "expect signal 1231 U", "expect signal 1217 LU")


def test_a_guide_aspect_ahead_is_followed_as_a_red_signal() -> None:
    gaotie = Driver(Simulation("gaotie"))
    gaotie("route X XI", "run 10s", "occupy IG", "run 1s", "guide X", "run 1s", "expect signal X HB",
           "expect signal 1231 U", "occupy 4G", "run 1s", "expect signal X HB", "expect signal 1231 U",
           "expect signal 1217 LU")
