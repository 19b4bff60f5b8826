"""Automatic station-to-station block (自动站间闭塞) with axle counters (计轴), as a signaller works it on
examples/stations/danxian.yaml, whose line SL to Station B is one block section IIAG counted at both ends."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import Driver

from liansuo.cli.main import main
from liansuo.interlocking.table.build import build_table
from liansuo.kit.source import StationError
from liansuo.proving.mutation.cli import run_mutants
from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.verify import verify_station
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load, load_text

DANXIAN = Path(__file__).resolve().parent.parent / "src" / "liansuo" / "examples" / "stations" / "danxian.yaml"


@pytest.fixture
def d() -> Driver:
    return Driver(Simulation(str(DANXIAN)))


def test_a_departure_route_blocks_the_line_and_the_block_restores_when_the_train_has_left_it(d: Driver) -> None:
    d("expect block-line SL idle", "train T1 at IG length=100 mode=signal", "route XI S", "run 3s",
      "expect block-line SL outbound", "expect signal XI L")
    d("run 40s", "expect block-line SL departed", "expect section IIAG occupied", "expect signal XI H")
    d("run 5min", "expect section IIAG free", "expect block-line SL idle")
    assert any("SL (station block): departed -> idle" in e for e in d.sim.event_texts())


def test_cancelling_the_departure_before_the_train_leaves_unblocks_the_line(d: Driver) -> None:
    d("route XI S", "run 3s", "expect block-line SL outbound", "cancel XI", "run 1s", "expect block-line SL idle")


def test_the_neighbours_block_keeps_our_departure_at_stop_until_its_train_has_arrived(d: Driver) -> None:
    d("neighbour SL block", "run 4s", "expect block-line SL inbound")
    d.refused("neighbour SL block", "already blocked")
    d("route XI S", "run 5s", "expect route XI-S locked", "expect signal XI H", "cancel XI")
    d("train T2 at IIAG length=100 mode=signal", "run 2s", "expect block-line SL arriving")
    d.refused("neighbour SL cancel", "train is on line SL")
    d("route S SI", "run 4min", "expect block-line SL idle", "expect section IIAG free")
    d("route XI S", "run 5s", "expect signal XI L")


def test_the_neighbour_cannot_block_a_line_we_have_blocked(d: Driver) -> None:
    d("route XI S", "run 3s", "expect signal XI L")
    d.refused("neighbour SL block", "already blocked (for our train)")


def test_a_disturbed_counter_holds_the_departure_until_the_sealed_reset(d: Driver) -> None:
    d.refused("axle-reset IIAG", "shows clear: nothing to reset")
    d("fault axle-miscount IIAG", "run 1s", "expect section IIAG occupied", "route XI S", "run 5s",
      "expect signal XI H", "repair axle-miscount IIAG", "run 1s", "expect section IIAG occupied")
    message = d.refused("axle-reset 2DG", "is a track circuit")
    assert "not counted by axle counters" in message
    d("cancel XI", "run 1s")
    first = d.sim.command("axle-reset IIAG")
    assert first.ok and "counter 1" in first.message and "confirm the line clear" in first.message
    d("run 1s", "expect section IIAG free", "route XI S", "run 5s", "expect signal XI L")
    d("fault axle-miscount IIAG", "run 1s", "cancel XI", "run 1s")
    assert "counter 2" in d.sim.command("axle-reset IIAG").message


def test_a_reset_under_a_train_shows_clear_and_counting_that_train_out_disturbs_the_count_again(d: Driver) -> None:
    d("train T2 at IIAG length=60 mode=signal", "run 1s", "expect section IIAG occupied", "axle-reset IIAG",
      "run 1s", "expect section IIAG free", "route S SI", "run 3min", "expect section IIAG occupied")


def test_axle_counters_see_every_axle_whatever_the_shunt_and_no_broken_rail(d: Driver) -> None:
    d("fault poor-shunt IIAG ohm=5", "train T2 at IIAG length=60", "run 1s", "expect section IIAG occupied")
    d2 = Driver(Simulation(str(DANXIAN)))
    d2("fault broken-rail IIAG", "run 1s", "expect section IIAG free")
    d2.refused("fault axle-miscount IG", "is a track circuit, not counted by axle counters")


def test_the_reset_is_refused_under_a_route() -> None:
    text = DANXIAN.read_text().replace("{id: 2DG, type: 25hz}", "{id: 2DG, type: axle_counter}")
    d = Driver(Simulation(load_text(text, "danxian-counted.yaml")))
    d("route XI S", "run 5s", "fault axle-miscount 2DG", "run 1s")
    d.refused("axle-reset 2DG", "locked in route XI-S")


def test_the_signed_table_and_the_aspects(capsys: pytest.CaptureFixture[str]) -> None:
    table = build_table(load(DANXIAN))
    r = table.routes["XI-S"]
    assert r.exit_link == "SL" and r.aspects == ("L",)  # no block signals: L or nothing
    assert main(["table", str(DANXIAN), "--format", "csv"]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if "由 IG 至 乙站" in line)
    assert "自动站间闭塞 IIAG 计轴空闲" in row


def test_verify_checks_the_station_block_liaison() -> None:
    report = verify_station(load(DANXIAN))
    assert report.ok, [f.detail for f in report.failures]
    for res in report.results:
        if res.id in ("XI-S", "X3-S"):
            assert res.aspects_seen == {"L"} and not [n for n in res.not_applicable if n.startswith("liaison")]


@pytest.mark.parametrize("mutant", ["station-block-ignores-neighbour", "station-block-blind-to-counters"])
def test_seeded_station_block_defects_are_caught(mutant: str) -> None:
    (result,) = run_mutants([str(DANXIAN)], [m for m in MUTANTS if m.name == mutant])
    assert result.by, f"{mutant} not caught"


@pytest.mark.parametrize(("edit", "message"), [
    (("sections: [IIAG]}", "sections: []}"), "station-to-station block line SL names no sections"),
    (("{id: IIAG, type: axle_counter,", "{id: IIAG, type: axle_counter, carrier: 2300-1,"),
     "section 'IIAG' (axle_counter) cannot have a ZPW-2000A carrier"),
    (("{id: J-S, at: 1800}", "{id: J-S, at: 1800, at2: 1803}"),
     "joint 'J-S' borders axle-counter section 'IIAG' but has a dead zone"),
])
def test_station_block_errors_name_file_and_line(edit: tuple[str, str], message: str) -> None:
    text = DANXIAN.read_text()
    assert edit[0] in text
    with pytest.raises(StationError) as exc:
        load_text(text.replace(edit[0], edit[1]), "bad.yaml")
    shown = str(exc.value)
    assert message in shown and "bad.yaml:" in shown
