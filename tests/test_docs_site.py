"""The documentation site builds as a reader gets it: the guides in docs/ and the API reference from the docstrings
(mkdocs.yml, docs/api.md), with ``--strict``, so a broken link, a missing anchor or an API name that no longer exists
fails here."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_the_site_builds_strict_with_the_api_reference(tmp_path: Path) -> None:
    site = tmp_path / "site"
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("load_station", "build_table", "verify_station", "Simulation", "Simulation.command",
                 "Simulation.aspect", "Simulation.route_state", "Result", "UnknownId"):
        assert f'id="liansuo.{name}"' in api, f"the API reference has no entry liansuo.{name}"
    assert (site / "station-format" / "index.html").is_file()
