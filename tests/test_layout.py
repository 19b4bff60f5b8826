"""The repository's layout: a folder per layer at the top, installed and linked as ``liansuo.<layer>``."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("stations", "circuits", "interlocking", "simulation", "proving", "bench", "tui", "cli")


def test_every_layer_is_linked_into_the_package() -> None:
    for layer in LAYERS:
        link = ROOT / "liansuo" / layer
        assert link.is_symlink(), f"liansuo/{layer} should be a link to ../{layer}"
        assert link.resolve() == (ROOT / layer).resolve()
        assert (ROOT / layer / "__init__.py").is_file()


def test_no_module_imports_a_layer_by_its_bare_name() -> None:
    """``import stations`` works in the checkout only (the top folder is on sys.path there), never installed."""
    bare = []
    files = [p for layer in LAYERS for p in (ROOT / layer).rglob("*.py")] + list((ROOT / "tests").rglob("*.py"))
    for path in files:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                     else [])
            bare += [f"{path.relative_to(ROOT)}:{node.lineno}: {n}" for n in names if n.split(".")[0] in LAYERS]
    assert len(files) > 100
    assert not bare, "import these as liansuo.<layer>:\n" + "\n".join(bare)
