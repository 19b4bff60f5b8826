"""Fuzzing in the suite (issue 17, docs/robustness.md "Recordings"): damaged copies of real recordings through
``replay --verify``'s path, derandomized with a small budget; ``liansuo fuzz recordings --budget N`` runs longer."""

from __future__ import annotations

import time

from hypothesis import HealthCheck, given, settings

from liansuo.proving.fuzz import recordings as fuzzrecordings

SAMPLE_LIMIT_S = 10.0  # far above what a sample takes (well under a second): only a hang reaches it


@settings(derandomize=True, max_examples=60, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(fuzzrecordings.strategy())
def test_a_damaged_recording_is_refused_or_replays_never_a_traceback_or_a_hang(sample: bytes) -> None:
    started = time.monotonic()
    assert fuzzrecordings.attempt(sample) in ("accepted", "refused")
    assert time.monotonic() - started < SAMPLE_LIMIT_S


def test_the_seeds_are_real_recordings_that_replay() -> None:
    seeds = fuzzrecordings.seeds()
    assert len(seeds) == 1 + len(fuzzrecordings.SCENARIOS)
    assert all(fuzzrecordings.attempt(seed) == "accepted" for seed in seeds)
    assert all(b'"k":"cyc"' in seed and b'"k":"cmd"' in seed for seed in seeds)  # trains moved, commands sent
