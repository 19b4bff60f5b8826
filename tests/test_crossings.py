"""Diamond crossings (菱形交叉): a scissors crossover's diamond found from the geometry when the file leaves it out, a
stand-alone diamond whose two tracks lie in two sections (or in one), and track conditions the file adds."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import edit

from liansuo.interlocking.table.build import build_table
from liansuo.kit.source import StationError
from liansuo.stations.library import resolve
from liansuo.stations.loader import load_text

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
SHUANGXIAN = (PKG / "examples" / "stations" / "shuangxian.yaml").read_text(encoding="utf-8")
JIAOCHA = (PKG / "examples" / "stations" / "jiaocha.yaml").read_text(encoding="utf-8")
DOUBLESLIP = (PKG / "examples" / "stations" / "doubleslip.yaml").read_text(encoding="utf-8")


def refusal(text: str) -> str:
    with pytest.raises(StationError) as exc:
        load_text(text, "s.yaml")
    return "\n".join(str(d) for d in exc.value.diagnostics)


@pytest.mark.parametrize(("text", "diamond", "tracks", "at"), [
    (SHUANGXIAN, "diamonds:\n  - {id: XD1, tracks: [t-4r, t-8r], at: 3933}\n", "t-4r, t-8r", "3933"),
    (resolve("gaotie").read_text(encoding="utf-8"), "diamonds:\n  - {id: XD1, tracks: [t-3r, t-7r], at: 4573}\n",
     "t-3r, t-7r", "4573"),
])
def test_a_scissors_crossover_without_its_diamond_is_refused_with_the_diamond_to_declare(
        text: str, diamond: str, tracks: str, at: str) -> None:
    why = refusal(edit(text, (diamond, "")))
    assert "cross each other (a scissors crossover, 交叉渡线)" in why and "no diamond is declared" in why
    assert f"declare it: 'diamonds: [{{id: XD, tracks: [{tracks}], at: {at}}}]'" in why


def test_a_double_slip_and_parallel_crossovers_are_no_scissors() -> None:
    load_text(DOUBLESLIP, "doubleslip.yaml")  # its slip roads do not cross: its straight roads do, declared
    load_text(JIAOCHA, "jiaocha.yaml")


def test_a_route_over_a_stand_alone_diamond_checks_the_crossing_tracks_section() -> None:
    t = build_table(load_text(JIAOCHA, "jiaocha.yaml"))
    for rid in ("X-XI", "X-X2", "SI-X", "S2-X"):  # over the main line's side of XD9
        assert [(f.section, f.diamond) for f in t.routes[rid].fouling] == [("9WG", "XD9")], rid
    for rid in ("D1-D3", "D3-D1"):  # over the goods track's side
        assert ("5DG", "XD9") in [(f.section, f.diamond) for f in t.routes[rid].fouling], rid
    assert "D1-D3" in t.routes["X-XI"].conflicts


def test_both_tracks_of_a_diamond_may_lie_in_one_section() -> None:
    one = edit(JIAOCHA, ("  - {id: t-9WG, from: J-9a, to: J-9b, section: 9WG, row: -1}",
                         "  - {id: t-9WG, from: J-9a, to: J-9b, section: 5DG, row: -1}"))
    one = edit(one, ("  - {id: 9WG, type: 25hz, name: 货物联络线}\n", ""))
    t = build_table(load_text(one, "one.yaml"))
    assert "5DG" in t.routes["D1-D3"].sections and "5DG" in t.routes["X-XI"].sections


def test_the_file_can_add_a_track_condition_to_a_route() -> None:
    added = JIAOCHA + "\noverrides:\n  fouling:\n    - {route: X-XI, section: QXG}\n"
    t = build_table(load_text(added, "added.yaml"))
    assert "QXG" in [f.section for f in t.routes["X-XI"].fouling]
    with pytest.raises(StationError) as exc:
        build_table(load_text(JIAOCHA + "\noverrides:\n  fouling:\n    - {route: X-XI, section: 1DG}\n", "a.yaml"))
    assert "already checks section 1DG" in str(exc.value.diagnostics[0])
    unknown = JIAOCHA + "\noverrides:\n  fouling:\n    - {route: X-XI, section: NOPE}\n"
    assert "unknown section 'NOPE'" in refusal(unknown)
