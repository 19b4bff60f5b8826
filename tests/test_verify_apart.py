"""Compatible pairs of routes apart (issue 13): verify proves them without a simulation, and simulates every pair whose
routes name an element in common, and every pair of a route that failed on its own, so its report is the same as
with ``--simulate-all-pairs``."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from liansuo.cli.main import main
from liansuo.interlocking.core import Core
from liansuo.interlocking.selection import Selection
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.proving import verify as verify_module
from liansuo.proving.mutation.cli import load_station
from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.oracle.pairs import PaperOracle
from liansuo.proving.verify import near_routes, verify_station
from liansuo.proving.verify.against import spec
from liansuo.proving.verify.apart import table_reach
from liansuo.proving.verify.plan import cover_adjacent, plan
from liansuo.rules import load_rules
from liansuo.stations.station import Station

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "liansuo"
STATIONS = ["jiaopei", "gaotie", "depot", *(str(PKG / "examples" / "stations" / f"{s}.yaml")
                                            for s in ("danxian", "shuangxian", "doubleslip")), "hub:10:4"]
_NOT_ELEMENTS = {"id", "kind", "category", "direction", "aspects", "conflicts", "conflict_reasons",
                 "conditional_conflicts", "opposing", "position", "role", "release_s", "alternative", "length_m"}


def _names(row: Any) -> Iterator[str]:
    """Every name of a station element in a printed row of the table (``Route.as_dict``), whatever field holds it:
    each string in it, and each key of a ``when`` (turnouts), except the fields that name no element."""
    if isinstance(row, dict):
        for key, value in row.items():
            if key == "when":
                yield from value
            elif key not in _NOT_ELEMENTS:
                yield from _names(value)
    elif isinstance(row, list):
        for value in row:
            yield from _names(value)
    elif isinstance(row, str):
        yield row


def _row_names(st: Station, table: InterlockingTable) -> dict[str, set[str]]:
    """Each route's element names, a crossover's turnouts standing for each other (they move as one)."""
    out = {}
    for r in table.routes.values():
        names = set(_names(r.as_dict()))
        for t in list(names):
            pair = st.turnouts[t].pair if t in st.turnouts else None
            if pair:
                names |= set(st.pairs[pair])
        out[r.id] = names
    return out


def unsimulated_sharing(st: Station) -> list[tuple[str, str]]:
    """Compatible pairs left to the argument of .apart although their printed rows share an element name or the
    oracle's footprints meet: each should have been simulated."""
    table = build_table(st)
    order = list(table.routes.values())
    oracle = PaperOracle(st, load_rules())
    prints = [oracle.footprint(spec(r)) for r in order]
    work = plan(table, None, pairs=True, near=verify_module.near_routes(st, order, prints, None))
    simulated = {frozenset(p) for u in work.units if u.kind == "batches" for _, pairs in u.batches for p in pairs}
    assert sum(x.bit_count() for x in work.compatible) // 2 == len(simulated) + work.pairs_apart
    names = _row_names(st, table)
    wrong = []
    for i, a in enumerate(order):
        for j in range(i + 1, len(order)):
            b = order[j]
            meet = names[a.id] & names[b.id] or prints[i] & prints[j]
            if meet and work.compatible[i] >> j & 1 and frozenset((a.id, b.id)) not in simulated:
                wrong.append((a.id, b.id))
    return wrong


@settings(max_examples=80, deadline=None)
@given(hs.integers(2, 14).flatmap(lambda n: hs.tuples(hs.just(n), hs.sets(hs.tuples(
    hs.integers(0, n - 1), hs.integers(0, n - 1), hs.booleans()).filter(lambda e: e[0] < e[1])))),
    hs.integers(2, 6))
def test_the_cover_of_some_pairs_proves_each_once_in_groups_of_compatible_routes(
        graph: tuple[int, set[tuple[int, int, bool]]], size: int) -> None:
    n, edges = graph
    adj, need = [0] * n, [0] * n
    wanted = set()
    for a, b, needed in edges:
        adj[a] |= 1 << b
        adj[b] |= 1 << a
        if needed:
            need[a] |= 1 << b
            need[b] |= 1 << a
            wanted.add((a, b))
    groups = cover_adjacent(adj, max_size=size, need=need)
    proved = [e for _, new in groups for e in new]
    assert sorted(proved) == sorted(wanted)  # every pair needed, once, and no other
    for group, _ in groups:
        assert len(group) <= size
        assert all(adj[a] >> b & 1 for i, a in enumerate(group) for b in group[i + 1:])  # pairwise compatible


@pytest.mark.parametrize("name", STATIONS)
def test_every_compatible_pair_whose_routes_share_an_element_is_simulated(name: str) -> None:
    assert unsimulated_sharing(load_station(name)) == []


def _without_approach(st: Station, r: Any) -> frozenset[str]:
    """table_reach with a seeded defect: the approach sections left out (those the route names only there)."""
    gone = {f"section {s}" for s in r.approach} - {f"section {s}" for s in (*r.sections, *r.overlap_sections)}
    return table_reach(st, r) - gone


