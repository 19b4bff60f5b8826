"""The interlocking table as engineers sign it (联锁表): the routes grouped by direction and throat (下行接车, 下行发车,
上行接车, 上行发车, ... 调车), each row a list of cells in the Chinese conventions.

Text, CSV and xlsx all print these cells, so the three agree; docs/interlocking-table.md describes the conventions:

- 按下按钮: ``XLA`` is the train button (列车按钮) of signal X, ``XIDA`` the shunting button (调车按钮) of XI, ``D1A``
  the one button of a shunting signal; standalone buttons (exit, variant, end) keep their own names.
- 道岔: ``1`` normal, ``(1)`` reverse, ``[1]`` flank protection, ``{1}`` driven; a crossover pair ``1/3`` or ``(1/3)``
  once, with the strongest role of its two halves.
- 轨道区段: the route's sections, then ``<5DG>`` for a section inside a turnout's fouling point (侵限).
- 敌对信号: by signal, never the route's own; ``XI(列)`` / ``XI(调)`` where only the train or only the shunting routes
  of XI are enemies; ``<1>D1`` / ``<(1)>D1`` where D1 is an enemy only with turnout 1 normal / reverse.
- 迎面进路: the enemies of the other direction onto the same station track, ``S(列)`` / ``D2(调)``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from liansuo.interlocking.table.route import Condition, InterlockingTable, Route, RouteTurnout
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station


@dataclass(frozen=True)
class Column:
    key: str  # the CSV header and JSON key
    heading: str  # the heading on the printed table
    width: int  # display columns in the text form


COLUMNS: tuple[Column, ...] = (
    Column("no", "序号", 4),
    Column("route", "进路", 14),
    Column("mode", "方式", 4),
    Column("buttons", "按下按钮", 11),
    Column("signal", "信号机", 6),
    Column("aspects", "显示", 8),
    Column("turnouts", "道岔", 15),
    Column("sections", "轨道区段", 13),
    Column("enemies", "敌对信号", 13),
    Column("opposing", "迎面进路", 8),
    Column("other", "其他联锁", 14),
)
DIRECTION_ZH = {Direction.down: "下行", Direction.up: "上行"}
CATEGORY_ZH = {"receiving": "接车", "departure": "发车", "transfer": "转线", "shunting": "调车"}
CATEGORY_ORDER = ("receiving", "departure", "transfer")
ROLE_RANK = {"route": 0, "protection": 1, "driven": 2}


@dataclass(frozen=True)
class SignedRow:
    route: str  # the route id
    cells: dict[str, str]  # column key -> cell


@dataclass(frozen=True)
class Group:
    name: str  # e.g. 下行接车 X咽喉
    direction: str | None  # down, up; None for the shunting groups
    category: str
    throat: str | None
    rows: tuple[SignedRow, ...]


@dataclass(frozen=True)
class SignedTable:
    station: str
    title: str  # the station's name
    file: str  # the station file's name
    sha256: str  # of the station file
    groups: tuple[Group, ...]

    def as_dict(self) -> list[dict[str, object]]:
        return [{"name": g.name, "direction": g.direction, "category": g.category, "throat": g.throat,
                 "rows": [{"id": r.route, **r.cells} for r in g.rows]} for g in self.groups]


def station_identity(station: Station) -> tuple[str, str]:
    """The station file's name and the SHA-256 of its bytes (of its parsed model where there is no file)."""
    src = station.source.file if station.source else ""
    path = Path(src) if src else None
    if path is not None and path.is_file():
        return path.name, hashlib.sha256(path.read_bytes()).hexdigest()
    data = json.dumps(station.model.model_dump(mode="json"), sort_keys=True, ensure_ascii=False)
    return (path.name if path else f"{station.id}.yaml"), hashlib.sha256(data.encode()).hexdigest()


def _position(t: str, reverse: bool) -> str:
    return f"({t})" if reverse else t


def _condition(cond: Condition) -> str:
    return "<" + ",".join(_position(t, p.value == "reverse") for t, p in cond) + ">"


