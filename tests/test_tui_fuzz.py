"""Fuzzing the console (issue 17, item 5): random operator sessions, derandomized and short, through Textual's pilot
(``proving/fuzz/console.py``; ``liansuo fuzz console --budget N`` runs the same generator longer). Each sample is a
bundled station, a window and a few dozen keys, typed and pasted commands, clicks, bursts of clicks, palette and dialog
sequences, resizes down to 1x1 and waits; the console must survive every one, with no error even caught and shown."""

from __future__ import annotations

import time

from hypothesis import HealthCheck, Phase, given, settings

from liansuo.proving.fuzz import console as fuzz

SAMPLE_LIMIT_S = 15.0  # a sample is a few seconds at most even on a slow, shared machine: far more is a hang


@settings(derandomize=True, max_examples=10, deadline=None, database=None,  # the long run: liansuo fuzz console
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(fuzz.strategy())
def test_the_console_survives_random_operator_sessions(sample: fuzz.Sample) -> None:
    start = time.monotonic()
    assert fuzz.attempt(sample) == "accepted", fuzz.describe(sample)
    assert time.monotonic() - start < SAMPLE_LIMIT_S, fuzz.describe(sample)


def test_the_samples_reach_the_palette_the_dialogs_commands_clicks_and_tiny_windows() -> None:
    """The generator is worth running: its samples open the palette and every dialog, type commands with extreme
    numbers, paste escape sequences, click in bursts and shrink the window to 1x1."""
    seen: list[fuzz.Sample] = []

    @settings(derandomize=True, max_examples=150, database=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @given(fuzz.strategy())
    def collect(sample: fuzz.Sample) -> None:
        seen.append(sample)

    collect()
    events = [e for s in seen for e in s.events]
    for key in ("ctrl+p", "ctrl+q", "P", "f2", "question_mark", "y", "escape"):
        assert fuzz.Key(key) in events, key
    assert fuzz.Resize(1, 1) in events
    assert any(isinstance(e, fuzz.Click) and e.twice for e in events)
    assert any(isinstance(e, fuzz.ClickElement) for e in events)
    assert any(isinstance(e, fuzz.Type) and "nan" in e.text.split() for e in events)
    assert any(isinstance(e, fuzz.Paste) and "\x1b" in e.text for e in events)
    assert {s.station for s in seen} == set(fuzz.STATIONS)
