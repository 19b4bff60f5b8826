"""The native build (docs/native.md): which modules mypyc compiles, the rules they keep, and the switch back to their
Python sources.

With ``LIANSUO_NATIVE=1`` the build (setup.py, which reads :data:`MODULES` from this file without importing liansuo)
compiles the hot path to C extensions: the cycle of the field, the interlocking and the trains, and the safety oracle.
A compiled module must keep to what mypyc supports, and tests/test_native_rules.py checks the first two rules on the
sources in the default suite:

1. no class of a compiled module is subclassed by a class of a module that is not compiled;
2. no attribute of a class of a compiled module is replaced at run time (``Class.name = ...``, ``setattr(Class, ...)``,
   ``patch.object(Class, ...)``), except by what runs on the Python sources only: the seeded defects of
   ``liansuo mutate`` (:data:`PURE_ONLY`) and the suite's doubles (tests/conftest.py runs the suite pure);
3. the station model (``stations/``) stays Python: compiled, deriving a 200-turnout hub's table took over ten
   minutes instead of seconds (tried 2026-11-24; the cause was not looked into).

``LIANSUO_PURE=1`` in the environment (or :func:`use_pure` before the first import) runs the Python sources of a
native build instead, in this process and the processes it starts.
"""

from __future__ import annotations

import os
import sys
from importlib.machinery import (
    BYTECODE_SUFFIXES,
    EXTENSION_SUFFIXES,
    SOURCE_SUFFIXES,
    FileFinder,
    ModuleSpec,
    SourceFileLoader,
    SourcelessFileLoader,
)
from typing import Any

# the compiled modules, as paths inside the package without ".py"
MODULES = (
    "circuits/field", "circuits/lamps", "circuits/machines", "circuits/shunts", "circuits/trackcircuits",
    "interlocking/cbi", "interlocking/core", "interlocking/equipment", "interlocking/io", "interlocking/lifecycle",
    "interlocking/locks", "interlocking/memos", "interlocking/operations", "interlocking/quiet",
    "interlocking/selection", "interlocking/state", "interlocking/throatguide",
    "simulation/commands", "simulation/neighbour", "simulation/view", "simulation/wiring",
    "simulation/trains/cabsignal", "simulation/trains/drivers", "simulation/trains/fleet",
    "simulation/trains/movement", "simulation/trains/odometerfeed", "simulation/trains/wheelsets",
    "proving/oracle/authority", "proving/oracle/ceiling", "proving/oracle/check", "proving/oracle/flank",
    "proving/oracle/lamps", "proving/oracle/meet", "proving/oracle/records", "proving/oracle/tables",
    "proving/oracle/watch",
    "proving/verify/pairs", "proving/verify/probe",
)
# modules that replace what compiled modules define, and so run on the Python sources only (rule 2)
PURE_ONLY = ("proving/mutation/cbidefects", "proving/mutation/patching", "proving/mutation/tabledefects")
# the layers that stay Python (rule 3)
NEVER = ("stations/",)


class PureFinder:
    """Finds liansuo's modules among its Python sources only, passing over the compiled ones of a native build."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> ModuleSpec | None:
        if not fullname.startswith("liansuo.") or path is None:
            return None
        for where in path:
            spec = FileFinder(where, (SourceFileLoader, SOURCE_SUFFIXES),
                              (SourcelessFileLoader, BYTECODE_SUFFIXES)).find_spec(fullname, target)
            if spec is not None:
                return spec
        return None


def native_modules() -> list[str]:
    """The modules of liansuo loaded so far that run compiled (a native build without LIANSUO_PURE=1)."""
    return sorted(name for name, mod in list(sys.modules.items()) if name.startswith("liansuo.")
                  and (getattr(mod, "__file__", None) or "").endswith(tuple(EXTENSION_SUFFIXES)))


def use_pure() -> None:
    """Run the Python sources of liansuo's modules from now on, in this process and the processes it starts. Asked
    before any of them is imported compiled (the suite's tests/conftest.py), else it raises."""
    os.environ["LIANSUO_PURE"] = "1"
    if not any(isinstance(f, PureFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, PureFinder())
    loaded = native_modules()
    if loaded:
        raise RuntimeError(f"liansuo's compiled modules are loaded already ({', '.join(loaded)}): set LIANSUO_PURE=1 "
                           "in the environment to run the Python sources")