class _Builder:
    def __init__(self, table: InterlockingTable, rules: RuleSet) -> None:
        self.table, self.st, self.rules = table, table.station, rules
        self.pair_of = {t: name for name, ts in self.st.pairs.items() for t in ts}
        self.signal_order = {s.id: i for i, s in enumerate(self.st.model.signals)}
        self.kinds: dict[str, set[str]] = {}  # signal -> kinds of route it starts
        for r in table.routes.values():
            self.kinds.setdefault(r.signal, set()).add(r.kind)
        self.centres = {name: sum(self.st.node_at(t) for t in ts) / len(ts)
                        for name, ts in table.throats.items() if ts}

    # ---- the cells -------------------------------------------------------------------------------------------
    def button(self, b: str, kind: str) -> str:
        sig = self.st.signals.get(b)
        if sig is None:
            return b  # a standalone button: exit, variant or end
        has = {x.value for x in sig.buttons}
        if has == {"shunt"}:
            return f"{b}A"
        if has == {"train"}:
            return f"{b}LA"
        return f"{b}{'LA' if kind == 'train' else 'DA'}"

    def track(self, sections: tuple[str, ...]) -> str | None:
        return next((s for s in reversed(sections) if s in self.st.sections and self.st.is_station_track(s)), None)

    def route_name(self, r: Route) -> str:
        start_track = self.track(r.approach) or r.signal
        if r.category == "receiving":
            return f"至 {self.track(r.sections) or r.leads_into or r.end}"
        if r.category == "departure":
            link = next((lk for lk in self.st.model.links if lk.id == r.exit_link), None)
            return f"由 {start_track} 至 {link.neighbour.zh.replace(' ', '') if link else '区间'}"
        if r.category == "transfer":
            return f"由 {start_track} 至 {self.track(r.sections) or r.end}"
        end = r.end if r.end in self.st.signals else (r.sections[-1] if r.sections else r.end)
        return f"由 {r.signal} 至 {end}"

    def turnouts(self, turnouts: tuple[RouteTurnout, ...]) -> str:
        by_id = {t.id: t for t in turnouts}
        done: set[str] = set()
        out = []
        for t in turnouts:
            if t.id in done:
                continue
            label, role = t.id, t.role
            pair = self.pair_of.get(t.id)
            partners = [by_id[p] for p in self.st.pairs.get(pair, []) if p != t.id and p in by_id] if pair else []
            if pair and partners and all(p.position == t.position for p in partners):
                label = pair
                role = min([t.role, *(p.role for p in partners)], key=ROLE_RANK.__getitem__)
                done.update(p.id for p in partners)
            text = _position(label, t.position.value == "reverse")
            out.append({"route": text, "protection": f"[{text}]", "driven": f"{{{text}}}"}[role])
        return " ".join(out)

    def sections(self, r: Route) -> str:
        return " ".join([*r.sections, *(f"<{f.section}>" for f in r.fouling)])

    def enemies(self, r: Route) -> str:
        always: dict[str, set[str]] = {}  # signal -> kinds of its routes that are enemies
        for rid in r.conflicts:
            o = self.table.routes.get(rid)
            if o is not None and o.signal != r.signal:
                always.setdefault(o.signal, set()).add(o.kind)
        only: dict[tuple[str, str], list[Condition]] = {}  # (signal, kind) -> the conditions
        for rid, alts in r.conditional.items():
            o = self.table.routes.get(rid)
            if o is None or o.signal == r.signal or o.kind in always.get(o.signal, set()):
                continue
            for cond, _why in alts:
                if cond not in only.setdefault((o.signal, o.kind), []):
                    only[(o.signal, o.kind)].append(cond)

        def name(sig: str, kinds: set[str]) -> str:
            if kinds >= self.kinds.get(sig, set()):
                return sig
            return f"{sig}({'列' if 'train' in kinds else '调'})"

        items = [(self.signal_order.get(s, 0), "", name(s, k)) for s, k in always.items()]
        items += [(self.signal_order.get(s, 0), _condition(c), _condition(c) + name(s, {k}))
                  for (s, k), conds in only.items() for c in conds]
        return " ".join(text for _o, _c, text in sorted(items))

    def opposing(self, r: Route) -> str:
        """迎面进路: the routes of the other direction onto the same station track, by signal and kind (列 train,
        调 shunting)."""
        seen: dict[str, set[str]] = {}
        for rid in r.opposing:
            o = self.table.routes.get(rid)
            if o is not None:
                seen.setdefault(o.signal, set()).add(o.kind)
        items = sorted(seen.items(), key=lambda kv: self.signal_order.get(kv[0], 0))
        return " ".join(f"{sig}({'列' if kind == 'train' else '调'})" for sig, kinds in items
                        for kind in sorted(kinds, key=("train", "shunt").index))

    def other(self, r: Route) -> str:
        items = []
        link = next((lk for lk in self.st.model.links if lk.id == r.exit_link), None)
        if link is not None:
            if link.kind.value == "64d":
                items.append("64D半自动闭塞")
            elif link.kind.value == "station":
                items.append("自动站间闭塞 " + " ".join(link.sections) + " 计轴空闲")
            else:
                items.append("自动闭塞" + (f" {link.sections[0]}空闲" if link.sections else ""))
        if r.line_sections:
            items.append(f"区间 {' '.join(r.line_sections)} 空闲")
        if r.kind == "train":
            on = set(r.sections) | set(r.approach)
            items += [f"{p.section}站台门关闭" for p in self.st.model.platforms if p.screen_doors and p.section in on]
        if r.diamonds:
            items.append("菱形交叉 " + " ".join(r.diamonds))
        if r.safety_line:
            items.append(f"安全线 {r.safety_line}")
        if r.overlap_sections:
            to = f"至 {r.overlap_end} " if r.overlap_end else ""
            items.append(f"延续进路 {to}" + " ".join([*r.overlap_sections, self.turnouts(r.overlap_turnouts)]).strip()
                         + f" {r.overlap_release_s:g}s解锁")
        sig = self.st.signals.get(r.signal)
        release = sig.release_s if sig and sig.release_s is not None else self.rules.release_s[r.kind]
        if r.approach:
            items.append(f"接近锁闭 {' '.join(r.approach)} {release:g}s")
        return "; ".join(items)

    def row(self, n: int, r: Route) -> SignedRow:
        cells = {
            "no": str(n), "route": self.route_name(r),
            "mode": "变更延续" if r.overlap_alternative else "变通" if r.via else "基本",
            "buttons": " ".join(self.button(b, r.kind) for b in r.buttons),
            "signal": r.signal, "aspects": "/".join(r.aspects), "turnouts": self.turnouts(r.turnouts),
            "sections": self.sections(r), "enemies": self.enemies(r), "opposing": self.opposing(r),
            "other": self.other(r),
        }
        return SignedRow(r.id, cells)

    # ---- the groups ------------------------------------------------------------------------------------------
    def throat(self, r: Route) -> str | None:
        if not self.centres:
            return None
        ts = [t.id for t in r.turnouts if t.role == "route"]
        sig = self.st.signals.get(r.signal)
        at = (sum(self.st.node_at(t) for t in ts) / len(ts) if ts
              else self.st.node_at(sig.at) if sig and (sig.at in self.st.joints or sig.at in self.st.ends) else 0.0)
        return min(self.centres, key=lambda name: abs(self.centres[name] - at))

    def groups(self) -> tuple[Group, ...]:
        keys: dict[tuple[int, int, str], tuple[str | None, str, str | None]] = {}
        members: dict[tuple[int, int, str], list[Route]] = {}
        throats = list(self.table.throats)
        for r in self.table.routes.values():
            throat = self.throat(r)
            t_rank = throats.index(throat) if throat in throats else 0
            if r.kind == "train" and r.category in CATEGORY_ORDER:
                d = 0 if r.direction is Direction.down else 1
                key = (d, CATEGORY_ORDER.index(r.category), f"{t_rank:03}")
                keys[key] = (r.direction.value, r.category, throat)
            else:
                key = (2, 0, f"{t_rank:03}")
                keys[key] = (None, "shunting", throat)
            members.setdefault(key, []).append(r)
        out, n = [], 0
        for key in sorted(members):
            direction, category, throat = keys[key]
            name = (DIRECTION_ZH[Direction(direction)] if direction else "") + CATEGORY_ZH[category]
            if throat is not None:
                name += f" {throat}咽喉"
            rows = []
            for r in members[key]:
                n += 1
                rows.append(self.row(n, r))
            out.append(Group(name, direction, category, throat, tuple(rows)))
        return tuple(out)


def signed_table(table: InterlockingTable, rules: RuleSet | None = None) -> SignedTable:
    """The table as engineers sign it: groups of rows of cells (see the module's docstring)."""
    b = _Builder(table, rules or load_rules())
    file, sha = station_identity(table.station)
    return SignedTable(table.station.id, table.station.display_name(), file, sha, b.groups())
