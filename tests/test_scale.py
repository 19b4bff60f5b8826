"""Scale (issue 13): the hub generator on the command line, compatible pairs proved in batches, verify and soak fanned
out on Dask with the same report, the table written row by row and the same on every run."""

from __future__ import annotations

import copy
import json
import os
import random
import subprocess
import sys
from itertools import combinations
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liansuo.interlocking.table.build import InterlockingTable, Route, build_table
from liansuo.interlocking.table.text import as_json
from liansuo.proving.progress import progress
from liansuo.proving.soak.cli import soak_runs
from liansuo.proving.spread import client
from liansuo.proving.verify import verify_station
from liansuo.proving.verify.plan import CHAIN, Batch, by_turnouts, cover, plan
from liansuo.stations.loader import load, load_text

LIANSUO = [sys.executable, "-m", "liansuo.cli"]


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 14).flatmap(lambda n: st.tuples(st.just(n), st.sets(
    st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda e: e[0] < e[1])))),
    st.integers(2, 6))
def test_the_cover_proves_every_compatible_pair_exactly_once_in_groups_of_compatible_routes(
        graph: tuple[int, set[tuple[int, int]]], size: int) -> None:
    n, edges = graph
    groups = cover(n, sorted(edges), max_size=size)
    proved = [e for _, new in groups for e in new]
    assert sorted(proved) == sorted(edges)  # every edge, once
    for group, new in groups:
        assert len(group) <= size
        assert all(pair in edges for pair in combinations(sorted(group), 2))  # pairwise compatible
        assert all(a in group and b in group for a, b in new)
    assert cover(n, sorted(edges), max_size=size) == groups  # the same plan every time


Groups = list[tuple[list[int], list[tuple[int, int]]]]


def _cover_by_scanning(n: int, edges: list[tuple[int, int]], size: int) -> Groups:
    """The cover's rule, plainly: a group starts at the vertex with the most uncovered pairs (the lowest of those
    tied), found by looking at every vertex, and grows by a candidate covering the most new pairs with it, counted
    here candidate by candidate: of those tied, the first 32 are weighed by the pairs they keep within reach."""
    adj: list[set[int]] = [set() for _ in range(n)]
    for a, b in edges:
        adj[a].add(b)
        adj[b].add(a)
    left = [set(x) for x in adj]
    groups: Groups = []
    while any(left):
        seed = max(range(n), key=lambda v: (len(left[v]), -v))
        group, reach, useful = [seed], set(adj[seed]), set(left[seed])
        while len(group) < size and (pool := sorted(reach & useful)):
            gain = {v: len(left[v] & set(group)) for v in pool}
            most = max(gain.values())
            tied = [v for v in pool if gain[v] == most]
            best = max(tied[:32], key=lambda v: (len(left[v] & reach), -v))
            group.append(best)
            reach &= adj[best]
            useful |= left[best]
        proved: list[tuple[int, int]] = []
        for v in group:
            proved += [(v, w) for w in sorted(left[v] & set(group)) if v < w]
            left[v] -= set(group)
        groups.append((sorted(group), sorted(proved)))
    return groups


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 40).flatmap(lambda n: st.tuples(st.just(n), st.sets(
    st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda e: e[0] < e[1])))),
    st.integers(2, 8))
def test_the_cover_follows_its_rule(graph: tuple[int, set[tuple[int, int]]], size: int) -> None:
    n, edges = graph
    assert cover(n, sorted(edges), max_size=size) == _cover_by_scanning(n, sorted(edges), size)


@pytest.mark.parametrize("seed", range(6))
def test_the_cover_follows_its_rule_on_dense_graphs(seed: int) -> None:
    """Dense graphs, as a hub's compatibility graph is: groups grow large, so candidates differ in the new pairs they
    cover (counted in several bit planes) and more than 32 of them may tie."""
    rng = random.Random(seed)
    n = rng.randint(50, 90)
    density = rng.choice([0.6, 0.8, 0.9])
    edges = [(a, b) for a, b in combinations(range(n), 2) if rng.random() < density]
    groups = cover(n, edges, max_size=40)
    assert groups == _cover_by_scanning(n, edges, 40)
    assert max(len(g) for g, _ in groups) >= 8


