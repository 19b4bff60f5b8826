"""Aspect rules (pluggable Chinese set), lamp downgrade, and the interlocking table's properties."""

from __future__ import annotations

import itertools
import json

import pytest
from conftest import Driver
from hypothesis import given
from hypothesis import strategies as st

from liansuo.cli.main import main
from liansuo.interlocking.aspects import downgrade
from liansuo.interlocking.table.build import build_table
from liansuo.kit.source import StationError
from liansuo.rules import load_rules
from liansuo.stations.library import bundled
from liansuo.stations.loader import load, load_text

RULES = load_rules()
ALL_LAMPS = ["L", "L2", "U", "U2", "H", "B", "A", "flasher"]


@given(st.sampled_from(sorted(RULES.downgrade)), st.sets(st.sampled_from(ALL_LAMPS)))
def test_a_dark_lamp_never_makes_an_aspect_more_permissive(aspect: str, dark: set[str]) -> None:
    assert RULES.aspects.rank_of(downgrade(aspect, dark, RULES)) <= RULES.aspects.rank_of(aspect)


@pytest.mark.parametrize(("aspect", "dark", "shown"), [
    ("LU", {"L"}, "U"),  # a dark green on LU leaves U
    ("UU", {"U2"}, "H"),  # a dark second yellow must give H, not a lone U
    ("USU", {"flasher"}, "UU"),
    ("L", {"L"}, "H"),
    ("B", {"B"}, "A"),
    ("L", set(), "L"),
])
def test_downgrade_order(aspect: str, dark: set[str], shown: str) -> None:
    assert downgrade(aspect, dark, RULES) == shown


def test_dark_green_on_home_signal_closes_it(jiaopei: Driver) -> None:
    jiaopei("route X XI", "route XI S", "block-line SL request", "run 6s", "expect signal X L")
    jiaopei("fault filament X lamp=L which=both", "run 1s", "expect signal X H", "expect alarm lamp(s) L dark")


def test_dark_yellow_closes_the_signal_and_it_stays_closed(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "expect signal X U")
    jiaopei("fault filament X lamp=U which=both", "run 1s", "expect signal X H", "repair filament X", "run 5s",
            "expect signal X H", "reopen X", "run 1s", "expect signal X U")


def test_red_lamp_transfer_keeps_the_signal_in_rear_closed(jiaopei: Driver) -> None:
    jiaopei("fault filament XI lamp=H which=both", "run 1s", "expect alarm XI: H lamp dark", "route X XI", "run 1s",
            "expect signal X H")


# ---- table ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(bundled()))
def test_conflicts_are_symmetric_and_agree_with_the_oracle(name: str) -> None:
    """Every pair the oracle keeps apart (judged from the geometry, not from the table) is listed as conflicting,
    and no other pair is; conflicts are listed on both routes."""
    from liansuo.proving.oracle.pairs import PaperOracle
    from liansuo.proving.verify.against import spec

    st = load(name)
    table = build_table(st)
    oracle = PaperOracle(st, RULES)
    routes = list(table.routes.values())
    assert routes
    for a, b in itertools.combinations(routes, 2):
        assert (a.id in b.conflicts) == (b.id in a.conflicts) and (a.id in b.conditional) == (b.id in a.conditional)
        if a.signal == b.signal:
            continue
        apart = oracle.apart(spec(a), spec(b))
        listed = b.id in a.conflicts or b.id in a.conditional
        assert bool(apart) == listed, (a.id, b.id, apart, a.conflicts.get(b.id))


def test_jiaopei_table_rows_a_signal_engineer_expects() -> None:
    table = build_table(load("jiaopei"))
    r = table.routes["X-XI"]
    assert r.category == "receiving" and r.sections == ("7DG", "1DG", "IG") and r.approach == ("IAG",)
    assert {(t.id, t.position.value, t.role) for t in r.turnouts} == {
        ("7", "normal", "route"), ("1", "normal", "route"), ("3", "normal", "driven")}  # 3 moves with 1 (1/3)
    # straight to XI, which departs onto a 64D line and so shows only L: X shows L, or U with XI at stop, never LU
    assert r.aspects == ("L", "U") and table.routes["XI-S"].aspects == ("L",)
    assert table.routes["X-X3"].aspects == ("UU",)  # No. 12 turnouts: no USU
    assert table.routes["XI-S"].category == "departure" and table.routes["XI-S"].exit_link == "SL"
    assert "S-SI" in r.opposing and "X-X3" not in r.opposing
    assert table.routes["D1-5GA"].sections[-1] == "5G"  # shunting to the buffer stop of the spur
    assert table.throats == {"X": ("1", "3", "5", "7"), "S": ("2", "4", "6")}


