"""How much liansuo reads from one file, kept as data in one place (docs/robustness.md, "Reading files").

Every YAML file (stations, test scripts, scenarios, exercises, rule files, a recording's kind check) is read by
:mod:`.safeyaml` within these limits, so a file can make liansuo refuse it with a ``FILE:LINE:COLUMN`` message but can
never make it run out of memory or time. Each limit is far above what a real file needs; the comment says why.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class InputLimits:
    """The limits on one file; :data:`LIMITS` is the one set every reader uses."""

    # bytes in one file: the generated hub of 2,000 turnouts over 400 tracks (far beyond any real station) is 4 MB
    max_file_bytes: int = 16 * 1024 * 1024
    # values repeated through YAML aliases ('*name' copies what '&name' marks), counted as the reader expands them:
    # a station may share a list of lamps or a mapping of settings; 700 bytes of aliases nested 9 deep would
    # otherwise expand to 10^9 values
    max_alias_values: int = 100_000
    # levels of lists and mappings inside each other: a station file nests 6 deep; deeper nesting only comes from a
    # mistake or a crafted file, and crashes YAML's C reader past a few tens of thousands
    max_depth: int = 64
    # characters in one value: a description of a few paragraphs is a few thousand
    max_value_chars: int = 20_000
    # characters in one id (a signal, section, turnout, route ...): ids are those of the station diagram, at most a
    # dozen characters; a route id names up to five of them
    max_id_chars: int = 64


LIMITS = InputLimits()
