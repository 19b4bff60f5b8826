"""The range of every number liansuo reads, from a file or a command, and why: one place for all of them.

A number outside its range is refused where it is read: a station file at its ``FILE:LINE:COLUMN`` (the schema,
:mod:`.schema`, and the cross-checks, :mod:`.checks`), a command with a refusal that gives the range (the command
language, :mod:`liansuo.simulation.commands`, :mod:`liansuo.circuits.faults`). Every number must also be finite:
``.nan`` and ``.inf`` are refused everywhere. The limits are physical (what a railway has) widened to what the
models can still compute and a user can wait for, so that whatever ``liansuo check`` accepts every other command
accepts too, in time proportional to the station's size (docs/robustness.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pydantic import AfterValidator, Field

from liansuo.kit.fit import number


@dataclass(frozen=True)
class Limit:
    """The allowed range of one kind of number: ``low`` to ``high`` in ``unit`` (``low`` itself excluded where
    ``above``); ``whole`` for a count. ``why`` says where the figures come from."""

    what: str  # the quantity, as a message names it: 'a position', 'a train's length'
    unit: str  # 'm', 'km/h', '' for a count
    low: float
    high: float
    why: str
    above: bool = False  # low itself is not allowed (a length of 0)
    whole: bool = False

    def range_text(self) -> str:
        """'from 0 to 4000 m', 'above 0 and up to 400 km/h', 'a whole number from 1 to 1200'."""
        unit = f" {self.unit}" if self.unit else ""
        head = "a whole number " if self.whole else ""
        if self.above:
            return f"{head}above {number(self.low)} and up to {number(self.high)}{unit}"
        return f"{head}from {number(self.low)} to {number(self.high)}{unit}"

    def holds(self, value: float) -> bool:
        if not math.isfinite(value) or (self.whole and value != int(value)):
            return False
        return (value > self.low if self.above else value >= self.low) and value <= self.high

    def problem(self, name: str, value: float, shown: str | None = None) -> str:
        """'' when ``value`` is in range, else '``name`` must be RANGE, not SHOWN' (a refusal's words; ``shown`` is
        the value as the user wrote it, by default ``value``)."""
        if self.holds(value):
            return ""
        text = shown if shown is not None else f"{value:g}"
        if len(text) > 40:  # a number of 400 digits
            text = f"{text[:37]}..."
        return f"{name} must be {self.range_text()}, not '{text}'"

    def field(self, **extra: Any) -> Any:
        """The range in a JSON Schema (what editors check), for a pydantic model's field; :meth:`check` validates."""
        low = {"exclusiveMinimum": self.low} if self.above else {"minimum": self.low}
        return Field(json_schema_extra={**low, "maximum": self.high}, **extra)

    def check(self) -> AfterValidator:
        """A pydantic validator refusing a number out of range, in the words of :meth:`range_text`."""
        def inside(value: float) -> float:
            if not self.holds(value):
                raise ValueError(f"{self.what} must be {self.range_text()}")
            return value

        return AfterValidator(inside)


# ---- station files ----------------------------------------------------------------------------------------------
POSITION = Limit(
    "a position", "m", -10_000_000.0, 10_000_000.0,
    "kilometre posts of Chinese lines stay below K5000 (the Beijing-Guangzhou line ends near K2294); 10,000 km either "
    "way of the origin leaves room for any line")
EXTENT = Limit(
    "a station's extent", "m", 0.0, 200_000.0,
    "from the lowest to the highest position of the station's ends, joints and turnouts. A station with its approach, "
    "departure and block sections spans a few km, a station-to-station block line some tens; the track-circuit "
    "models solve a section as one exact line, and a 25 Hz line of some 800 km overflows floating point")
TRACK_LENGTH = Limit(
    "a track's length", "m", 0.0, EXTENT.high,
    "a track lies within its station (the extent above)", above=True)
ZPW_SECTION = Limit(
    "a ZPW-2000A section's length", "m", 0.0, 10_000.0,
    "real sections are at most some 1,500 m (the adjustment table stops at 2 km); past about 20 km in wet ballast the "
    "model's line equations leave floating point")
STRETCH = Limit(
    "a marker's stretch", "m", 0.0, EXTENT.high,
    "a sanding or washing stretch lies on its track, within the station; 0 for a point")
DEAD_ZONE = Limit(
    "a dead zone", "m", 0.0, 30.0,
    "the two rails' joints are staggered by a few metres (the design rule warns over 2.5 m); 30 m, the most 'at2' "
    "may lie from 'at', is no joint any more")
TUNING_AREA = Limit(
    "a tuning area", "m", 0.0, 100.0,
    "the standard ZPW-2000A tuning area is 29 m (the design rule warns beyond 3 m off it)", above=True)
CAPACITANCE = Limit(
    "a capacitance", "uF", 1.0, 1000.0,
    "ZPW-2000A compensation capacitors are 25 to 80 uF; a tenth or ten times that is still a capacitor")
