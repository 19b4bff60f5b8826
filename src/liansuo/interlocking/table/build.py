"""The interlocking table (联锁表), derived from the topology: ``build_table(station)``.

The rows are :class:`~interlocking.route.Route`; :mod:`.derive` finds the routes, their turnouts, sections, overlaps
and run-ons, :mod:`.conflicts` the enemy routes.
"""

from __future__ import annotations

from liansuo.interlocking.table.derive import derive_table
from liansuo.interlocking.table.route import (
    Condition,
    FoulingSection,
    InterlockingTable,
    Kind,
    Role,
    Route,
    RouteTurnout,
    RunOn,
)
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.station import Station

__all__ = ["Condition", "FoulingSection", "InterlockingTable", "Kind", "Role", "Route", "RouteTurnout", "RunOn",
           "build_table"]


def build_table(station: Station, rules: RuleSet | None = None) -> InterlockingTable:
    """Derive the interlocking table under ``rules`` (default: the Chinese rule set); station-file overrides that
    name unknown routes raise StationError."""
    return derive_table(station, rules or load_rules())
