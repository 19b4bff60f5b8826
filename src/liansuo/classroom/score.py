"""The score of an assessment (docs/exercises.md, "Scoring"): 100 points at most.

```
score = goals + diagnosis + time - refused * r - unsafe * u - wrong diagnoses * w     (never below 0)
goals     = G * (points of the goals met) / (points of every goal)
diagnosis = D * mean over the findings of their credit: 1 when diagnosed within 'diagnose_within' of the start,
            then falling linearly to 0.5 at the time limit; 0 when never diagnosed
time      = T when every goal was met by 'par' (default half the time limit), falling linearly to 0 at the time
            limit; 0 when not every goal was met
```
G, D, T, r, u, w are the exercise's ``scoring`` (defaults 60, 30, 10, 2, 15, 5). An exercise with nothing to find
gives D to the goals. Points are rounded to one decimal.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.classroom.schema import Scoring


@dataclass(frozen=True)
class ScoreInputs:
    """What the score is computed from (times in seconds since the exercise began)."""

    goal_points: tuple[tuple[float, float | None], ...]  # (points, met at or None)
    findings: tuple[float | None, ...]  # per finding: diagnosed at or None
    refused: int
    unsafe: int
    wrong: int
    time_limit: float


def _share(t: float, full_until: float, limit: float, floor: float) -> float:
    """1 until ``full_until``, then linearly down to ``floor`` at ``limit``."""
    if t <= full_until or limit <= full_until:
        return 1.0 if t <= limit else floor
    return max(floor, 1.0 - (1.0 - floor) * (t - full_until) / (limit - full_until))


def _goals_max(rules: Scoring, given: ScoreInputs) -> float:
    return rules.goals + (0.0 if given.findings else rules.diagnosis)


def goal_worth(rules: Scoring, given: ScoreInputs) -> list[float]:
    """What each goal is worth in the score's ``goals`` part: its share of G by its ``points`` (a weight among the
    goals, not points of the score), rounded as the parts are."""
    total_points = sum(p for p, _ in given.goal_points)
    return [round(_goals_max(rules, given) * p / total_points, 1) if total_points else 0.0
            for p, _ in given.goal_points]


def score(rules: Scoring, given: ScoreInputs) -> dict[str, float]:
    """The score's parts and total: ``goals``, ``diagnosis``, ``time`` (earned), ``refused``, ``unsafe``,
    ``wrong_diagnosis`` (lost, as negative numbers), ``total`` and ``max``."""
    goals_max = _goals_max(rules, given)
    diagnosis_max = rules.diagnosis if given.findings else 0.0
    total_points = sum(p for p, _ in given.goal_points)
    met_points = sum(p for p, at in given.goal_points if at is not None)
    goals = goals_max * met_points / total_points if total_points else 0.0
    credits = [0.0 if at is None else _share(at, rules.diagnose_within, given.time_limit, 0.5)
               for at in given.findings]
    diagnosis = diagnosis_max * sum(credits) / len(credits) if credits else 0.0
    all_met = [at for _, at in given.goal_points]
    time = 0.0
    if all_met and all(at is not None for at in all_met):
        done = max(at for at in all_met if at is not None)
        par = rules.par if rules.par is not None else given.time_limit / 2
        time = rules.time * _share(done, par, given.time_limit, 0.0)
    lost = {"refused": -rules.refused * given.refused, "unsafe": -rules.unsafe * given.unsafe,
            "wrong_diagnosis": -rules.wrong_diagnosis * given.wrong}
    earned = {"goals": goals, "diagnosis": diagnosis, "time": time}
    total = max(0.0, sum(earned.values()) + sum(lost.values()))
    parts = {k: round(v, 1) for k, v in {**earned, **lost}.items()}
    return {**parts, "total": round(total, 1), "max": round(goals_max + diagnosis_max + rules.time, 1)}
