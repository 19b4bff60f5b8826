"""Seeded defects (mutants) of the interlocking, to show that ``liansuo verify`` and the safety oracle catch them.

Each mutant changes the interlocking's code for as long as it is applied (a context manager patching one method or
function), the way a plausible programming or design mistake would: a conflict class dropped from the table, a
protection turnout forgotten, a lock not asked, a release without its three-point check. None touches the oracle,
verify or the station data. ``liansuo mutate`` runs each against verify (and, if verify misses it, a short random
run under the oracle) and reports the score (docs/safety.md).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass

from liansuo.kit.native import native_modules
from liansuo.proving.mutation import cbidefects as cbi
from liansuo.proving.mutation import tabledefects as table

Apply = Callable[[ExitStack], None]


@dataclass(frozen=True)
class Mutant:
    name: str
    what: str  # the defect, in words
    apply: Apply
    # where the defect shows (a bundled name, an example station's file name or hub:T:N): tried there first, so a
    # run stops early; the other stations are still tried after it when it is not caught there
    first: str = ""

    @contextmanager
    def applied(self) -> Iterator[None]:
        compiled = [m for m in native_modules() if m.startswith("liansuo.interlocking.")]
        if compiled:  # a patch of a compiled module would change nothing, and the defect would go untried
            raise RuntimeError(f"mutant {self.name}: the interlocking runs compiled ({', '.join(compiled)}); seeded "
                               "defects need its Python sources (LIANSUO_PURE=1, or run_mutants)")
        with ExitStack() as stack:
            self.apply(stack)
            yield

MUTANTS: tuple[Mutant, ...] = (
    Mutant("no-head-on-enemies", "the table leaves out opposing routes onto one track (train against train or "
           "shunting movement)", table.no_head_on),
    Mutant("no-diamond", "the table ignores diamond crossings: no conflict, no protection of the crossing track",
           table.no_diamonds, first="shuangxian"),
    Mutant("no-flank-protection", "the table lists no flank protection turnouts", table.no_protection,
           first="doubleslip"),
    Mutant("guide-over-lost-indication", "the guide aspect opens over a route with a turnout out of position or "
           "without indication", table.guide_over_lost_indication),
    Mutant("no-run-on", "a shunting route ending at a signal of the other direction stops there on paper; the "
           "movement runs on unprotected", table.no_run_on),
    Mutant("no-overlap", "receiving routes lock no overlap (延续进路)", table.no_overlap, first="danxian"),
    Mutant("approach-one-section", "approach locking is one section everywhere, whatever the line",
           table.approach_one_section, first="shuangxian"),
    Mutant("empty-conflict-table", "the table lists no conflicting routes at all", table.no_conflict_table),
    Mutant("usu-without-onward-check", "USU is given whatever turnouts the onward route diverges over",
           cbi.usu_without_onward, first="shuangxian"),
    Mutant("throw-ignores-locks", "individual operation moves a locked turnout", cbi.throw_ignores_locks),
    Mutant("throw-ignores-section-locks", "a turnout standing in a locked section is not locked with it",
           cbi.throw_ignores_section_locks),
    Mutant("blind-to-occupancy", "a signal opens and stays open over an occupied section", cbi.blind_to_occupancy),
    Mutant("blind-to-indication", "a signal opens and stays open over a turnout without indication",
           cbi.blind_to_indication),
    Mutant("reopens-by-itself", "a signal closed abnormally reopens once the fault is gone", cbi.reopens_by_itself),
    Mutant("no-three-point-check", "sections release as soon as they are clear, without the three-point check",
           cbi.no_three_point_check),
    Mutant("cancel-ignores-approach", "a route is cancelled at once with a train approaching",
           cbi.cancel_ignores_approach),
    Mutant("no-release-delay", "manual time release releases at once", cbi.no_release_delay),
    Mutant("no-red-lamp-check", "a dark red lamp goes unnoticed: no red lamp transfer (红灯转移)",
           cbi.no_red_lamp_check),
    Mutant("no-red-lamp-transfer-on-the-line", "the block signal in rear of a dark red lamp is not held at H",
           cbi.no_red_lamp_transfer_on_the_line, first="shuangxian"),
    Mutant("no-lamp-proving", "a dark lamp does not change the aspect commanded", cbi.no_lamp_proving),
    Mutant("deaf-to-flash-check", "USU is kept with the flasher's check relay down", cbi.deaf_to_flash_check,
           first="shuangxian"),
    Mutant("deaf-to-doors", "signals open with screen doors open", cbi.deaf_to_doors, first="shuangxian"),
    Mutant("no-64d-acceptance", "a 64D departure opens without the neighbour's acceptance", cbi.no_64d_check),
    Mutant("64d-block-over-occupied-line", "a 64D block is given with the line's departure section occupied",
           cbi.block_over_occupied_line),
    Mutant("station-block-ignores-neighbour", "a departure onto a station-block line opens although the neighbour "
           "has blocked the line for its own train", cbi.station_block_ignores_neighbour, first="danxian"),
    Mutant("station-block-blind-to-counters", "the station block never reads the line's axle counters: a "
           "departure opens with the line showing occupied", cbi.station_block_blind_to_counters, first="danxian"),
    Mutant("line-without-block-unchecked", "a departure onto a line with no block described ignores the line's "
           "track circuits", cbi.line_without_block_unchecked, first="hub:10:4"),
    Mutant("against-running-direction", "a departure against a line's running direction opens without 改方",
           cbi.against_running_allowed, first="shuangxian"),
    Mutant("guide-lock-ignores-doors", "the guide aspect under guide total lock ignores the screen doors",
           cbi.guide_lock_ignores_doors, first="shuangxian"),
    Mutant("guide-stays-open", "the guide aspect stays lit after the guided train has entered", cbi.guide_stays_open),
    Mutant("no-power-up-lock", "after the interlocking starts, the station is not locked", cbi.no_power_up_lock),
    Mutant("overlap-released-at-once", "the overlap releases as soon as the train is on the receiving track",
           cbi.overlap_released_at_once, first="danxian"),
    Mutant("table-conflicts-skipped", "route setting skips the table's conflicts (only locked sections and "
           "turnouts stop it)", cbi.table_conflicts_skipped),
    Mutant("open-signal-unwatched", "an open signal is not looked at again while it was fine last cycle, whatever "
           "relay changed since", cbi.open_skip_blind_to_relays),
    Mutant("open-signal-blind-ahead", "an open signal keeps its aspect when the signal ahead changes",
           cbi.open_skip_blind_to_the_signal_ahead),
    Mutant("rest-deaf-to-relays", "the interlocking at rest sleeps on through relay changes, until a command or "
           "a timer wakes it", cbi.rest_deaf_to_relays),
    Mutant("route-over-locked-sections", "route setting ignores sections other routes hold (an overlap after its "
           "route has released)", cbi.route_ignores_locked_sections, first="danxian"),
    Mutant("no-crossing-check", "a route over a diamond crossing does not check the section of the track that "
           "crosses it", cbi.no_crossing_check, first="jiaocha"),
    Mutant("overlap-fault-release-at-once", "a section fault release of an overlap is carried out at once, under "
           "the open signal or with a train approaching", cbi.overlap_fault_release_at_once, first="danxian"),
    Mutant("fault-release-ahead-at-once", "a section fault release ahead of a movement in its route is carried out "
           "at once", cbi.fault_release_ahead_at_once),
    Mutant("fault-release-cuts-time-release", "a section fault release given while its route counts down a time "
           "release frees the route at once when the approach shows clear", cbi.fault_release_cuts_time_release),
    Mutant("time-release-ends-on-any-occupancy", "a manual time release ends as if a movement had entered when any "
           "section of the route shows occupied", cbi.time_release_ends_on_any_occupancy),
    Mutant("direction-change-ignores-guide", "the line's direction changes while a guide aspect calls a train in "
           "from it", cbi.direction_change_ignores_guide, first="podao"),
    Mutant("home-ignores-line-direction", "a home signal receives from a line set for departures from the station",
           cbi.home_ignores_line_direction, first="podao"),
    Mutant("overlap-from-the-yard", "the overlap is derived from the gradient beyond the end signal, not from the "
           "approach outside the home signal", cbi.overlap_from_the_yard, first="podao"),
    Mutant("through-route-in-one-order", "a through movement is refused when its departure is set first or its "
           "overlap is timing", cbi.through_route_in_one_order, first="danxian"),
    Mutant("guide-route-checks-occupancy", "a guide route is refused over the occupied section it is meant for",
           cbi.guide_route_checks_occupancy),
    Mutant("guide-blind", "routes and guide aspects ignore a guide aspect lit under guide total lock",
           cbi.guide_blind),
    Mutant("release-delay-a-tenth", "a manual time release waits a tenth of its delay (18 s for 180 s)",
           cbi.release_delay_tenth),
    Mutant("shunt-delay-for-trains", "a manual time release of a train route waits the shunting delay (30 s)",
           cbi.shunt_delay_for_trains),
    Mutant("overlap-time-a-tenth", "the overlap releases a tenth of its time after the train reached the receiving "
           "track", cbi.overlap_time_tenth, first="danxian"),
    Mutant("guide-never-times-out", "an unused guide aspect stays lit for ever", cbi.guide_never_times_out),
    Mutant("power-up-release-over-occupancy", "the power-up release is given with sections showing occupied",
           cbi.power_up_release_over_occupancy),
    Mutant("fault-release-of-station-track", "a section fault release of a station track is carried out",
           cbi.fault_release_of_station_track),
    Mutant("fault-release-under-open-signal", "a section fault release is carried out under the open signal",
           cbi.fault_release_under_open_signal),
    Mutant("reopen-without-conditions", "a signal closed abnormally is reopened without its conditions checked",
           cbi.reopen_without_conditions),
    Mutant("queued-move-under-a-vehicle", "a turnout move waiting in the queue starts without looking again at "
           "its section", cbi.queued_move_under_a_vehicle),
    Mutant("second-lamp-unproved", "lamp proving looks at an aspect's first lamp only", cbi.second_lamp_unproved),
    Mutant("guide-before-power-up-release", "a guide aspect under guide total lock is given before the power-up "
           "release", cbi.guide_before_power_up_release),
)