RELEASE = Limit(
    "a release delay", "s", 0.0, 600.0,
    "the Chinese rules release after 180 s (train) or 30 s (shunting), overlaps after 180 s; a station's own delay is "
    "of that order, and verify and the console wait it out for every route", above=True)
SPEED = Limit(
    "a speed", "km/h", 0.0, 400.0,
    "the fastest Chinese lines run at 350 km/h", above=True)
STOP_WINDOW = Limit(
    "a stopping window", "m", 0.0, 100.0,
    "a train stops within half a metre (screen doors) to a few metres of its stopping point", above=True)
DOUBLE_SLIP_LENGTH = Limit(
    "a double slip's length", "m", 0.0, 200.0,
    "a double slip is some 30 to 40 m long from its low-end to its high-end points", above=True)
DIAGRAM = Limit(
    "a diagram coordinate", "", -10_000.0, 10_000.0,
    "a row or column of the console's station diagram: the console draws a grid that large (a hub of 1,000 turnouts "
    "uses some 50 rows)")

# ---- commands -----------------------------------------------------------------------------------------------------
RUN = Limit(
    "a run", "s", 0.0, 3600.0,
    "one 'run' command: the longest wait of the bundled scripts is 7 min, the longest timer of the rules 3 min; an "
    "hour of simulated time takes well under a second to compute on a small station, and the console shows it")
SCENARIO = Limit(
    "a scenario's length", "s", 0.0, 86_400.0,
    "a scenario's 'until' (or 'liansuo run --until'): a day of simulated time, run headless")
SLIP = Limit(
    "a slip", "s", 0.0, RUN.high,
    "how long the wheels slip or slide: seconds in reality; at most one 'run'", above=True)
TRAIN_LENGTH = Limit(
    "a train's length", "m", 0.0, 4000.0,
    "the longest Chinese trains, the 30,000 t heavy-haul trains of the Daqin line, are some 3.8 km long", above=True)
AXLES = Limit(
    "a number of wheelsets", "", 2.0, 1200.0,
    "a trolley has 2; a 4 km train of 14 m four-axle wagons some 1,150", whole=True)
TRAIN_SPEED = Limit(
    "a train's top speed", "km/h", 0.0, SPEED.high,
    "as a line speed: the fastest Chinese lines run at 350 km/h", above=True)
BACK = Limit(
    "a distance to the section's end", "m", 0.0, EXTENT.high,
    "where a placed train's front stands short of the end of its section: within the station", above=True)
POOR_SHUNT = Limit(
    "a shunt resistance", "ohm", 0.0, 1000.0,
    "rusty rails or a light vehicle shunt through some tenths of an ohm to a few ohms; at 1,000 ohm no track circuit "
    "sees the wheelset at all")
BALLAST = Limit(
    "a ballast resistance", "ohm*km", 0.05, 1000.0,
    "wet or dirty ballast leaks down to a few tenths of an ohm*km, dry ballast some hundreds; below 0.05 the "
    "line equations of a long section leave floating point")
CAPACITOR_NUMBER = Limit(
    "a capacitor's number", "", 1.0, 60.0,
    "compensation capacitors are numbered from 1 at the section's lower end; a section has at most 60 (the station "
    "file's limit), the field refuses one past the section's own count", whole=True)
OBSTRUCTION = Limit(
    "an obstruction", "mm", 0.0, 200.0,
    "between switch rail and stock rail: from a sliver to a stone or a wooden block; 4 mm already stops the lock")
SWITCH_FORCE = Limit(
    "a switching resistance", "N", 0.0, 100_000.0,
    "a switch machine pushes some 2,000 to 6,000 N; ice or a seized slide chair can resist many times that")
ODOMETRY_BOUND = Limit(
    "an odometry error bound", "m", 0.0, EXTENT.high,
    "the error an 'expect odometry' allows: within the station")


# How many items each list of a station file may hold (StationFile in :mod:`.schema`). The largest real stations
# (hubs such as Zhengzhou North) have some 1,000 signals and 600 turnouts; the generated hub of 2,000 turnouts and
# 400 station tracks (liansuo generate hub), far beyond them, has 3,208 signals, 25,124 tracks and 21,124 sections
# and takes some 20 s and 0.5 GB to check or table on one core (docs/robustness.md, "Station size"). A station past
# these counts is refused by check, before any work grows with it.
STATION_ITEMS: dict[str, int] = {
    "ends": 2_000, "joints": 30_000, "turnouts": 2_500, "tracks": 30_000, "sections": 30_000, "signals": 4_000,
    "buttons": 2_000, "fouling_points": 5_000, "diamonds": 1_000, "double_slips": 1_000, "profile": 5_000,
    "markers": 5_000, "platforms": 1_000, "links": 1_000, "overlaps": 5_000,
}
