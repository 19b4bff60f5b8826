"""The fuzz runner finds what it is there to find: a traceback, a hang, a runaway allocation; and counts the rest.

The kinds here are made up on purpose, each with a known defect, because the runner is the thing under test: a
runner that missed a crash or a hang would let every real kind pass (tests/test_fuzz_*.py run the real ones).
"""

from __future__ import annotations

import json
import time
from types import ModuleType
from typing import Any

import pytest
from hypothesis import strategies as st

from liansuo.cli.main import main
from liansuo.proving.fuzz import cli as fuzzcli
from liansuo.proving.fuzz.runner import run


def _kind(name: str, strategy: Any, attempt: Any) -> ModuleType:
    module = ModuleType(name)
    module.NAME = name  # type: ignore[attr-defined]
    module.strategy = lambda: strategy  # type: ignore[attr-defined]
    module.attempt = attempt  # type: ignore[attr-defined]
    return module


def _divide(n: int) -> str:
    if n % 7 == 3:
        return "refused"
    return "accepted" if 100 // (n % 5) else "refused"  # n % 5 == 0 divides by zero, like `ohm_km=0` once did


def _sleepy(n: int) -> str:
    if n == 3:
        time.sleep(30)
    return "accepted"


def _greedy(n: int) -> str:
    if n == 2:
        _ = bytearray(8 * 1024**3)  # 8 GB: past the cap, MemoryError instead of the machine's memory
    return "accepted"


def test_tracebacks_are_counted_with_their_place_and_sample() -> None:
    rep = run(_kind("divide", st.integers(0, 40), _divide), 60, seed=1)
    assert rep.samples > 0
    crashed = [d for d in rep.defects if d.kind == "traceback"]
    assert crashed and all(d.error.startswith("ZeroDivisionError") for d in crashed)
    assert all("_divide" in d.where and d.sample.isdigit() and int(d.sample) % 5 == 0 for d in crashed)
    assert rep.accepted + rep.refused + len(rep.defects) == rep.samples
    assert rep.refused > 0 and not rep.ok


def test_a_hang_is_cut_at_the_limit() -> None:
    started = time.perf_counter()
    rep = run(_kind("sleepy", st.just(3), _sleepy), 2, limit_s=0.5)
    assert time.perf_counter() - started < 10
    assert [d.kind for d in rep.defects] == ["hang"] * len(rep.defects) and rep.defects
    assert "0.5 s" in rep.defects[0].error


def test_a_runaway_allocation_is_a_defect_not_the_end_of_the_machine() -> None:
    rep = run(_kind("greedy", st.just(2), _greedy), 1, memory_mb=2048)
    assert rep.defects and rep.defects[0].error.startswith("MemoryError")
    assert bytearray(64 * 1024**2)  # the cap is lifted afterwards


def test_the_same_seed_draws_the_same_samples() -> None:
    seen: list[list[int]] = [[], []]
    for k in range(2):
        run(_kind("record", st.integers(0, 10**6), lambda n, k=k: seen[k].append(n) or "accepted"), 25, seed=7)
    assert seen[0] == seen[1] and len(set(seen[0])) > 5


def test_command_line_report_and_kept_samples(monkeypatch: pytest.MonkeyPatch, tmp_path: Any,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(fuzzcli, "kind_module", lambda kind: _kind("divide", st.integers(0, 40), _divide))
    status = main(["fuzz", "recordings", "--budget", "40", "--format", "json", "--keep", str(tmp_path / "kept")])
    out = capsys.readouterr().out
    body = json.loads(out[:out.rindex("}") + 1])
    assert status == 1 and body["ok"] is False and body["schema"] == 1
    assert body["tracebacks"] == len(body["defects"]) > 0 and body["hangs"] == 0
    kept = sorted((tmp_path / "kept").iterdir())
    assert len(kept) == body["tracebacks"] and int(kept[0].read_text()) % 5 == 0
    with pytest.raises(SystemExit) as refused:
        main(["fuzz", "recordings", "--budget", "0"])
    assert refused.value.code == 2 and "0 is not a positive number" in capsys.readouterr().err