def test_gaotie_home_signal_may_show_usu_over_no18() -> None:
    table = build_table(load("gaotie"))
    assert "USU" in table.routes["X-X3"].aspects
    assert table.routes["XI-XFCK"].aspects == ("L", "LU", "U")
    assert table.routes["X-XI"].aspects == ("L", "LU", "U")  # XI shows U with one clear block section: X shows LU


def test_override_forbid_removes_a_route_and_unknown_route_is_an_error_with_line() -> None:
    base = bundled()["jiaopei"].read_text(encoding="utf-8")
    table = build_table(load_text(base + "overrides:\n  forbid: [D1-5GA]\n", "j.yaml"))
    assert "D1-5GA" not in table.routes
    with pytest.raises(StationError) as err:
        build_table(load_text(base + "overrides:\n  forbid: [D1-NOPE]\n", "j.yaml"))
    d = err.value.diagnostics[0]
    assert d.file == "j.yaml" and d.line == base.count("\n") + 2 and "D1-NOPE" in d.message


def test_override_protection_adds_a_protection_turnout() -> None:
    base = bundled()["jiaopei"].read_text(encoding="utf-8")
    extra = "overrides:\n  protection: [{route: XI-S, turnout: \"5\", position: normal}]\n"
    r = build_table(load_text(base + extra, "j.yaml")).routes["XI-S"]
    assert any(t.id == "5" and t.role == "protection" for t in r.turnouts)


@pytest.mark.parametrize("fmt", ["text", "csv", "json"])
def test_table_command_formats(fmt: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["table", "jiaopei", "--format", fmt]) == 0
    out = capsys.readouterr().out
    if fmt == "json":
        data = json.loads(out)
        assert data["station"] == "jiaopei"
        row = next(r for r in data["routes"] if r["id"] == "X-XI")
        assert {"id", "kind", "start", "end", "via", "signal", "turnouts", "sections", "approach",
                "conflicts"} <= set(row)
        assert row["kind"] == "train" and {"id": "3", "position": "normal", "role": "driven"} in row["turnouts"]
        assert row["exit_link"] is None and row["leads_into"] is None
        d2xi = next(r for r in data["routes"] if r["id"] == "D2-XI")
        assert d2xi["leads_into"] == "IG" and "X-XI" in d2xi["conflicts"]
    elif fmt == "csv":
        # the signed layout's cells, keyed by route id (tests/test_signed_table.py checks them)
        assert out.splitlines()[0].startswith("id,group,no,route,mode,buttons")
        assert any(line.startswith("X-XI,下行接车 X咽喉,") for line in out.splitlines())
    else:
        assert "联锁表" in out and "至 IG" in out and "1/3" in out


def test_variant_route_by_via_button_takes_the_detour(capsys: pytest.CaptureFixture[str]) -> None:
    from liansuo.simulation.sim import Simulation

    table = build_table(load("gaotie"))
    v = table.routes["X-XI(BA1)"]
    assert v.via == ("BA1",) and "11-13DG" in v.sections and v.aspects == ("UU",)
    assert "X-XI" in v.conflicts  # same start signal, shared sections
    # a route over one diagonal of the scissors keeps the other pair normal: with both pairs reverse the diagonals
    # meet at the diamond
    assert v.diamonds == ("XD1",)
    assert {(t.id, t.position.value) for t in v.turnouts if t.role == "protection"} >= {("5", "normal"),
                                                                                          ("7", "normal")}
    d = Driver(Simulation("gaotie"))
    d("route X BA1 XI", "run 15s", "expect turnout 13 reverse locked", "expect turnout 1 reverse locked",
      "expect signal X UU", "expect route X-XI(BA1) open")
