"""What crosses the wire in one cycle, both ways, by the point map (:mod:`.points`): the interlocking's commands as
coils and code registers, the field's relays as discrete inputs.

The interlocking's side builds coils from its :class:`~circuits.field.FieldCommands` and reads a
:class:`~simulation.fieldlink.Reading` from the inputs; the field's side (the field simulator, or any PLC program
that follows docs/field-mode.md) does the reverse. Whatever is contradictory or unknown on arrival is taken the
safe way: both turnout drives at once is no drive, an unknown code value is no code, a lamp not driven is dark.
"""

from __future__ import annotations

from liansuo.circuits.field import Field, FieldCommands
from liansuo.fieldio.points import PointMap
from liansuo.simulation.fieldlink import Reading


# ---- the interlocking's side ---------------------------------------------------------------------------------------
def coils(pm: PointMap, cmd: FieldCommands | None) -> list[bool]:
    """Every coil from address 0: the commands, or with ``cmd`` None every output de-energised."""
    out = [False] * pm.coil_count
    if cmd is None:
        return out
    for p in pm.file.outputs:
        e, r = p.element, p.relay
        if r == "lamp":
            on = p.lamp in cmd.lamps.get(e, ())
        elif r == "flasher":
            on = e in cmd.flashing
        elif r == "DCJ":
            on = cmd.drives.get(e) == "normal"
        elif r == "FCJ":
            on = cmd.drives.get(e) == "reverse"
        elif r == "reset":
            on = e in cmd.axle_resets
        else:  # door relays
            zckj, kmj, gmj = cmd.doors.get(e, (False, False, False))
            on = {"ZCKJ": zckj, "KMJ": kmj, "GMJ": gmj}[r]
        out[p.at] = on
    return out


def code_registers(pm: PointMap, cmd: FieldCommands | None) -> list[int]:
    """The code registers from the first (:attr:`PointMap.register_span`); all 0 (no code) with ``cmd`` None."""
    first, count = pm.register_span
    out = [0] * count
    if cmd is None:
        return out
    values = pm.file.code_values
    for p in pm.file.codes:
        code = cmd.cab_codes.get(p.section)
        out[p.at - first] = values.get(code, 0) if code else 0
    return out


def reading(pm: PointMap, bits: list[bool]) -> Reading:
    """The relays in ``bits`` (discrete inputs from address 0); a point past the bits read is read as dropped."""
    r = Reading()
    dbj: dict[str, bool] = {}
    fbj: dict[str, bool] = {}
    pdkj: dict[str, bool] = {}
    pdqcj: dict[str, bool] = {}
    for p in pm.file.inputs:
        up = p.at < len(bits) and bool(bits[p.at])
        e = p.element
        if p.relay == "GJ":
            r.tracks[e] = up
        elif p.relay == "DBJ":
            dbj[e] = up
        elif p.relay == "FBJ":
            fbj[e] = up
        elif p.relay == "DJ" and p.lamp is not None:
            r.lamps.setdefault(e, {})[p.lamp] = up
        elif p.relay == "SNJ":
            r.flashers[e] = up
        elif p.relay == "DSBJ":
            r.filaments[e] = up
        elif p.relay == "PDKJ":
            pdkj[e] = up
        elif p.relay == "PDQCJ":
            pdqcj[e] = up
    r.turnouts = {t: (dbj.get(t, False), fbj.get(t, False)) for t in dbj.keys() | fbj.keys()}
    r.doors = {k: (pdkj.get(k, False), pdqcj.get(k, False)) for k in pdkj.keys() | pdqcj.keys()}
    return r


# ---- the field's side ----------------------------------------------------------------------------------------------
def commands(pm: PointMap, coil_bits: list[bool], registers: dict[int, int], last: FieldCommands) -> FieldCommands:
    """The commands the coils and code registers carry; a signal's lamps are marked changed against ``last``."""
    def on(at: int) -> bool:
        return at < len(coil_bits) and bool(coil_bits[at])

    cmd = FieldCommands()
    lamps: dict[str, set[str]] = {}
    normal: set[str] = set()
    reverse: set[str] = set()
    doors: dict[str, dict[str, bool]] = {}
    for p in pm.file.outputs:
        e, r = p.element, p.relay
        if r == "lamp" and p.lamp is not None:
            lit = lamps.setdefault(e, set())
            if on(p.at):
                lit.add(p.lamp)
        elif r == "flasher" and on(p.at):
            cmd.flashing.add(e)
        elif r == "DCJ" and on(p.at):
            normal.add(e)
        elif r == "FCJ" and on(p.at):
            reverse.add(e)
        elif r == "reset" and on(p.at):
            cmd.axle_resets.add(e)
        elif r in ("ZCKJ", "KMJ", "GMJ"):
            doors.setdefault(e, {})[r] = on(p.at)
    cmd.drives = {t: "normal" for t in normal - reverse} | {t: "reverse" for t in reverse - normal}
    cmd.lamps = lamps
    cmd.changed_signals = {s for s in lamps if lamps[s] != last.lamps.get(s) or
                           (s in cmd.flashing) != (s in last.flashing)}
    cmd.doors = {k: (d.get("ZCKJ", False), d.get("KMJ", False), d.get("GMJ", False)) for k, d in doors.items()}
    by_value = {v: code for code, v in pm.file.code_values.items()}
    cmd.cab_codes = {p.section: by_value.get(registers.get(p.at, 0)) for p in pm.file.codes}
    return cmd


def inputs(pm: PointMap, field: Field) -> list[bool]:
    """The discrete inputs from address 0, as ``field``'s relays stand now."""
    out = [False] * pm.input_count
    for p in pm.file.inputs:
        e, r = p.element, p.relay
        if r == "GJ":
            up = field.track_up(e)
        elif r in ("DBJ", "FBJ"):
            up = field.indication(e)[r == "FBJ"]
        elif r == "DJ" and p.lamp is not None:
            up = field.lamp_proven(e, p.lamp)
        elif r == "SNJ":
            up = field.flasher_ok(e)
        elif r == "DSBJ":
            up = field.filament_alarm(e)
        else:
            up = field.doors_relays(e)[r == "PDQCJ"]
        out[p.at] = up
    return out
