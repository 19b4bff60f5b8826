"""A train route never runs through a station track (股道) out into the far throat: where a track has no train signal
at its far end, the path through it is left out of the table with a design warning (a real table has no route that
receives and departs in one, or leaves onto a line against its direction)."""

from __future__ import annotations

from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.interlocking.table.build import build_table
from liansuo.proving.verify import verify_station
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
BROKEN = PKG / "examples" / "broken" / "no-starting-signal.yaml"


def test_a_home_signal_gets_no_route_through_a_track_without_its_starting_signal() -> None:
    table = build_table(load(BROKEN))
    assert not [r for r in table.routes.values() if r.signal == "X" and r.end == "XFK2"]
    assert {r.id for r in table.routes.values() if r.signal == "X"} == {"X-XI"}
    assert len(table.warnings) == 1
    w = table.warnings[0]
    assert w.severity == "warning" and "station track IIG has no down train signal at J-IIS" in w.message
    assert "X to XFK2" in w.message and w.line > 1


def test_check_and_table_print_the_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(BROKEN)]) == 0
    out = capsys.readouterr().out
    assert "warnings     1" in out and "IIG has no down train signal at J-IIS" in " ".join(out.split())
    assert main(["table", str(BROKEN)]) == 0
    out, err = capsys.readouterr()
    assert "IIG has no down train signal at J-IIS" in err
    assert "XFK2" not in out.split("== 下行发车")[0]  # no receiving row from X that leaves by XFK2


def test_the_bundled_and_example_stations_lose_no_route() -> None:
    examples = sorted((PKG / "examples" / "stations").glob("*.yaml"))
    for name in ("jiaopei", "gaotie", "depot", *(str(p) for p in examples)):
        assert build_table(load(name)).warnings == [], name


JIAOPEI = PKG / "stations" / "library" / "jiaopei.yaml"
X3 = "  - {id: X3, kind: starting, at: J-3G2, direction: down, lamps: [L, H, B], buttons: [train, shunt]}\n"


@pytest.mark.parametrize("x3", [
    X3.replace("buttons: [train, shunt]", "buttons: []"),  # a starting signal without its train button
    "  - {id: X3, kind: shunting, at: J-3G2, direction: down, lamps: [A, B], buttons: [shunt]}\n",  # shunting only
    "",  # no starting signal at all
], ids=["no-buttons", "shunting-only", "removed"])
def test_a_starting_signal_that_cannot_start_a_train_leaves_no_route_through_its_track(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], x3: str) -> None:
    """Issue 45, item 5: with X3 unable to show a train aspect, a route X -> S through 3G would make X show a
    proceed aspect with nothing beyond 3G to read; check warns, the table has no such route, and verify passes."""
    text = JIAOPEI.read_text(encoding="utf-8")
    assert text.count(X3) == 1
    path = tmp_path / "jiaopei.yaml"
    path.write_text(text.replace(X3, x3), encoding="utf-8")

    assert main(["check", str(path)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "warnings 1" in out and "station track 3G has no down train signal at J-3G2" in out, out
    assert "the path from X to S would run on through it" in out

    station = load(str(path))
    table = build_table(station)
    from_x = [r for r in table.routes.values() if r.signal == "X" and r.kind == "train"]
    assert [r.id for r in from_x] == ["X-XI"]  # nothing from X into 3G, and so none through it onto the line
    assert not [r for r in table.routes.values() if r.kind == "train" and r.direction == "down" and "3G" in r.sections]

    report = verify_station(station)
    assert report.ok, report
