"""Text output fits a terminal of 100 columns (the interlocking table 120), with one way of writing lengths and
counts: every text command run as a user runs it, on every bundled and example station."""

from __future__ import annotations

import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

from liansuo.kit.fit import fit, metres, plural

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
EXAMPLES = sorted(str(p.relative_to(ROOT)) for p in (PKG / "examples" / "stations").glob("*.yaml"))
STATIONS = ["jiaopei", "gaotie", "depot", *EXAMPLES, "src/liansuo/examples/broken/gaotie-no-diamond-protection.yaml"]


def width(line: str) -> int:
    """Terminal columns, counted here on their own: CJK wide and full-width characters take two."""
    return sum(2 if unicodedata.east_asian_width(c) in ("W", "F") else 1 for c in line)


def liansuo(*args: str) -> str:
    done = subprocess.run([sys.executable, "-m", "liansuo.cli", *args], capture_output=True, text=True, cwd=ROOT)
    return done.stdout + done.stderr


def too_wide(text: str, limit: int = 100) -> list[str]:
    """Lines wider than ``limit``, except a single word that cannot be folded (a long path)."""
    return [line for line in text.splitlines() if width(line) > limit and " " in line.strip()]


@pytest.mark.parametrize("station", STATIONS)
def test_check_fits_100_columns(station: str) -> None:
    out = liansuo("check", station)
    assert out.strip()
    assert too_wide(out) == []


@pytest.mark.parametrize("args", [("stations",), ("zpw", "gaotie"), ("25hz", "jiaopei", "--section", "IG"),
                                  ("verify", "src/liansuo/examples/stations/minimal.yaml"),
                                  ("soak", "jiaopei", "--steps", "150"),
                                  ("run", "src/liansuo/examples/scenarios/jiaopei-receive-depart.yaml"),
                                  ("test", "src/liansuo/examples/scripts/jiaopei-interlocking-test.yaml"),
                                  ("test", "-v", "src/liansuo/examples/scripts/dead-zone-hazard.yaml"),
                                  ("mutate", "--list"), ("exercise", "list"),
                                  ("explore", "src/liansuo/examples/stations/minimal.yaml", "--depth", "2")])
def test_text_commands_fit_100_columns(args: tuple[str, ...]) -> None:
    out = liansuo(*args)
    assert out.strip()
    assert too_wide(out) == []


def test_the_table_fits_120_columns() -> None:
    out = liansuo("table", "gaotie")
    assert too_wide(out, 120) == []


def test_verify_counts_in_words() -> None:
    last = liansuo("verify", "src/liansuo/examples/stations/minimal.yaml").strip().splitlines()[-1]
    assert "(2 routes, 1 pair)" in last and "0 failures" in last and "1 pairs" not in last


def test_lengths_are_written_one_way() -> None:
    out = " ".join(liansuo("check", "gaotie").split())  # as read, across folded lines
    assert "11.2 m" in out and "8.45 m" in out and "193.61 m" in out and "140 m long" in out
    assert "11.20 m" not in out and "140.0 m" not in out and "-0" not in out


def test_fold_keeps_words_and_indents() -> None:
    line = "  " + " ".join(f"word{i}" for i in range(40))
    folded = fit(line).splitlines()
    assert len(folded) > 1 and all(width(x) <= 100 for x in folded)
    assert all(x.startswith("      ") for x in folded[1:])
    assert " ".join(" ".join(folded).split()) == " ".join(line.split())
    assert fit("/" + "x" * 150) == "/" + "x" * 150  # one word is never cut
    assert width(fit("站" * 30 + " " + "站" * 30 + " " + "站" * 30).splitlines()[0]) <= 100


def test_numbers_and_plurals() -> None:
    assert [metres(x) for x in (-0.001, 140.0, 11.2, 8.446, 193.614)] == ["0 m", "140 m", "11.2 m", "8.45 m",
                                                                            "193.61 m"]
    assert (plural(1, "pair"), plural(2, "pair"), plural(0, "failure")) == ("1 pair", "2 pairs", "0 failures")
