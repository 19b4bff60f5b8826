"""Consists: a locomotive and vehicles with their wheelsets, length, mass and performance."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Consist:
    """A train as the track sees it: wheelset offsets from the front, and how it moves."""

    axle_offsets_m: tuple[float, ...]  # distance of each wheelset behind the front of the train, front first
    length_m: float
    mass_t: float
    vmax_kmh: float
    accel_ms2: float = 0.5  # traction (at low speed)
    brake_ms2: float = 0.8  # service braking
    emergency_ms2: float = 1.2

    @property
    def axles(self) -> int:
        return len(self.axle_offsets_m)


def _vehicle_axles(start: float, length: float, bogie_centres: float, wheelbase: float, per_bogie: int) -> list[float]:
    """Wheelset offsets of one bogie vehicle whose front is at ``start``."""
    overhang = (length - bogie_centres) / 2
    out = []
    for centre in (start + overhang, start + overhang + bogie_centres):
        first = centre - wheelbase * (per_bogie - 1) / 2
        out += [first + i * wheelbase for i in range(per_bogie)]
    return out


def make_consist(kind: str = "freight", *, length_m: float | None = None, axles: int | None = None,
                 vmax_kmh: float | None = None) -> Consist:
    """A typical consist. ``freight``: a locomotive and 60-t wagons; ``emu``: an 8-car EMU; ``shunter``: a shunting
    locomotive alone; ``trolley``: a two-axle track trolley. ``length_m`` / ``axles`` scale the number of vehicles."""
    if kind == "trolley":
        return Consist((0.5, 4.5), 5.0, 8.0, vmax_kmh or 30.0, 0.5, 0.8)
    if kind == "shunter":
        return Consist(tuple(_vehicle_axles(0.0, 17.0, 9.0, 1.8, 3)), 17.0, 138.0, vmax_kmh or 40.0, 0.4, 0.8)
    if kind == "emu":
        car, centres, wb, per = 25.0, 17.5, 2.5, 2
        default_cars = 8
        mass_per, vmax, acc, brk = 55.0, 250.0, 0.6, 0.9
        loco = None
    else:
        car, centres, wb, per = 14.0, 9.4, 1.75, 2
        default_cars = 20
        mass_per, vmax, acc, brk = 80.0, 120.0, 0.3, 0.5
        loco = (21.0, 11.0, 1.8, 3)
    offs: list[float] = []
    front = 0.0
    if loco is not None:
        offs += _vehicle_axles(0.0, loco[0], loco[1], loco[2], loco[3])
        front = loco[0]
    cars = default_cars
    if length_m is not None:
        cars = max(1, round((length_m - front) / car))
    if axles is not None:
        loco_axles = len(offs)
        cars = max(1, round((axles - loco_axles) / (2 * per)))
    for i in range(cars):
        offs += _vehicle_axles(front + i * car, car, centres, wb, per)
    length = front + cars * car
    return Consist(tuple(offs), length, mass_per * cars + (138.0 if loco else 0.0), vmax_kmh or vmax, acc, brk)
