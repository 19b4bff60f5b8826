"""Physical inputs the track-circuit models accept: a ballast resistance above zero, positions that are numbers.

A ballast resistance of 0 divides by zero in the line equations, a negative one has no physical meaning, and NaN
makes every voltage NaN, so that no comparison with a relay's pick-up or drop level holds. A position that is not a
finite number (NaN, infinite) lies nowhere: the models would leave such a wheelset out and the section clear.
Infinite ballast resistance is meaningful (dry ballast, no leakage) and accepted where a ballast is given. The
models raise ``ValueError`` naming the parameter and its value; the command language and the station loader refuse
the same values in their own words (docs/faults.md, docs/station-format.md).
"""

from __future__ import annotations

import math
from collections.abc import Iterable


def ballast_problem(value: float, *, infinite_ok: bool = True) -> str:
    """Why ``value`` (ohm*km) cannot be a ballast resistance, or '' if it can."""
    if math.isnan(value):
        return "is not a number"
    if value <= 0.0:
        return "must be above 0 ohm*km"
    if math.isinf(value) and not infinite_ok:
        return "must be finite"
    return ""


def check_ballast(name: str, value: float, *, infinite_ok: bool = True) -> float:
    """``value`` if it is a ballast resistance (ohm*km) the models can use; else ``ValueError`` naming ``name``."""
    why = ballast_problem(float(value), infinite_ok=infinite_ok)
    if why:
        raise ValueError(f"{name} {why}, got {value!r}")
    return float(value)


def check_position(name: str, value: float) -> float:
    """``value`` if it is a finite number of metres; else ``ValueError`` naming ``name``."""
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number of metres, got {value!r}")
    return float(value)


def check_shunts(shunts: Iterable[tuple[float, float]]) -> None:
    """Every ``(position_m, ohm)`` shunt has a finite position and a resistance that is a number >= 0."""
    for x, r in shunts:
        if not math.isfinite(x):
            raise ValueError(f"shunt position must be a finite number of metres, got {x!r}")
        if not r >= 0.0:
            raise ValueError(f"shunt resistance must be a number of ohms >= 0, got {r!r}")
