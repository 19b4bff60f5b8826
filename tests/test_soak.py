"""`liansuo soak`: long random runs under the safety checker, a reproducer script for each violation, and scripts
with `safety: true` that replay them."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from liansuo.cli.main import main
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.proving.soak.run import soak


def test_soak_reports_steps_and_no_violations(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["soak", "jiaopei", "--steps", "300", "--seed", "3", "--format", "json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["steps"] == 300 and rep["violations"] == [] and rep["cycles"] >= 300
    assert rep["station"] == "jiaopei" and rep["seed"] == 3
    assert all(isinstance(n, int) and n > 0 for n in rep["hazards"].values())  # counted apart from violations


def test_the_same_seed_gives_the_same_run() -> None:
    a, b = soak("gaotie", 120, 9), soak("gaotie", 120, 9)
    assert a.lines == b.lines and a.cycles == b.cycles
    assert soak("gaotie", 120, 10).lines != a.lines


def test_the_generator_exercises_the_whole_language() -> None:
    words = {line.split()[0] for line in soak("gaotie", 700, 4).lines}
    assert {"route", "shunt", "cancel", "release", "reopen", "throw", "occupy", "fault", "repair", "axles",
            "run", "doors"} <= words
    if "train" in words:  # trains, once the command language has them
        assert "drive" in words


def forgetful(real: object) -> object:
    def advance(self: RouteLifecycle, rs: RouteState) -> None:  # an interlocking that reopens a signal by itself
        if rs.stage is RouteStage.closed:
            rs.stage = RouteStage.locked
        real(self, rs)  # type: ignore[operator]

    return advance


def test_a_violation_comes_with_a_short_reproducer_that_replays_it(monkeypatch: pytest.MonkeyPatch,
                                                                    tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(RouteLifecycle, "advance", forgetful(RouteLifecycle.advance))
    assert main(["soak", "jiaopei", "--steps", "200", "--seed", "8", "--format", "json",
                 "--out", str(tmp_path)]) == 1
    rep = json.loads(capsys.readouterr().out)
    first = rep["violations"][0]
    assert first["property"] == "reopened" and first["reproducer"]
    script = yaml.safe_load(first["reproducer"])
    assert script["safety"] is True and script["station"] == "jiaopei"
    steps = script["tests"][0]["steps"]
    assert 0 < len(steps) < first["line"]  # cut down from the run
    files = sorted(tmp_path.glob("soak-jiaopei-8-*.yaml"))
    assert files and files[0].read_text(encoding="utf-8") == first["reproducer"]
    # replayed by liansuo test: it fails at the step where the signal reopens by itself
    assert main(["test", str(files[0])]) == 1
    out = capsys.readouterr().out
    assert "safety violation at t =" in out and "(reopened)" in out
    # and with the interlocking as it is, the same script passes
    monkeypatch.undo()
    assert main(["test", str(files[0])]) == 0


def test_safety_scripts_pass_on_the_real_interlocking(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("station: jiaopei\nsafety: true\ntests:\n  - name: abnormal close and reopen\n    steps:\n"
                 "      - route X XI\n      - run 2s\n      - occupy IG\n      - run 1s\n      - vacate IG\n"
                 "      - run 5s\n      - reopen X\n      - run 1s\n      - expect signal X U\n", encoding="utf-8")
    assert main(["test", str(f)]) == 0
    f.write_text(f.read_text(encoding="utf-8").replace("safety: true", "safety: 1"), encoding="utf-8")
    assert main(["test", str(f)]) == 3  # a malformed script is a bad input file
    err = capsys.readouterr().err
    assert "safety: Input should be a valid boolean (got 1)" in err and "hint: write true or false" in err
