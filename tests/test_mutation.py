"""The checks are strong: seeded defects of the interlocking (proving/mutation/mutants.py) are caught by
``liansuo verify`` or the safety oracle, at least 95 % of them, and the report says by which check."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.proving.mutation.cli import default_stations, first_where_it_shows, run_mutants
from liansuo.proving.mutation.mutants import MUTANTS


@pytest.mark.slow  # make test-slow (CI runs it after make test)
def test_at_least_twenty_distinct_defects_and_95_percent_caught() -> None:
    assert len(MUTANTS) >= 20 and len({m.name for m in MUTANTS}) == len(MUTANTS)
    results = run_mutants()
    missed = [r.mutant for r in results if not r.by]
    assert len(results) == len(MUTANTS)
    assert (len(results) - len(missed)) / len(results) >= 0.95, f"not caught: {missed}"
    by = {r.mutant: r for r in results}
    # the defects the issue names, each caught by the check that sees it
    assert by["no-head-on-enemies"].check == "omitted-conflict"
    assert by["no-flank-protection"].check == "flank-protection"
    assert by["usu-without-onward-check"].by == "oracle"
    assert by["no-red-lamp-transfer-on-the-line"].by == "oracle"
    assert by["no-three-point-check"].check == "three-point-check"
    assert by["throw-ignores-section-locks"].by
    # the blind spots of timers, commands, queued moves and lamps beyond the first, each seen by what sees it
    assert by["release-delay-a-tenth"].by == "judge" and by["overlap-time-a-tenth"].check == "overlap-time"
    assert by["reopen-without-conditions"].check == "reopen"
    assert by["queued-move-under-a-vehicle"].by == "oracle" and by["second-lamp-unproved"].by == "oracle"
    assert by["guide-never-times-out"].check == "guide"


def test_the_mutate_command_reports_the_score(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["mutate", "--station", "jiaopei", "--mutant", "blind-to-indication", "--mutant",
                 "cancel-ignores-approach", "--format", "json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["mutants"] == 2 and rep["caught"] == 2 and rep["score"] == 1.0
    assert {r["caught_by"] for r in rep["results"]} == {"oracle", "judge"}  # the cancel: by the reference judge


def test_each_mutant_is_tried_first_where_it_shows_and_then_everywhere_else() -> None:
    stations = default_stations()
    for m in [m for m in MUTANTS if m.first]:  # where a defect shows is one of the stations a run tries
        ordered = first_where_it_shows(stations, m.first)
        assert sorted(ordered) == sorted(stations) and m.first in (ordered[0], Path(ordered[0]).stem), m.name
    assert first_where_it_shows(["jiaopei", "/x/danxian.yaml", "hub:10:4"], "danxian") == [
        "/x/danxian.yaml", "jiaopei", "hub:10:4"]
    assert first_where_it_shows(["jiaopei", "hub:10:4"], "hub:10:4") == ["hub:10:4", "jiaopei"]
    assert first_where_it_shows(["jiaopei", "depot"], "") == ["jiaopei", "depot"]
    assert first_where_it_shows(["jiaopei", "depot"], "nowhere") == ["jiaopei", "depot"]


def test_a_mutant_refuses_a_compiled_interlocking_rather_than_go_untried(monkeypatch: pytest.MonkeyPatch) -> None:
    """Under a native build (docs/native.md) a patch of a compiled module would change nothing: applying a mutant in
    a process where the interlocking runs compiled must say so, not run verify on the sound interlocking. The suite
    runs pure, so the compiled state is stood in for by what ``native_modules`` reports."""
    import liansuo.proving.mutation.mutants as mutants

    monkeypatch.setattr(mutants, "native_modules", lambda: ["liansuo.circuits.field", "liansuo.interlocking.core"])
    with pytest.raises(RuntimeError, match=r"interlocking runs compiled \(liansuo.interlocking.core\).*LIANSUO_PURE"), \
            MUTANTS[0].applied():
        pass
    monkeypatch.setattr(mutants, "native_modules", lambda: ["liansuo.circuits.field"])  # only the field compiled
    with MUTANTS[0].applied():
        pass