def test_batches_are_ordered_to_move_the_fewest_turnouts_next() -> None:
    """Each next batch of a chain is the one of the following 32 that needs the fewest turnouts moved from where the
    chain's earlier batches left them (all normal at a chain's start), counted here name by name."""
    table = build_table(load("gaotie"))
    batches: list[Batch] = [b for u in plan(table, None, pairs=True).units if u.kind == "batches" for b in u.batches]
    _assert_ordered_by_moves(sorted(batches, key=lambda b: (len(b[0]), b[0])), table.routes)


def test_batches_whose_routes_need_a_turnout_both_ways_are_ordered_by_the_last_route_naming_it() -> None:
    """A table missing an enemy could put two routes needing one turnout both ways in a batch: the turnout then lies
    as the batch's last route needs it, as it would once the batch is set."""
    table = build_table(load("gaotie"))
    routes = list(table.routes.values())
    both_ways: list[Batch] = []
    for a, b in combinations(routes, 2):
        lie = {t.id: t.position for t in a.all_turnouts}
        if any(lie.get(t.id, t.position) != t.position for t in b.all_turnouts):
            both_ways += [((a.id, b.id), ()), ((b.id, a.id), ())]
    assert len(both_ways) > 32
    _assert_ordered_by_moves(both_ways, table.routes)


def _assert_ordered_by_moves(shuffled: list[Batch], routes: dict[str, Route]) -> None:
    def needs(b: Batch) -> dict[str, str]:
        return {t.id: t.position.value for r in b[0] for t in routes[r].all_turnouts}

    ordered = by_turnouts(shuffled, routes)
    assert sorted(ordered) == sorted(shuffled)
    left = sorted(shuffled, key=lambda b: (sorted(t for t, p in needs(b).items() if p == "reverse"),
                                           shuffled.index(b)))
    lie: dict[str, str] = {}
    for i, b in enumerate(ordered):
        if i % CHAIN == 0:
            lie = {}
        moves = [sum(lie.get(t, "normal") != p for t, p in needs(c).items()) for c in left[:32]]
        assert b == left[moves.index(min(moves))]
        left.remove(b)
        lie.update(needs(b))


def test_the_plan_covers_the_table_with_batches_and_counts_every_pair() -> None:
    table = build_table(load("jiaopei"))
    work = plan(table, None, pairs=True)
    routes = list(table.routes.values())
    assert work.pairs_tested == len(routes) * (len(routes) - 1) // 2
    batches = [b for u in work.units if u.kind == "batches" for b in u.batches]
    proved = sorted(tuple(sorted(p)) for _, pairs in batches for p in pairs)
    compatible = sorted(tuple(sorted((a.id, b.id))) for a, b in combinations(routes, 2)
                        if b.id not in a.conflicts and a.id not in b.conflicts and a.signal != b.signal
                        and b.id not in a.conditional and a.id not in b.conditional)
    assert proved == compatible
    assert len(batches) < len(compatible)  # batches prove several pairs at once
    assert [u.item for u in work.units if u.kind == "station"] == ["throats", "power-up", "red-lamp-transfer",
                                                                   "line-direction", "guide-area", "queued-move"]


def _pair_units_by_scanning(table: InterlockingTable, focus: set[str] | None) -> tuple[list[tuple[str, ...]], list[
        tuple[str, str]], list[tuple[str, str]], list[tuple[str, str]], tuple[int, int, int]]:
    """What the plan's pair units must be, a pair at a time: each route's enemies (listed on either route, or the
    same signal), the conditional pairs, the compatible pairs, the pairs listed on one route only, and the counts
    (tested, conflicting, compatible; a conditional pair counts as both)."""
    order = list(table.routes.values())
    rivals, conditional, compatible, lopsided = [], [], [], []
    tested = conflicting = fine = 0

    def relevant(a: Route, b: Route) -> bool:
        return not focus or a.id in focus or b.id in focus

    def enemies(a: Route, b: Route) -> bool:
        return b.id in a.conflicts or a.id in b.conflicts or a.signal == b.signal

    for i, a in enumerate(order):
        mine = [b.id for b in order if b is not a and enemies(a, b) and relevant(a, b)]
        if mine:
            rivals.append((a.id, *mine))
        for b in order[i + 1:]:
            if not relevant(a, b):
                continue
            tested += 1
            if enemies(a, b):
                conflicting += 1
            elif b.id in a.conditional or a.id in b.conditional:
                conflicting += 1
                fine += 1
                conditional.append((a.id, b.id))
            else:
                fine += 1
                compatible.append((a.id, b.id))
            if (b.id in a.conflicts) != (a.id in b.conflicts) or (b.id in a.conditional) != (a.id in b.conditional):
                lopsided.append((a.id, b.id))
    return rivals, conditional, compatible, lopsided, (tested, conflicting, fine)


