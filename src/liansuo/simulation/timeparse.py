"""Durations in commands: ``30s``, ``3min``, ``250ms``, ``1h``, or plain seconds."""

from __future__ import annotations

import re

_UNITS = {"ms": 0.001, "s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0}
_RE = re.compile(r"^(\d+(?:\.\d+)?)\s*(ms|sec|s|min|m|h)?$")


def parse_duration(text: str) -> float:
    m = _RE.match(text.strip())
    if not m:
        raise ValueError(f"'{text}' is not a duration: write e.g. 30s, 3min, 250ms")
    return float(m.group(1)) * _UNITS[m.group(2) or "s"]
