"""The station's longitudinal profile (纵断面): the gradient under any stretch of the line.

The file's ``profile`` lists stretches with their gradient in per mille, positive where the line rises towards
increasing positions (the down direction). A stretch the profile does not cover counts as level.
"""

from __future__ import annotations

from collections.abc import Sequence

from liansuo.stations.schema import Direction, Grade


def mean_gradient(profile: Sequence[Grade], a: float, b: float) -> float:
    """The mean gradient (per mille, rising towards increasing positions) between positions ``a`` and ``b``."""
    lo, hi = min(a, b), max(a, b)
    if hi <= lo:
        return 0.0
    rise = sum(g.per_mille * (min(hi, g.end) - max(lo, g.start)) for g in profile if g.end > lo and g.start < hi)
    return rise / (hi - lo)


def falling(profile: Sequence[Grade], a: float, b: float, direction: Direction) -> float:
    """How steeply the line falls (per mille, positive downhill) for a movement in ``direction`` between ``a`` and
    ``b``, on average."""
    g = mean_gradient(profile, a, b)
    return -g if direction is Direction.down else g