def _lopsided(table: InterlockingTable) -> InterlockingTable:
    """``table`` with one conflict and one conditional conflict listed on one of their routes only."""
    table = copy.deepcopy(table)
    a = next(r for r in table.routes.values() if r.conflicts)
    del a.conflicts[next(iter(a.conflicts))]
    b = next((r for r in table.routes.values() if r.conditional), None)
    if b is not None:
        del b.conditional[next(iter(b.conditional))]
    return table


def test_the_plan_sorts_every_pair_as_a_test_a_pair_does() -> None:
    """The plan finds enemies, conditional and compatible pairs with bit sets; here they are found a pair at a time,
    on stations with conditional enemies (depot, doubleslip), with a focus, and on tables whose conflicts are listed
    on one route only."""
    for name in ("jiaopei", "depot", "gaotie", "src/liansuo/examples/stations/doubleslip.yaml"):
        built = build_table(load(name if "/" not in name else Path(__file__).parent.parent / name))
        for table in (built, _lopsided(built)):
            ids = list(table.routes)
            for focus in (None, {ids[0], ids[len(ids) // 2]}):
                work = plan(table, focus, pairs=True)
                rivals, conditional, compatible, lopsided, counts = _pair_units_by_scanning(table, focus)
                assert [u.routes for u in work.units if u.kind == "rivals"] == rivals
                assert [u.routes for u in work.units if u.kind == "conditional"] == conditional
                proved = [p for u in work.units if u.kind == "batches" for _, pairs in u.batches for p in pairs]
                assert sorted(proved) == sorted(compatible)
                assert work.asymmetric == lopsided
                assert (work.pairs_tested, work.pairs_conflicting, work.pairs_compatible) == counts
                assert [u.routes[0] for u in work.units if u.kind == "route"] == [
                    r for r in ids if not focus or r in focus]


def test_verify_on_two_dask_workers_reports_exactly_what_one_process_does() -> None:
    here = verify_station("gaotie").as_dict()
    spread = verify_station("gaotie", workers=2).as_dict()
    assert here.pop("elapsed_s") is not None and spread.pop("elapsed_s") is not None
    assert here["warnings"], "gaotie's dead-zone warnings should be in both reports"
    assert here == spread


def test_local_workers_run_without_the_statistical_profiler() -> None:
    """A Dask worker samples its task's stack every 10 ms for the dashboard; on verify's units that cost a quarter of
    the worker's time, so the local cluster's workers run without it (and a worker its nanny restarts, too)."""
    def profiling(dask_worker: Any) -> list[str]:
        return [name for name in ("profile", "profile-cycle") if name in dask_worker.periodic_callbacks]

    with client(2, None) as c:
        assert list(c.run(profiling).values()) == [[], []]
        c.restart()
        assert list(c.run(profiling).values()) == [[], []]


def test_soak_runs_on_workers_are_the_runs_made_here_in_seed_order() -> None:
    here = soak_runs("jiaopei", 150, [3, 4])
    spread = soak_runs("jiaopei", 150, [3, 4], workers=2)
    for r in (*here, *spread):
        r.pop("elapsed_s")
    assert [r["seed"] for r in spread] == [3, 4]
    assert here == spread


def test_generate_hub_writes_a_station_that_loads(tmp_path: Path) -> None:
    out = tmp_path / "hub.yaml"
    done = subprocess.run([*LIANSUO, "generate", "hub", "--turnouts", "30", "--tracks", "12", "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    station = load(str(out))
    assert len(station.turnouts) == 30 and "wrote" in done.stderr
    piped = subprocess.run([*LIANSUO, "generate", "hub", "--turnouts", "30", "--tracks", "12"], capture_output=True,
                           text=True, check=True).stdout
    assert piped == out.read_text(encoding="utf-8") and load_text(piped).id == station.id


def test_generate_hub_refuses_numbers_that_make_no_hub_and_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "hub.yaml"
    done = subprocess.run([*LIANSUO, "generate", "hub", "--turnouts", "10", "--tracks", "40", "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "40 tracks need at least 78 turnouts" in done.stderr
    assert not out.exists() and "Traceback" not in done.stderr


def test_the_table_is_the_same_on_every_run() -> None:
    """Conflict reasons used to depend on the order of a set of section names (Python's string hashing)."""
    outs = set()
    for seed in ("1", "2", "3"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        outs.add(subprocess.run([*LIANSUO, "table", "jiaopei", "--format", "json"], capture_output=True, text=True,
                                env=env, check=True).stdout)
    assert len(outs) == 1
    assert json.loads(outs.pop()) == json.loads(as_json(build_table(load("jiaopei"))))


def test_progress_is_silent_when_not_asked_for() -> None:
    with progress("work", 10, show=False) as advance:
        advance(10)
    done = subprocess.run([*LIANSUO, "verify", "jiaopei", "--route", "X-XI", "--no-pairs"], capture_output=True,
                          text=True)
    assert done.returncode == 0 and done.stderr == ""  # stderr is a pipe here: no bar


def test_routes_with_disjoint_footprints_are_never_kept_apart_by_the_oracle() -> None:
    """verify judges only pairs whose footprints meet; every other pair must be one the full judgement lets be open
    together (on the bundled stations, the examples and a generated hub)."""
    from liansuo.proving.oracle.pairs import PaperOracle
    from liansuo.proving.verify.against import spec
    from liansuo.rules import load_rules
    from liansuo.stations.hubgen import generate_hub

    rules = load_rules()
    stations = [load(name, rules=rules) for name in ("jiaopei", "gaotie", "depot")]
    examples = Path(__file__).resolve().parents[1] / "src" / "liansuo" / "examples" / "stations"
    stations += [load(str(p), rules=rules) for p in sorted(examples.glob("*.yaml"))]
    stations.append(load_text(generate_hub(20, 8), "<hub20>"))
    skipped = 0
    for station in stations:
        oracle = PaperOracle(station, rules)
        routes = list(build_table(station, rules).routes.values())
        prints = {r.id: oracle.footprint(spec(r)) for r in routes}
        for a, b in combinations(routes, 2):
            if a.signal != b.signal and not prints[a.id] & prints[b.id]:
                skipped += 1
                assert oracle.apart(spec(a), spec(b)) == "", (station.id, a.id, b.id)
    assert skipped > 1000  # the filter does skip work


def test_an_item_that_fails_on_the_shared_simulation_is_reported_with_its_own_script() -> None:
    """A route's section items run in turn on one simulation; a failing one is run again alone, so its script holds
    that one section only, as when every item had a fresh simulation."""
    from liansuo.proving.mutation.mutants import MUTANTS

    mutant = next(m for m in MUTANTS if m.name == "blind-to-occupancy")
    with mutant.applied():
        rep = verify_station("jiaopei", routes=["X-XI"], pairs=False)
    failed = [f for f in rep.failures if f.check == "section-occupied"]
    assert failed, [f.check for f in rep.failures]
    for f in failed:
        occupied = [s for s in f.steps if s.startswith("occupy ")]
        assert len(occupied) == 1 and occupied[0].split()[1] in f.detail, f.steps


def test_a_negative_number_of_workers_is_refused_with_a_reason() -> None:
    done = subprocess.run([*LIANSUO, "verify", "jiaopei", "--workers", "-1"], capture_output=True, text=True)
    assert done.returncode == 2 and "-1 is negative; give 0 (run here) or more" in done.stderr
    done = subprocess.run([*LIANSUO, "soak", "jiaopei", "--runs", "two"], capture_output=True, text=True)
    assert done.returncode == 2 and "'two' is not a whole number" in done.stderr
