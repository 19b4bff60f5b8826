"""The operator's commands on the station's equipment beyond routes (操作表示机): turnouts one by one (单操, 单锁,
单封), the power-up release, a line's direction (改方), the 64D block line, the axle counter reset and the platform
doors. Each returns a :class:`~.io.Result`; a refusal says why in a signaller's terms."""

from __future__ import annotations

from liansuo.interlocking.core import Core
from liansuo.interlocking.index import INTERLOCKED
from liansuo.interlocking.io import Result
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.locks import Hold


class EquipmentCommands:
    """The commands on the equipment, for the :class:`~.operations.Operator` that holds the ``core`` and the route
    ``lifecycle``."""

    core: Core
    lifecycle: RouteLifecycle

    # ---- turnouts ---------------------------------------------------------------------------------------------
    def _turnout_ids(self, name: str) -> list[str] | None:
        if name in self.core.station.turnouts:
            return self.core.pair_members(name)
        if name in self.core.station.pairs:
            return list(self.core.station.pairs[name])
        return None

    def throw(self, name: str, position: str) -> Result:
        """单操: individual operation of a turnout (a crossover pair moves together)."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.core.station.id}")
        if position not in ("normal", "reverse"):
            return Result.refuse(f"a turnout goes 'normal' or 'reverse', not '{position}'")
        if all(self.core.board.indication(t) == position for t in ids):
            return Result.accept(f"turnout {name} is already {position}")
        for t in ids:
            why = self.core.locks.why_turnout(t)
            if why:
                return Result.refuse(why)
            if not self.core.clear(self.core.turnouts[t].section):
                return Result.refuse(f"turnout {t} cannot move: section {self.core.turnouts[t].section} is occupied")
        self.core.request_move(ids[0], position)
        self.core.event("turnout", f"turnout {name} to {position} (individual operation)")
        return Result.accept(f"turnout {name} moving to {position}")

    def single_lock(self, name: str, on: bool) -> Result:
        """单锁 / 单解: the turnout (and its crossover partner) may not be moved."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.core.station.id}")
        for t in ids:
            if on:
                self.core.locks.lock_turnout(t, Hold.single)
            else:
                self.core.locks.unlock_turnout(t, Hold.single)
        word = "single-locked (单锁)" if on else "unlocked (单解)"
        self.core.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    def single_block(self, name: str, on: bool) -> Result:
        """单封 / 解封: no route through the turnout; individual operation stays allowed."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.core.station.id}")
        for t in ids:
            if on:
                self.core.locks.blocked.add(t)
            else:
                self.core.locks.blocked.discard(t)
        word = "single-blocked (单封)" if on else "unblocked (解封)"
        self.core.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    # ---- power-up, line direction ----------------------------------------------------------------------------
    def power_up_release(self) -> Result:
        """上电解锁 (a sealed button): give back the sections locked since the interlocking started; refused while a
        section of the station shows occupied."""
        if not self.core.power_up_locked:
            return Result.refuse("there is no power-up lock to release: the interlocking is in service")
        core = self.core
        occupied = [s for s, sec in core.station.sections.items() if sec.role in INTERLOCKED and not core.clear(s)]
        if occupied:
            return Result.refuse(f"power-up release refused: section {', '.join(occupied[:6])}"
                                 f"{' ...' if len(occupied) > 6 else ''} shows occupied; every section of the station "
                                 "must show clear first (clear it, or have the track circuit repaired)")
        self.core.locks.release_all(Hold.power_up)
        self.core.power_up_locked = False
        self.core.event("power", "power-up release (上电解锁): every section released")
        return Result.accept("power-up release: the station is in service")

    def line_direction(self, link: str, direction: str) -> Result:
        """改方: set an automatic line for departures from this station ('out') or back to its running direction
        ('in'). Only a bidirectional line, clear, with no route into or out of it."""
        lk = next((x for x in self.core.station.model.links if x.id == link), None)
        if lk is None or lk.kind.value != "automatic":
            names = ", ".join(x.id for x in self.core.station.model.links if x.kind.value == "automatic") or "none"
            return Result.refuse(f"there is no automatic block line '{link}' (automatic lines: {names})")
        if direction not in ("out", "in"):
            return Result.refuse("line-direction LINE out|in")
        if self.core.station.link_running(link) != "inbound":
            return Result.refuse(f"line {link} already runs away from this station: its direction needs no change")
        if not lk.bidirectional:
            return Result.refuse(f"line {link} is not bidirectional (双向): its direction cannot be changed")
        want_out = direction == "out"
        if (link in self.core.line_out) == want_out:
            return Result.accept(f"line {link} is already set {'for departures' if want_out else 'towards us'}")
        occupied = [s for s in lk.sections if not self.core.clear(s)]
        if occupied:
            return Result.refuse(f"line {link} is not clear ({', '.join(occupied)} occupied): the direction changes "
                                 "only with the whole line clear")
        receiving = [sig for sig, line in self.core.index.receives_from.items() if line == link]
        for rs in self.core.routes.values():
            r = rs.route
            if r.exit_link == link or set(r.approach) & set(lk.sections) or r.signal in receiving:
                return Result.refuse(f"route {r.id} uses line {link}: the direction changes only with no route "
                                     "into or out of it")
        guided = [sig for sig in receiving if sig in self.core.guide_only]
        if guided:
            return Result.refuse(f"signal {guided[0]} shows the guide aspect for a train from line {link}: the "
                                 "direction changes only with no signal given for a movement on the line")
        if want_out:
            self.core.line_out.add(link)
            self.core.out.line_direction[link] = "outbound"
        else:
            self.core.line_out.discard(link)
            self.core.out.line_direction.pop(link, None)
        self.core.line_direction_changed()
        word = "set for departures from this station" if want_out else "back to its running direction"
        self.core.event("block", f"line {link} {word} (改方)")
        return Result.accept(f"line {link} {word}")

    # ---- 64D block and platform doors ------------------------------------------------------------------------
    def block_line(self, link: str, action: str) -> Result:
        bl = self.core.links.get(link)
        if bl is None:
            names = ", ".join(sorted(self.core.links)) or "none"
            return Result.refuse(f"there is no 64D block line '{link}' (64D lines: {names})")
        before = bl.state
        why, pulse = bl.operate(action, self.core.clear(bl.departure_section))
        if why:
            return Result.refuse(why)
        if pulse:
            self.core.send(link, pulse)
        self.core.event("block", f"block line {link}: {action}, {before.value} -> {bl.state.value}")
        return Result.accept(f"block line {link}: {bl.state.value}")

    def axle_reset(self, section: str) -> Result:
        """计轴复零 (a sealed button, counted): set an axle-counter section's count to zero after its disturbance.
        Refused on a track circuit, on a section that shows clear, and on one a route holds: the operator resets only
        a line confirmed clear on site, never under a movement the interlocking has authorised."""
        core = self.core
        sec = core.station.sections.get(section)
        if sec is None:
            return Result.refuse(f"there is no section '{section}' at {core.station.id}")
        if sec.type.value != "axle_counter":
            return Result.refuse(f"section {section} is a track circuit, not counted by axle counters: nothing to "
                                 "reset")
        if core.clear(section):
            return Result.refuse(f"the axle counter of {section} shows clear: nothing to reset")
        holders = core.locks.section_holders(section)
        if holders:
            return Result.refuse(f"section {section} is locked in route {holders[0]}: a counter under a route is "
                                 "never reset")
        core.out.axle_resets.add(section)
        core.axle_resets_used += 1
        core.event("block", f"axle counter {section} reset (计轴复零, sealed button, counter {core.axle_resets_used})")
        return Result.accept(f"axle counter {section} reset (sealed button 铅封, counter {core.axle_resets_used}); "
                             "confirm the line clear on site before the next train")

    def doors(self, platform: str, action: str) -> Result:
        p = next((p for p in self.core.station.model.platforms if p.id == platform), None)
        if p is None or not p.screen_doors:
            return Result.refuse(f"there is no platform with screen doors '{platform}'")
        if action not in ("open", "close"):
            return Result.refuse("doors open|close")
        if action == "open" and self.core.clear(p.section):
            return Result.refuse(f"no train at platform {platform}: section {p.section} is clear")
        for d in p.screen_doors:
            cmd = self.core.out.doors[f"{p.id}:{d.side.value}"]
            cmd.zckj = not self.core.clear(p.section)
            cmd.kmj = action == "open"
            cmd.gmj = action == "close"
        self.core.event("doors", f"platform {platform}: {action} command")
        return Result.accept(f"platform {platform} doors: {action}")
