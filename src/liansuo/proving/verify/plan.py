"""The interlocking test cut into units of work that run on their own simulations, in any order, on any worker.

A :class:`Unit` is one route's items, one route's enemies (its rivals refused with it setting and open), a chain of
batches of mutually compatible routes, each set and open together, one conditionally conflicting pair, or one
station-wide item.
:func:`plan` lists them in a fixed order for a station and a focus; the report is put together in that order,
whatever ran where (:mod:`.spread`).

Compatible pairs are proven in batches, not one at a time: :func:`cover` finds groups of routes that are pairwise
compatible (cliques of the compatibility graph) until every compatible pair lies in one group. Setting a group's
routes together and seeing every signal open proves each of its pairs; a group that does not open is tried again
pair by pair, so a failure still comes with the script of just its two routes. Batches run in chains on one
simulation, each cancelled before the next is set: the turnouts the next needs often lie right already.

Given which routes are near one another (:mod:`.apart`), only the compatible pairs of near routes must lie in a
group; the groups are still cliques of the whole compatibility graph, so a group may hold routes far apart too. The
pairs of routes apart are counted, and simulated only for a route that failed on its own (:func:`again`).
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

from liansuo.interlocking.table.build import InterlockingTable, Route
from liansuo.proving.verify.probe import Failure

MAX_BATCH = 40  # routes set together at most: their turnout moves queue (a few at a time), so time grows with it
CHAIN = 32  # batches one after the other on one simulation (each cancelled before the next is set)
_LOOK = 32  # of the candidates tied on new pairs, those weighed by what they keep within reach


Batch = tuple[tuple[str, ...], tuple[tuple[str, str], ...]]  # (routes set together, the pairs they prove)


@dataclass(frozen=True)
class Unit:
    """One independent piece of the test. ``kind``: route, rivals, batches, conditional or station; ``routes``: the
    routes it is about; ``batches``: a chain of batches, each its routes and the compatible pairs it proves (each
    pair is proved by exactly one batch); ``item``: which station-wide item."""

    kind: str
    routes: tuple[str, ...] = ()
    batches: tuple[Batch, ...] = ()
    item: str = ""



@dataclass
class Plan:
    units: list[Unit]
    pairs_tested: int = 0
    pairs_conflicting: int = 0
    pairs_compatible: int = 0
    pairs_apart: int = 0  # compatible pairs proven apart (.apart), not simulated
    asymmetric: list[tuple[str, str]] = field(default_factory=list)  # conflicts listed on one route only
    ids: list[str] = field(default_factory=list)  # the routes in table order: bit j of the sets below is ids[j]
    compatible: list[int] = field(default_factory=list)  # each route's compatible partners (of the focus)
    apart: list[int] = field(default_factory=list)  # of those, the partners it is apart from


STATION_ITEMS = ("throats", "power-up", "red-lamp-transfer", "line-direction", "guide-area", "queued-move")


def plan(table: InterlockingTable, focus: set[str] | None, *, pairs: bool, near: list[int] | None = None) -> Plan:
    """Every unit of the test of ``table``, in report order (see the module docstring). ``near``: for each route of
    the table, in its order, the routes near it as a bit set (:func:`.apart.near_masks`); None: every compatible pair
    is simulated."""
    order = list(table.routes.values())
    units = [Unit("route", (r.id,)) for r in order if not focus or r.id in focus]
    out = Plan([])
    if pairs:
        out = _pairs(order, focus, near)
    out.units[:0] = units
    if not focus:
        out.units += [Unit("station", item=item) for item in STATION_ITEMS]
    return out


def _pairs(order: list[Route], focus: set[str] | None, near: list[int] | None) -> Plan:
    """The pair units of ``order``: each route's enemies, the chains of batches of compatible routes near each other
    (all of them when ``near`` is None), each conditional pair. Who conflicts with whom is kept as bit sets (Python
    integers, bit ``j`` for ``order[j]``), so a hub's millions of pairs are sorted in a few operations a route instead
    of a test a pair; the units and counts are those of a test a pair (tests/test_scale.py holds them to it)."""
    n = len(order)
    index = {r.id: k for k, r in enumerate(order)}
    listed = _masks(order, index, lambda r: r.conflicts)  # b in a.conflicts
    listed_by = _transpose(listed, n)  # a in b.conflicts
    cond = _masks(order, index, lambda r: r.conditional)
    cond_by = _transpose(cond, n)
    same_signal: dict[str, int] = {}
    for k, r in enumerate(order):
        same_signal[r.signal] = same_signal.get(r.signal, 0) | 1 << k
    everyone = (1 << n) - 1
    in_focus = sum(1 << k for k, r in enumerate(order) if r.id in focus) if focus else everyone

    out = Plan([])
    rivals: list[Unit] = []
    conditionals: list[Unit] = []
    adj = [0] * n  # each route's compatible partners (the relation is symmetric: so is every part of it)
    for i, a in enumerate(order):
        me = 1 << i
        relevant = everyone if in_focus & me else in_focus
        enemies = (listed[i] | listed_by[i] | same_signal[a.signal]) & ~me
        mine = enemies & relevant
        if mine:
            rivals.append(Unit("rivals", (a.id, *(order[j].id for j in _bits(mine)))))
        later = relevant & ~((me << 1) - 1)  # j > i
        out.pairs_tested += later.bit_count()
        out.pairs_conflicting += (later & enemies).bit_count()
        conditional = cond[i] | cond_by[i]
        conditional_later = later & ~enemies & conditional
        out.pairs_conflicting += conditional_later.bit_count()
        out.pairs_compatible += conditional_later.bit_count()
        conditionals += [Unit("conditional", (a.id, order[j].id)) for j in _bits(conditional_later)]
        adj[i] = relevant & ~enemies & ~conditional & ~me
        out.pairs_compatible += (adj[i] & later).bit_count()
        lopsided = later & ((listed[i] ^ listed_by[i]) | (cond[i] ^ cond_by[i]))
        out.asymmetric += [(a.id, order[j].id) for j in _bits(lopsided)]
    apart = [0] * n if near is None else [x & ~near[i] for i, x in enumerate(adj)]
    out.pairs_apart = sum(x.bit_count() for x in apart) // 2
    out.ids, out.compatible, out.apart = [r.id for r in order], adj, apart
    need = adj if near is None else [x & near[i] for i, x in enumerate(adj)]
    out.units = rivals + _chains(order, adj, need) + conditionals
    return out


def again(p: Plan, order: list[Route], failed: set[str]) -> tuple[list[Unit], int]:
    """The chains of batches that simulate every pair apart with a route in ``failed`` (a route that failed on its
    own: the argument for its pairs apart does not hold), and how many pairs they are."""
    bad = sum(1 << k for k, r in enumerate(p.ids) if r in failed)
    need = [x if bad >> i & 1 else x & bad for i, x in enumerate(p.apart)]
    return _chains(order, p.compatible, need), sum(x.bit_count() for x in need) // 2


def _chains(order: list[Route], adj: list[int], need: list[int]) -> list[Unit]:
    """Chains of batches: cliques of ``adj`` covering every edge of ``need``, in an order that moves few turnouts."""
    ids = [r.id for r in order]
    batches: list[Batch] = [(tuple(ids[k] for k in group), tuple((ids[x], ids[y]) for x, y in proved))
                            for group, proved in cover_adjacent(adj, need=need)]
    batches = by_turnouts(batches, {r.id: r for r in order})
    return [Unit("batches", batches=tuple(batches[i:i + CHAIN])) for i in range(0, len(batches), CHAIN)]


def _masks(order: list[Route], index: dict[str, int], named: Callable[[Route], Iterable[str]]) -> list[int]:
    """For each route, the bit set of the routes it names (its conflicts, its conditional enemies)."""
    return [sum(1 << j for j in {index[x] for x in named(r) if x in index}) for r in order]


def _transpose(masks: list[int], n: int) -> list[int]:
    """Bit ``i`` of ``out[j]`` is bit ``j`` of ``masks[i]``: who names each route."""
    named_by: list[list[int]] = [[] for _ in range(n)]
    for i, m in enumerate(masks):
        for j in _bits(m):
            named_by[j].append(i)
    return [sum(1 << i for i in who) for who in named_by]


def by_turnouts(batches: list[Batch], routes: dict[str, Route], window: int = 32) -> list[Batch]:
    """The batches in an order that moves few turnouts from one to the next of a chain (each chain starts with every
    turnout normal): sorted by the turnouts they need reversed, then each next one the cheapest of the following
    ``window``. Waiting for turnouts is most of a batch's time. The turnouts a batch needs, and those it needs
    reversed, are bit sets (Python integers), so a move is counted with a few integer operations."""
    bit: dict[str, int] = {}
    needs: list[tuple[int, int]] = []  # (every turnout the batch needs, those of them reversed)
    rev_names: list[list[str]] = []
    lies: dict[str, tuple[int, int, frozenset[str]]] = {}  # each route's (turnouts, reversed ones, their names)
    for b in batches:
        every = rev = normal = 0
        names: set[str] = set()
        for r in b[0]:
            if r not in lies:
                lies[r] = _lie(routes[r], bit)
            e, v, ns = lies[r]
            every |= e
            rev |= v
            normal |= e & ~v
            names |= ns
        if rev & normal:  # a turnout two routes need lying both ways (an enemy the table missed): the last one wins
            lie = {t.id: t.position.value for r in b[0] for t in routes[r].all_turnouts}
            rev = sum(bit[t] for t, p in lie.items() if p == "reverse")
            names = {t for t, p in lie.items() if p == "reverse"}
        needs.append((every, rev))
        rev_names.append(sorted(names))
    left = sorted(range(len(batches)), key=lambda i: (rev_names[i], i))
    out: list[int] = []
    lying = 0  # the turnouts lying reverse now
    while left:
        if len(out) % CHAIN == 0:
            lying = 0
        k = min(range(min(window, len(left))),
                key=lambda j: (((lying ^ needs[left[j]][1]) & needs[left[j]][0]).bit_count(), j))
        i = left.pop(k)
        out.append(i)
        every, rev = needs[i]
        lying = (lying & ~every) | rev
    return [batches[i] for i in out]


def _lie(route: Route, bit: dict[str, int]) -> tuple[int, int, frozenset[str]]:
    """The turnouts ``route`` needs and those it needs reversed, as bit sets (each turnout's bit given at its first
    sight), and the names of the reversed ones; a turnout named twice lies as it is named last."""
    lie = {t.id: t.position.value for t in route.all_turnouts}
    every = rev = 0
    for t, p in lie.items():
        k = bit.setdefault(t, 1 << len(bit))
        every |= k
        if p == "reverse":
            rev |= k
    return every, rev, frozenset(t for t, p in lie.items() if p == "reverse")


def cover(n: int, edges: Iterable[tuple[int, int]], max_size: int = MAX_BATCH
          ) -> list[tuple[list[int], list[tuple[int, int]]]]:
    """Groups of pairwise-adjacent vertices (cliques) of the graph on ``range(n)`` with ``edges`` until every edge
    lies in a group; each group comes with the edges it is the first to cover. Greedy and deterministic: a group
    starts at the vertex with the most uncovered edges and grows by the candidate that covers the most new edges with
    it; of the candidates tied on that, the first few are weighed by the uncovered edges they keep within reach.
    Adjacency is kept as Python integers used as bit sets."""
    adj = [0] * n
    for a, b in edges:
        adj[a] |= 1 << b
        adj[b] |= 1 << a
    return cover_adjacent(adj, max_size)


def cover_adjacent(adj: list[int], max_size: int = MAX_BATCH, need: list[int] | None = None
                   ) -> list[tuple[list[int], list[tuple[int, int]]]]:
    """:func:`cover` of the graph whose vertex ``v`` is adjacent to the bits of ``adj[v]``; with ``need`` (a part of
    ``adj``, symmetric as it is), groups are still cliques of ``adj`` but only the edges of ``need`` must be covered."""
    left = list(adj if need is None else need)  # uncovered edges at each vertex
    remaining = sum(x.bit_count() for x in left) // 2
    heap = [(-x.bit_count(), v) for v, x in enumerate(left)]  # counts only fall: stale entries are pushed again
    heapq.heapify(heap)
    groups: list[tuple[list[int], list[tuple[int, int]]]] = []
    while remaining:
        seed = _most_left(heap, left)
        group, members = [seed], 1 << seed
        reach = adj[seed]  # vertices adjacent to every member
        useful = left[seed]  # vertices with an uncovered edge to some member
        counts = [left[seed]]  # each vertex's uncovered edges to the members (kept within reach), in bit planes
        while len(group) < max_size:
            pool = reach & useful
            if not pool:
                break
            # of the candidates covering the most new pairs with the group, the one keeping the most within reach
            best = max(_first_bits(_most_counted(counts, pool), _LOOK),
                       key=lambda v: ((left[v] & reach).bit_count(), -v))
            group.append(best)
            members |= 1 << best
            reach &= adj[best]
            useful |= left[best]
            _count_in(counts, left[best] & reach)
        proved: list[tuple[int, int]] = []
        for v in group:
            new = left[v] & members
            proved += [(v, w) for w in _bits(new) if v < w]
            left[v] &= ~members
        remaining -= len(proved)
        groups.append((sorted(group), sorted(proved)))
    return groups


def _count_in(planes: list[int], s: int) -> None:
    """Add one to the count of every vertex in the bit set ``s``. The counts are kept in bit planes (``planes[j]`` holds
    bit ``j`` of every vertex's count), so adding a set is a binary addition done on all vertices at once: a few
    integer operations instead of one a vertex."""
    carry = s
    for j, plane in enumerate(planes):
        planes[j] = plane ^ carry
        carry &= plane
        if not carry:
            return
    planes.append(carry)


def _most_counted(planes: list[int], pool: int) -> int:
    """The vertices of ``pool`` with the highest count in ``planes``: from the highest bit down, those that have it
    whenever some do."""
    best = pool
    for plane in reversed(planes):
        have = best & plane
        if have:
            best = have
    return best


def _most_left(heap: list[tuple[int, int]], left: list[int]) -> int:
    """The vertex with the most uncovered edges, the lowest of those tied (what ``max`` over every vertex by
    ``(count, -vertex)`` gives), from a heap whose entries may count more than is left."""
    while True:
        count, v = heap[0]
        now = left[v].bit_count()
        if -count == now:
            return v
        heapq.heapreplace(heap, (-now, v))


def _first_bits(x: int, k: int) -> list[int]:
    """The ``k`` lowest set bits of ``x``, lowest first: found in its binary digits (one C-level search a bit), not
    by peeling bits off a large integer one at a time."""
    digits = bin(x)
    last = len(digits) - 1
    out: list[int] = []
    end = len(digits)
    while len(out) < k:
        end = digits.rfind("1", 2, end)
        if end < 0:
            break
        out.append(last - end)
    return out


def _bits(x: int) -> list[int]:
    return _first_bits(x, x.bit_count())


@dataclass
class UnitResult:
    """What one unit found: its checks, failures and warnings in the order made, and a route unit's tally."""

    checks: int = 0
    failures: list[Failure] = field(default_factory=list)
    warnings: list[Failure] = field(default_factory=list)
    route: object = None  # a RouteResult for a route unit


def merge(results: Sequence[UnitResult]) -> tuple[int, list[Failure], list[Failure]]:
    """Checks, failures and warnings of units taken in plan order; what the oracle found is reported once, at the
    first unit that met it (as one run in order would), so the report is the same however the units ran."""
    checks, failures, warnings = 0, [], []
    seen: set[str] = set()
    for res in results:
        checks += res.checks
        for f in res.failures:
            if f.key:
                if f.key in seen:
                    continue
                seen.add(f.key)
            failures.append(f)
        warnings += res.warnings
    return checks, failures, warnings
