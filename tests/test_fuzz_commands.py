"""The command language under fuzzing (proving/fuzz/commands.py): random and mutated command lines on the bundled
stations never raise, and a refused line changes nothing. Derandomized and small here; ``liansuo fuzz commands``
runs the same generator longer (docs/robustness.md)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

from liansuo.proving.fuzz.commands import RefusalChangedState, Session, attempt, corpus, strategy

SAMPLE_LIMIT_S = 10.0  # a sample runs its lines and a few cycles: seconds at most, even with a 'run 1h'


@settings(derandomize=True, max_examples=60, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(strategy())
def test_command_lines_never_raise_and_refusals_change_nothing(sample: Session) -> None:
    started = time.perf_counter()
    assert attempt(sample) in ("accepted", "refused")
    assert time.perf_counter() - started < SAMPLE_LIMIT_S, str(sample)


def test_the_corpus_holds_the_bundled_scripts_and_scenarios() -> None:
    stations = {station for station, _ in corpus()}
    assert stations == {"jiaopei", "gaotie", "depot"}
    assert sum(len(steps) for _, steps in corpus()) > 200


def test_a_refusal_that_changes_the_state_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The fuzzer's own check: a command refused after it changed something is a defect it reports."""
    from liansuo.interlocking.io import Result
    from liansuo.simulation.sim import Simulation

    real = Simulation.command

    def command(sim: Simulation, line: str) -> Result:  # does what it was asked, then says it refused
        real(sim, line)
        return Result.refuse("no")

    monkeypatch.setattr(Simulation, "command", command)
    with pytest.raises(RefusalChangedState, match="'occupy 1DG' was refused"):
        attempt(Session("jiaopei", (), ("occupy 1DG",)))


def test_a_sample_reads_as_a_script(tmp_path: Path) -> None:
    """A sample prints as a test script ``liansuo test`` reads, control characters and all."""
    from liansuo.proving.scripts import parse_script

    lines = ("route X XI", "run 168h", "fault broken-rail 1DG at=\x1b[2J 'x'")
    path = tmp_path / "sample.yaml"
    path.write_text(str(Session("jiaopei", lines[:1], lines[1:])), encoding="utf-8")
    script = parse_script(path)
    assert script.station == "jiaopei" and [s.text for s in script.tests[0].steps] == list(lines)
