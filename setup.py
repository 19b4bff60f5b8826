"""The build: pure Python by default. With ``LIANSUO_NATIVE=1`` in the environment the modules of the hot path (the
cycle of the field, the interlocking and the trains, and the safety oracle) are also compiled to C extensions with
mypyc (part of mypy), which runs them about 1.5-2x faster with the same results (docs/native.md). Everything else
about the package is in pyproject.toml.
"""

from __future__ import annotations

import os

from setuptools import setup

# Compiled modules must keep to what mypyc supports: no class of theirs subclassed by a Python class, no method
# of theirs replaced on an instance or a class at run time. What must replace them (the seeded defects of
# ``liansuo mutate``, the suite's counting doubles) runs on the pure modules (``LIANSUO_PURE=1``, liansuo/__init__.py).
# The station model (stations/station, topology) stays Python: compiled, deriving a 200-turnout hub's table took
# over ten minutes instead of seconds (tried 2026-11-24; the cause was not looked into).
NATIVE = [
    "circuits/field", "circuits/lamps", "circuits/machines", "circuits/shunts", "circuits/trackcircuits",
    "interlocking/cbi", "interlocking/core", "interlocking/io", "interlocking/lifecycle", "interlocking/locks",
    "interlocking/operations", "interlocking/quiet", "interlocking/state",
    "simulation/commands", "simulation/neighbour", "simulation/view", "simulation/wiring",
    "simulation/trains/cabsignal", "simulation/trains/drivers", "simulation/trains/fleet",
    "simulation/trains/movement", "simulation/trains/odometerfeed", "simulation/trains/wheelsets",
    "proving/oracle/authority", "proving/oracle/ceiling", "proving/oracle/check", "proving/oracle/flank",
    "proving/oracle/lamps", "proving/oracle/meet", "proving/oracle/watch",
    "proving/verify/pairs", "proving/verify/probe",
]


def native() -> dict[str, object]:
    """What ``setup`` takes for a native build, if asked for one."""
    if os.environ.get("LIANSUO_NATIVE", "") != "1":
        return {}
    try:
        from mypyc.build import mypycify
    except ImportError:
        raise SystemExit("a native build (LIANSUO_NATIVE=1) compiles with mypyc, which type-checks the modules first: "
                         "build it with --no-build-isolation in an environment with mypy, setuptools>=77 and "
                         "liansuo's dependencies installed (`make native` does all of it; docs/native.md)") from None
    return {"ext_modules": mypycify([f"src/liansuo/{m}.py" for m in NATIVE], opt_level="3")}


setup(**native())
