"""The JSON Schema of ``liansuo table STATION --format json`` (``liansuo table --schema`` prints it)."""

from __future__ import annotations

from typing import Any

from liansuo.interlocking.table.signed import COLUMNS
from liansuo.kit.jsonreport import SCHEMAS

_STR = {"type": "string"}
_STRS = {"type": "array", "items": _STR}
_POSITION = {"enum": ["normal", "reverse"]}
_WHEN = {"type": "object", "additionalProperties": _POSITION}
_TURNOUT = {"type": "object", "required": ["id", "position", "role"], "additionalProperties": False,
            "properties": {"id": _STR, "position": _POSITION, "role": {"enum": ["route", "protection", "driven"]}}}
_NULL_STR = {"type": ["string", "null"]}

_ROUTE: dict[str, Any] = {
    "type": "object",
    "additionalProperties": False,
    "required": ["id", "kind", "category", "start", "end", "via", "signal", "direction", "aspects", "turnouts",
                 "sections", "fouling_sections", "approach", "overlap", "safety_line", "diamonds", "leads_into",
                 "run_on", "length_m", "exit_link", "line_sections", "conflicts", "conflict_reasons",
                 "conditional_conflicts", "opposing"],
    "properties": {
        "id": _STR, "kind": {"enum": ["train", "shunt"]},
        "category": {"enum": ["receiving", "departure", "transfer", "shunting"]},
        "start": _STR, "end": _STR, "via": _STRS, "signal": _STR, "direction": {"enum": ["down", "up"]},
        "aspects": _STRS, "turnouts": {"type": "array", "items": _TURNOUT}, "sections": _STRS,
        "fouling_sections": {"type": "array", "items": {
            "type": "object", "required": ["section", "turnout", "position", "diamond"], "additionalProperties": False,
            "properties": {"section": _STR, "turnout": _NULL_STR, "position": {"oneOf": [{"type": "null"}, _POSITION]},
                           "diamond": _NULL_STR}}},
        "approach": _STRS,
        "overlap": {"oneOf": [{"type": "null"}, {
            "type": "object", "required": ["sections", "turnouts", "release_s", "end", "alternative"],
            "additionalProperties": False,
            "properties": {"sections": _STRS, "release_s": {"type": "number"}, "end": _NULL_STR,
                           "alternative": {"type": "boolean"}, "turnouts": {"type": "array", "items": {
                "type": "object", "required": ["id", "position"], "additionalProperties": False,
                "properties": {"id": _STR, "position": _POSITION}}}}}]},
        "safety_line": _NULL_STR, "diamonds": _STRS, "leads_into": _NULL_STR,
        "run_on": {"type": "array", "items": {
            "type": "object", "required": ["when", "sections", "turnouts", "leads_into"], "additionalProperties": False,
            "properties": {"when": _WHEN, "sections": _STRS, "turnouts": {"type": "array", "items": _TURNOUT},
                           "leads_into": _NULL_STR}}},
        "length_m": {"type": "number"}, "exit_link": _NULL_STR, "line_sections": _STRS,
        "conflicts": _STRS, "conflict_reasons": {"type": "object", "additionalProperties": _STR},
        "conditional_conflicts": {"type": "object", "additionalProperties": {"type": "array", "items": {
            "type": "object", "required": ["when", "why"], "additionalProperties": False,
            "properties": {"when": _WHEN, "why": _STR}}}},
        "opposing": _STRS,
    },
}

_ROW = {"type": "object", "required": ["id", *(c.key for c in COLUMNS)], "additionalProperties": False,
        "properties": {"id": _STR, **{c.key: _STR for c in COLUMNS}}}

TABLE_SCHEMA: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "liansuo interlocking table (联锁表)",
    "type": "object",
    "additionalProperties": False,
    "required": ["liansuo", "schema", "ok", "station", "routes", "throats", "station_file", "groups"],
    "properties": {
        "liansuo": {"type": "string", "description": "the version of liansuo that wrote the table"},
        "schema": {"const": SCHEMAS["table"], "description": "the version of this JSON shape"},
        "ok": {"const": True},
        "station": _STR,
        "routes": {"type": "array", "items": _ROUTE},
        "throats": {"type": "object", "additionalProperties": _STRS},
        "station_file": {"type": "object", "required": ["name", "sha256"], "additionalProperties": False,
                         "properties": {"name": _STR, "sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"}}},
        "groups": {"type": "array", "items": {
            "type": "object", "required": ["name", "direction", "category", "throat", "rows"],
            "additionalProperties": False,
            "properties": {"name": _STR, "direction": {"enum": ["down", "up", None]},
                           "category": {"enum": ["receiving", "departure", "transfer", "shunting"]},
                           "throat": _NULL_STR, "rows": {"type": "array", "items": _ROW}}}},
    },
}