def test_a_reach_that_leaves_out_the_approach_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(verify_module, "table_reach", _without_approach)
    assert any(unsimulated_sharing(load_station(name)) for name in STATIONS)


def test_near_routes_without_the_oracles_footprints_are_caught_on_a_table_missing_its_overlaps(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # the table's rows alone name every element the footprints hold, on every station here, as long as the table is
    # right; the footprints keep a pair simulated when the table leaves an element out
    was = verify_module.near_routes
    monkeypatch.setattr(verify_module, "near_routes", lambda st, order, prints, focus: was(
        st, order, [frozenset()] * len(prints), focus))
    danxian = load_station(str(PKG / "examples" / "stations" / "danxian.yaml"))
    assert unsimulated_sharing(danxian) == []  # the table is right: its rows say it all
    with next(m for m in MUTANTS if m.name == "no-overlap").applied():
        assert unsimulated_sharing(danxian)
        monkeypatch.setattr(verify_module, "near_routes", was)
        assert unsimulated_sharing(danxian) == []


@pytest.mark.parametrize("name", ["jiaopei", str(PKG / "examples" / "stations" / "shuangxian.yaml")])
def test_proving_pairs_apart_leaves_the_checks_and_the_verdict_as_simulating_them(name: str) -> None:
    fast = verify_station(name)
    full = verify_station(name, simulate_all=True)
    assert fast.ok and full.ok
    assert fast.pairs_apart > 0 and full.pairs_apart == 0
    assert fast.checks == full.checks
    assert fast.pairs_compatible == full.pairs_compatible


def _a_route_with_pairs_apart(station: str) -> tuple[str, int, int]:
    """The route with the most pairs apart, how many it has, and how many the station has."""
    st = load_station(station)
    table = build_table(st)
    order = list(table.routes.values())
    oracle = PaperOracle(st, load_rules())
    work = plan(table, None, pairs=True, near=near_routes(st, order, [oracle.footprint(spec(r)) for r in order],
                                                          None))
    mask, route = max(zip(work.apart, work.ids, strict=True), key=lambda x: x[0].bit_count())
    return route, mask.bit_count(), work.pairs_apart


def test_a_route_that_fails_on_its_own_has_its_pairs_apart_simulated_with_the_same_failures(
        monkeypatch: pytest.MonkeyPatch) -> None:
    broken, its_apart, apart = _a_route_with_pairs_apart("jiaopei")
    was = Core.open_blocker

    def open_blocker(self: Core, rs: Any, **kw: Any) -> str:
        return "a seeded defect" if rs.route.id == broken else was(self, rs, **kw)

    monkeypatch.setattr(Core, "open_blocker", open_blocker)
    fast = verify_station("jiaopei")
    full = verify_station("jiaopei", simulate_all=True)
    assert its_apart > 0 and fast.pairs_apart == apart - its_apart  # its pairs apart were simulated

    def seen(rep: Any) -> list[tuple[str, str, tuple[str, ...]]]:
        return sorted((f.check, f.subject, tuple(f.steps)) for f in rep.failures)

    compatible = [f for f in fast.failures if f.check == "compatible"]
    assert compatible and all(broken in f.subject for f in compatible)
    assert seen(fast) == seen(full)
    assert fast.checks == full.checks


def test_the_report_says_how_many_pairs_were_proven_apart(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify", "jiaopei"]) == 0
    assert "of them apart, proven without a simulation" in capsys.readouterr().out
    assert main(["verify", "jiaopei", "--simulate-all-pairs"]) == 0
    out = capsys.readouterr().out
    assert "apart" not in out and out.strip().splitlines()[-1].startswith("PASS: 3023 checks")


def test_a_coupling_through_no_shared_element_is_found_only_when_every_pair_is_simulated(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The limit docs/verify.md states, made visible: an interlocking that refuses one route while another it shares
    nothing with is set passes the argument of .apart, and fails once every compatible pair is simulated."""
    st = load_station("jiaopei")
    table = build_table(st)
    order = list(table.routes.values())
    oracle = PaperOracle(st, load_rules())
    work = plan(table, None, pairs=True, near=near_routes(st, order, [oracle.footprint(spec(r)) for r in order],
                                                          None))
    i = next(k for k, m in enumerate(work.apart) if m)
    a, b = work.ids[i], work.ids[(work.apart[i] & -work.apart[i]).bit_length() - 1]
    was = Selection.route_blocker

    def route_blocker(self: Selection, r: Any, run_on: Any = None, **kw: Any) -> str:
        coupled = {a: b, b: a}.get(r.id)
        return "a seeded coupling" if coupled in self.core.routes else was(self, r, run_on, **kw)

    monkeypatch.setattr(Selection, "route_blocker", route_blocker)
    assert verify_station("jiaopei").ok  # proven apart: the defect goes unseen, as the docs say
    full = verify_station("jiaopei", simulate_all=True)
    assert [f.subject for f in full.failures if f.check == "compatible"] == [f"{a} + {b}"]
    assert not full.ok
