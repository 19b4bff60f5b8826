"""The fuzz kind ``stations`` in the suite: mutants of the example stations through check, table and verify, each
answered with a station or a FILE:LINE:COLUMN refusal (exit status 3) within seconds (docs/robustness.md)."""

from __future__ import annotations

import time

from hypothesis import given, settings

from liansuo.proving.fuzzstations import NAME, StationSample, attempt, strategy

SECONDS = 10  # per sample: check, table and verify of a small station take well under one


@settings(derandomize=True, max_examples=60, deadline=None, database=None)
@given(strategy())
def test_station_mutants_are_answered_not_crashed(sample: StationSample) -> None:
    start = time.monotonic()
    assert attempt(sample) in ("accepted", "refused")
    assert time.monotonic() - start < SECONDS, f"{sample.changes} took {time.monotonic() - start:.1f} s"


def test_the_kind_is_named_for_the_fuzz_command() -> None:
    assert NAME == "stations"
