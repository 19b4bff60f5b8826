"""An assessment's report (:meth:`~liansuo.classroom.assessment.Assessment.report`) written for people and programs:
JSON, plain text and a standalone HTML page (the Jinja2 template ``report.html.j2``, every value escaped).
``write_report`` writes the three as ``STEM.json``, ``STEM.txt`` and ``STEM.html``."""

from __future__ import annotations

import json
from functools import cache
from pathlib import Path
from typing import Any

from jinja2 import Environment, PackageLoader, Template, select_autoescape


def _t(seconds: float | None) -> str:
    if seconds is None:
        return "-"
    m, s = divmod(float(seconds), 60.0)
    return f"{int(m)}:{s:04.1f}"


def _who(report: dict[str, Any]) -> str:
    seat = f" (seat {report['seat']})" if report.get("seat") else ""
    return f"{report.get('trainee') or 'trainee'}{seat}"


def _faults(report: dict[str, Any]) -> list[str]:
    f = report["faults"]
    return [*f["setup"], *f["fixed"], *f["drawn"]]


def _earned(goal: dict[str, Any]) -> str:
    """A goal's points of the score: earned of its worth (a report written before 'worth' was: its weight)."""
    worth = goal.get("worth")
    if worth is None:
        return f"weight {goal['points']:g}"
    return f"{worth if goal['met_at'] is not None else 0:g} / {worth:g}"


def _score_rows(report: dict[str, Any]) -> list[tuple[str, str]]:
    sc = report["score"]
    return [("goals", f"{sc['goals']:g}"), ("diagnosis", f"{sc['diagnosis']:g}"), ("time", f"{sc['time']:g}"),
            (f"refused commands ({report['refused']})", f"{sc['refused']:g}"),
            (f"unsafe actions ({len(report['unsafe'])})", f"{sc['unsafe']:g}"),
            (f"wrong diagnoses ({sum(not d['correct'] for d in report['diagnoses'])})",
             f"{sc['wrong_diagnosis']:g}"),
            ("total", f"{sc['total']:g} / {sc['max']:g}")]


def text_report(report: dict[str, Any]) -> str:
    """The report as plain text (100 columns)."""
    ex = report["exercise"]
    out = [f"Assessment: {ex['title']} ({ex['name']}) at {report['station']}",
           f"Trainee: {_who(report)}   difficulty {report['difficulty']}   seed {report['seed']}",
           f"Time: {_t(report['elapsed_s'])} of {_t(report['time_limit_s'])} ({report['ended']})",
           f"Faults: {', '.join(_faults(report)) or 'none'}", "", "Goals:"]
    for g in report["goals"]:
        mark = f"met at {_t(g['met_at'])}" if g["met_at"] is not None else "not met"
        out.append(f"  [{'x' if g['met_at'] is not None else ' '}] {g['description'] or '; '.join(g['expect'])}"
                   f" ({mark}; {_earned(g)} points)")
    out += ["", "Findings:"] + [
        f"  [{'x' if f['diagnosed_at'] is not None else ' '}] {f['finding']}: "
        f"{'diagnosed at ' + _t(f['diagnosed_at']) if f['diagnosed_at'] is not None else 'not diagnosed'}"
        for f in report["findings"]] + ([] if report["findings"] else ["  none"])
    wrong = [d for d in report["diagnoses"] if not d["correct"]]
    if wrong:
        out += ["", "Wrong diagnoses:"] + [f"  {_t(d['t'])} {d['diagnosis']}" for d in wrong]
    out += ["", "Unsafe actions:"] + [f"  {_t(u['t'])} {u['command']}: {u['rule']}: {u['why']}"
                                      for u in report["unsafe"]] + ([] if report["unsafe"] else ["  none"])
    sealed = ", ".join(f"{k} {n}" for k, n in sorted(report["sealed_uses"].items())) or "none"
    out += ["", f"Sealed buttons used (铅封计数): {sealed}", "", "Commands:"]
    out += [f"  {_t(c['t'])} {'  ' if c['ok'] else '! '}{c['command']} -> {c['answer']}" for c in report["commands"]]
    if report.get("commands_not_kept"):
        out.append(f"  ... and {report['commands_not_kept']} more commands, not kept")
    out += ["", "Score:"] + [f"  {name:<24} {value:>12}" for name, value in _score_rows(report)]
    return "\n".join(out) + "\n"


@cache
def _template() -> Template:
    env = Environment(loader=PackageLoader("liansuo.classroom", "."), autoescape=select_autoescape(["j2"]),
                      trim_blocks=True, keep_trailing_newline=True)
    return env.get_template("report.html.j2")


def html_report(report: dict[str, Any]) -> str:
    """The report as one HTML page (every text from the run escaped by the template)."""
    ex = report["exercise"]
    sections = [
        ("Score", ["part", "points"], [[a, b] for a, b in _score_rows(report)]),
        ("Goals", ["goal", "points of the score (earned / worth)", "met at"], [
            [g["description"] or "; ".join(g["expect"]), _earned(g), _t(g["met_at"])]
            for g in report["goals"]]),
        ("Findings", ["finding", "diagnosed at"], [[f["finding"], _t(f["diagnosed_at"])] for f in report["findings"]]),
        ("Diagnoses", ["time", "diagnosis", "correct"], [
            [_t(d["t"]), d["diagnosis"], "yes" if d["correct"] else "no"] for d in report["diagnoses"]]),
        ("Unsafe actions", ["time", "command", "rule", "why"], [
            [_t(u["t"]), u["command"], u["rule"], u["why"]] for u in report["unsafe"]]),
        ("Sealed buttons used (铅封计数)", ["button", "uses"], [
            [k, str(n)] for k, n in sorted(report["sealed_uses"].items())]),
        ("Commands", ["time", "command", "accepted", "answer"], [
            [_t(c["t"]), c["command"], "yes" if c["ok"] else "refused", c["answer"]] for c in report["commands"]]),
    ]
    return _template().render(
        title=ex["title"], who=_who(report), station=report["station"], difficulty=report["difficulty"],
        seed=report["seed"], elapsed=_t(report["elapsed_s"]), limit=_t(report["time_limit_s"]), ended=report["ended"],
        faults=", ".join(_faults(report)) or "none", sections=sections,
        not_kept=report.get("commands_not_kept", 0))


def write_report(report: dict[str, Any], directory: str | Path, stem: str) -> list[Path]:
    """Write ``STEM.json``, ``STEM.txt`` and ``STEM.html`` into ``directory`` (made if missing); their paths."""
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    texts = {".json": json.dumps(report, ensure_ascii=False, indent=2) + "\n", ".txt": text_report(report),
             ".html": html_report(report)}
    paths = []
    for suffix, text in texts.items():
        path = folder / f"{stem}{suffix}"
        path.write_text(text, encoding="utf-8")
        paths.append(path)
    return paths
