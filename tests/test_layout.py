"""The repository's layout: one tree, ``src/liansuo/<layer>``, each module with one name, ``liansuo.<layer>...``."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "liansuo"
LAYERS = ("kit", "rules", "stations", "circuits", "interlocking", "simulation", "classroom", "proving", "bench", "tui",
          "server", "remote", "cli")
# the floor of each layer: a module imports only from its own layer or from a lower floor (README.md, "Layout")
FLOOR = {"kit": 0, "rules": 1, "stations": 2, "circuits": 3, "interlocking": 3, "simulation": 4, "classroom": 5,
         "fieldio": 5, "tui": 6, "server": 6, "proving": 7, "remote": 7, "bench": 8, "cli": 9}
# the classroom (roles, exercises, assessment) stands on the simulation, below the console and the server that both
# use it; proving stands above the console, whose fuzzer it holds; bench measures what proving runs (verify, soak),
# so it stands above it; remote (the classroom's clients) puts the console (tui) on the server's seats, so it stands
# above both


def test_every_layer_is_a_folder_of_the_package_and_nothing_is_linked() -> None:
    for layer in LAYERS:
        assert (PKG / layer / "__init__.py").is_file(), f"src/liansuo/{layer} should be a package"
        assert not (ROOT / layer).exists(), f"{layer}/ at the top would give its modules a second name"
    if (ROOT / ".git").exists():  # what git tracks as a link (mode 120000)
        tracked = subprocess.run(["git", "ls-files", "-s"], cwd=ROOT, capture_output=True, text=True,
                                 check=True).stdout
        links = [line.split("\t", 1)[1] for line in tracked.splitlines() if line.startswith("120000")]
    else:  # an unpacked sdist: the tree itself
        links = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_symlink() and ".venv" not in p.parts]
    assert not links, f"symbolic links break a checkout without them (core.symlinks=false): {links}"


def test_a_layer_has_no_bare_name_from_the_repository_root() -> None:
    code = f"import importlib.util as u; print([n for n in {LAYERS!r} if u.find_spec(n)])"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", f"importable without liansuo. from the checkout: {out.strip()}"


def test_no_module_imports_a_layer_by_its_bare_name() -> None:
    """``import stations`` works in the checkout only (the top folder is on sys.path there), never installed."""
    bare = []
    files = [p for layer in LAYERS for p in (PKG / layer).rglob("*.py")] + list((ROOT / "tests").rglob("*.py"))
    for path in files:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                     else [])
            bare += [f"{path.relative_to(ROOT)}:{node.lineno}: {n}" for n in names if n.split(".")[0] in LAYERS]
    assert len(files) > 100
    assert not bare, "import these as liansuo.<layer>:\n" + "\n".join(bare)


def _imports() -> nx.DiGraph:
    """Module -> module it imports (anywhere in the file: at the top, in a function, for type checking only)."""
    files: dict[str, Path] = {}
    for layer in LAYERS:
        for p in (PKG / layer).rglob("*.py"):
            parts = p.relative_to(PKG).with_suffix("").parts
            files[".".join(("liansuo", *(parts[:-1] if parts[-1] == "__init__" else parts)))] = p
    graph = nx.DiGraph()
    for mod, path in files.items():
        package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                    base = f"{up}.{base}" if base else up
                names = [base, *(f"{base}.{a.name}" for a in node.names)]
            else:
                continue
            for name in names:
                while name and name not in files:
                    name = name.rpartition(".")[0]
                if name and name != mod and not mod.startswith(f"{name}."):  # not its own package's __init__
                    graph.add_edge(mod, name)
    return graph


def test_imports_point_down_and_close_no_circle() -> None:
    graph = _imports()
    assert graph.number_of_edges() > 300
    up = [f"{a} -> {b}" for a, b in graph.edges
          if (la := a.split(".")[1]) != (lb := b.split(".")[1]) and FLOOR[lb] >= FLOOR[la]]
    assert not up, "imports that do not point down:\n" + "\n".join(up)
    circles = [" -> ".join(c) for c in nx.simple_cycles(graph)]
    assert not circles, "modules that import each other:\n" + "\n".join(circles)


def test_nothing_of_the_simulated_station_reads_the_wall_clock() -> None:
    """Time is injected (docs/architecture.md): the front ends pace the world, proving and bench time their runs."""
    station_layers = ("kit", "rules", "stations", "circuits", "interlocking", "simulation", "classroom")
    clocks = {"monotonic", "perf_counter", "time", "time_ns", "sleep", "now", "utcnow", "today"}
    found = []
    for layer in station_layers:
        for path in (PKG / layer).rglob("*.py"):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            for node in ast.walk(tree):
                if isinstance(node, ast.Attribute) and node.attr in clocks and isinstance(node.value, ast.Name) \
                        and node.value.id in ("time", "datetime", "date"):
                    found.append(f"{path.relative_to(PKG)}:{node.lineno}: {node.value.id}.{node.attr}")
                if isinstance(node, ast.ImportFrom) and node.module in ("time", "datetime"):
                    found += [f"{path.relative_to(PKG)}:{node.lineno}: from {node.module} import {a.name}"
                              for a in node.names if a.name in clocks | {"datetime"}]
    assert not found, "the wall clock read below the front ends:\n" + "\n".join(found)
