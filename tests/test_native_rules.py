"""The rules of the native build (kit/native.py), checked on the sources in a second, without a compiler: no Python
class extends a compiled one, nothing replaces what a compiled module defines, the station model stays Python.
(tests/test_native.py builds the native wheel and compares its answers, on demand.)"""

from __future__ import annotations

import ast
from pathlib import Path

from liansuo.kit.native import MODULES, NEVER, PURE_ONLY

PKG = Path(__file__).resolve().parents[1] / "src" / "liansuo"


def _module(pkg: Path, path: Path) -> str:
    parts = path.relative_to(pkg.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _names(tree: ast.Module, module: str, is_package: bool) -> dict[str, str]:
    """Local name -> the dotted name it stands for (a module, or a module's attribute), from the file's imports."""
    here = module if is_package else module.rpartition(".")[0]
    names: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                names[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = here.rsplit(".", node.level - 1)[0] if node.level > 1 else here
                base = f"{up}.{base}" if base else up
            for a in node.names:
                names[a.asname or a.name] = f"{base}.{a.name}"
    return names


def _dotted(node: ast.expr, names: dict[str, str], module: str, local: set[str]) -> str | None:
    if isinstance(node, ast.Name):
        if node.id in local:
            return f"{module}.{node.id}"
        return names.get(node.id)
    if isinstance(node, ast.Attribute):
        head = _dotted(node.value, names, module, local)
        return f"{head}.{node.attr}" if head else None
    return None


def rule_breaks(pkg: Path, compiled: tuple[str, ...], pure_only: tuple[str, ...] = ()) -> list[str]:
    """Where the sources under ``pkg`` (a package folder) break rules 1 and 2 for the ``compiled`` modules (paths
    inside the package without ".py"); the modules of ``pure_only`` may replace (rule 2)."""
    name = pkg.name
    compiled_mods = {f"{name}.{m.replace('/', '.')}" for m in compiled}
    pure_mods = {f"{name}.{m.replace('/', '.')}" for m in pure_only}
    files = {_module(pkg, p): p for p in sorted(pkg.rglob("*.py"))}
    trees = {m: ast.parse(p.read_text(encoding="utf-8")) for m, p in files.items()}
    compiled_classes = {f"{m}.{n.name}" for m in compiled_mods for n in trees[m].body if isinstance(n, ast.ClassDef)}
    breaks = []
    for module, tree in trees.items():
        where = files[module].relative_to(pkg)
        names = _names(tree, module, files[module].name == "__init__.py")
        local = {n.name for n in tree.body if isinstance(n, ast.ClassDef | ast.FunctionDef)}
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and module not in compiled_mods:
                for base in node.bases:
                    target = _dotted(base, names, module, local)
                    if target in compiled_classes:
                        breaks.append(f"{where}:{node.lineno}: {node.name} extends the compiled {target} (rule 1)")
            if module in pure_mods:
                continue
            if isinstance(node, ast.Assign | ast.AugAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for t in targets:
                    if isinstance(t, ast.Attribute):
                        owner = _dotted(t.value, names, module, local)
                        if owner in compiled_classes or owner in compiled_mods:
                            breaks.append(f"{where}:{node.lineno}: assigns {owner}.{t.attr} (rule 2)")
            elif isinstance(node, ast.Call):
                for arg, after in zip(node.args, node.args[1:], strict=False):
                    owner = _dotted(arg, names, module, local)
                    if ((owner in compiled_classes or owner in compiled_mods)
                            and isinstance(after, ast.Constant) and isinstance(after.value, str)):
                        breaks.append(f"{where}:{node.lineno}: replaces {owner}.{after.value} (rule 2)")
    return breaks


def test_the_compiled_modules_exist_and_the_station_model_stays_python() -> None:
    assert len(MODULES) == len(set(MODULES)) >= 30
    for m in (*MODULES, *PURE_ONLY):
        assert (PKG / f"{m}.py").is_file(), f"kit/native.py names {m}, which is no module of liansuo"
    assert not [m for m in MODULES if m.startswith(NEVER)]


def test_the_sources_keep_the_native_builds_rules() -> None:
    assert rule_breaks(PKG, MODULES, PURE_ONLY) == []


def test_the_seeded_defects_replace_compiled_code_so_they_run_pure_only() -> None:
    """What makes the exemption needed: without it, the mutants break rule 2 (and the check sees them)."""
    found = rule_breaks(PKG, MODULES)
    assert found and all(b.startswith(("proving/mutation/cbidefects.py:", "proving/mutation/tabledefects.py:"))
                         for b in found)


def test_the_check_finds_each_kind_of_break(tmp_path: Path) -> None:
    pkg = tmp_path / "pkg"
    (pkg / "hot").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "hot" / "__init__.py").write_text("")
    (pkg / "hot" / "cycle.py").write_text("class Core:\n    def step(self) -> None: ...\n\n\ndef rule() -> bool:\n"
                                          "    return True\n")
    (pkg / "cold.py").write_text(
        "from unittest import mock\n"
        "from pkg.hot import cycle\n"
        "from pkg.hot.cycle import Core as C\n\n\n"
        "class Faster(C):\n    pass\n\n\n"
        "class Alsofast(cycle.Core):\n    pass\n\n\n"
        "C.step = lambda self: None\n"
        "setattr(cycle.Core, 'step', None)\n"
        "mock.patch.object(cycle, 'rule', lambda: False)\n")
    (pkg / "fine.py").write_text("from pkg.hot.cycle import Core\n\n\nclass Mine:\n    pass\n\n\n"
                                 "Mine.step = None\ncore = Core()\n")
    found = rule_breaks(pkg, ("hot/cycle",))
    assert [b.split(": ", 1)[0] for b in found] == ["cold.py:6", "cold.py:10", "cold.py:14", "cold.py:15",
                                                   "cold.py:16"], found
    assert rule_breaks(pkg, ("hot/cycle",), ("cold",)) == [b for b in found if "rule 1" in b]
