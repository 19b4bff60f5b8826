"""Every number of a station file within its range (stations/limits.py), refused by ``liansuo check`` at its
``FILE:LINE:COLUMN``; and whatever ``check`` accepts, the other commands accept too, in time that grows with the
station's size (issue 17, item 2; docs/robustness.md)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from conftest import edit, position

from liansuo.circuits.zpw.adjust import section_circuit
from liansuo.cli.main import main
from liansuo.interlocking.autoblock import AutoBlock
from liansuo.kit.exitcodes import Exit
from liansuo.kit.source import read_yaml
from liansuo.proving.verify import station as verify_station_items
from liansuo.proving.verify import verify_station
from liansuo.proving.verify.units import Bench
from liansuo.rules import load_rules
from liansuo.simulation.sim import Simulation
from liansuo.stations import limits
from liansuo.stations.checks import cross_check
from liansuo.stations.loader import load, load_text
from liansuo.stations.schema import StationFile

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
JIAOPEI = (PKG / "stations" / "library" / "jiaopei.yaml").read_text(encoding="utf-8")
SHUANGXIAN = (PKG / "examples" / "stations" / "shuangxian.yaml").read_text(encoding="utf-8")
MINIMAL = (PKG / "examples" / "stations" / "minimal.yaml").read_text(encoding="utf-8")
SB = "  - {id: SB, kind: boundary, at: 1500}"
IG_TRACK = "  - {id: t-IG, from: J-1I, to: J-XI, section: IG, row: 0}"
IG_SECTION = "  - {id: IG, type: zpw2000a, role: station_track, carrier: 1700-1, capacitors: {rule: standard}}"
X_SIGNAL = "  - {id: X, kind: home, at: J-X, direction: down, lamps: [U, L, H, U2, B], buttons: [train]}"


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def write(tmp_path: Path, text: str, name: str = "station.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("at", "said"), [
    ("1000000", "the station spans 1000000 m"),  # 1,000 km: OverflowError in the 25 Hz model before
    ("2147483648", "a position must be from -10000000 to 10000000 m"),  # 2^31 m: MemoryError before
    ("1.0e+308", "a position must be from -10000000 to 10000000 m"),
])
def test_a_boundary_far_away_is_refused_by_check_and_every_command(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], at: str, said: str) -> None:
    text = edit(JIAOPEI, (SB, SB.replace("1500", at)))
    path = write(tmp_path, text)
    line, col = position(text, "at: ^" + at)
    for command in ("check", "table", "verify"):
        code, _, err = cli(capsys, command, str(path))
        assert code == Exit.BAD_INPUT, (command, err)
        assert f"{path}:{line}:{col}: error: " in err and said in err, (command, err)
        assert "Traceback" not in err


def test_a_release_delay_of_three_years_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``release_s: 100000000`` made verify wait 10^8 s of simulated time for one route."""
    text = edit(JIAOPEI, (X_SIGNAL, X_SIGNAL.replace("}", ", release_s: 100000000}")))
    code, _, err = cli(capsys, "check", str(write(tmp_path, text)))
    line, col = position(text, "release_s: ^100000000")
    assert code == Exit.BAD_INPUT
    assert f":{line}:{col}: error: signals.0.release_s: a release delay must be above 0 and up to 600 s" in err
    load_text(edit(JIAOPEI, (X_SIGNAL, X_SIGNAL.replace("}", ", release_s: 600}"))))  # the limit itself is fine


HUGE = "1" + "0" * 400  # a whole number no float holds: OverflowError in the loader before (issue 45, item 6)
MINIMAL_SB = "{id: SB, kind: boundary, at: 1200}"
MINIMAL_TRACK = "{id: t-IG, from: J-1I, to: J-XI, section: IG}"


@pytest.mark.parametrize(("old", "new", "needle", "said"), [
    (MINIMAL_SB, f"{{id: SB, kind: boundary, at: {HUGE}}}", f"at: ^{HUGE}",
     "ends.1.at: a position must be from -10000000 to 10000000 m"),
    (MINIMAL_SB, f"{{id: SB, kind: boundary, at: -{HUGE}}}", f"at: ^-{HUGE}",
     "ends.1.at: a position must be from -10000000 to 10000000 m"),
    (MINIMAL_SB, f"{{id: SB, kind: boundary, at: K{HUGE}+100}}", f"at: ^K{HUGE}",
     "ends.1.at: a position must be from -10000000 to 10000000 m"),
    (MINIMAL_SB, f"{{id: SB, kind: boundary, at: K1+{HUGE}.5}}", f"at: ^K1+{HUGE}",
     "ends.1.at: a position must be from -10000000 to 10000000 m"),
    (MINIMAL_SB, "{id: SB, kind: boundary, at: K10001+0}", "at: ^K10001+0",
     "ends.1.at: a position must be from -10000000 to 10000000 m"),
    (MINIMAL_TRACK, f"{{id: t-IG, from: J-1I, to: J-XI, section: IG, length: {HUGE}}}", f"length: ^{HUGE}",
     "tracks.4.length: a track's length must be above 0 and up to 200000 m"),
    ("line_speed_kmh: 80", f"line_speed_kmh: {HUGE}", f"line_speed_kmh: ^{HUGE}",
     "line_speed_kmh: a number this large is out of every range (beyond 1e308)"),
], ids=["position", "negative", "km-post", "km-post-metres", "km-post-past-range", "track-length", "speed"])
def test_check_refuses_a_number_too_large_for_a_float_without_a_traceback(
        tmp_path: Path, old: str, new: str, needle: str, said: str) -> None:
    """``liansuo check`` in a process of its own, as a user runs it, on a copy of the minimal example station."""
    text = edit(MINIMAL, (old, new))
    path = write(tmp_path, text)
    proc = subprocess.run([sys.executable, "-m", "liansuo", "check", str(path)], capture_output=True, text=True,
                          check=False, timeout=120)
    line, col = position(text, needle)
    first = proc.stderr.splitlines()[0]
    assert proc.returncode == Exit.BAD_INPUT, proc.stderr
    assert first.startswith(f"{path}:{line}:{col}: error: {said}"), proc.stderr
    assert "    hint: " in proc.stderr and "Traceback" not in proc.stderr


@pytest.mark.parametrize(("old", "new", "said"), [
    ("at: 1500}", "at: 1500, draw: {x: 1.0e+9, y: 0}}", "a diagram coordinate must be from -10000 to 10000"),
    ("{id: J-QX, at: 310}", "{id: J-QX, at: 310, dead_zone_m: 1.0e+9}", "a dead zone must be from 0 to 30 m"),
    ("row: 0}", "row: 0, length: 1.0e+9}", "a track's length must be above 0 and up to 200000 m"),
])
def test_numbers_past_their_physical_limits_are_refused(old: str, new: str, said: str) -> None:
    text = JIAOPEI.replace(old, new, 1)
    assert text != JIAOPEI
    with pytest.raises(Exception) as exc:  # StationError, with the diagnostics
        load_text(text, "j.yaml")
    assert said in str(exc.value)


def test_a_shortened_zpw_section_with_standard_capacitors_runs_everywhere(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A track ``length`` shorter than the section's span: the capacitors were placed on the span and checked
    against the length (ValueError in check, verify, test, tui and run)."""
    text = edit(SHUANGXIAN, (IG_TRACK, IG_TRACK.replace("}", ", length: 200}")))
    path = write(tmp_path, text)
    code, _, err = cli(capsys, "check", str(path))
    assert code == Exit.OK, err
    station = load(path)
    circuit = section_circuit(station, "IG")  # what check's ZPW-2000A warnings and 'liansuo zpw' solve
    assert circuit.length_m == 200 and all(0 <= x <= 200 for x in circuit.capacitors_m)
    sim = Simulation(station)  # what verify, test, run and the console build
    assert sim.command("route X XI").ok
    sim.run(10)
    assert sim.aspect("X") not in ("", None)


def test_capacitor_positions_outside_their_section_are_refused(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    text = edit(SHUANGXIAN, (IG_SECTION, IG_SECTION.replace("{rule: standard}", "{positions: [50, 700, 150]}")))
    code, _, err = cli(capsys, "check", str(write(tmp_path, text)))
    line, col = position(text, "positions: [50, ^700")
    assert code == Exit.BAD_INPUT
    assert f":{line}:{col}: error: section 'IG': capacitor 2 at 700 m lies beyond the section, which runs " in err


def test_a_zpw_section_longer_than_its_model_is_refused() -> None:
    text = edit(SHUANGXIAN, (IG_TRACK, IG_TRACK.replace("}", ", length: 50000}")))
    with pytest.raises(Exception, match="ZPW-2000A section 'IG' is 50000 m long; a ZPW-2000A section's length is "
                                        "at most 10000 m"):
        load_text(text)


def test_check_refuses_overrides_naming_unknown_routes_as_table_does(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = MINIMAL + "overrides:\n  forbid: [X-NOPE]\n"
    path = write(tmp_path, text)
    answers = [cli(capsys, command, str(path)) for command in ("check", "table")]
    assert [code for code, _, _ in answers] == [Exit.BAD_INPUT, Exit.BAD_INPUT]
    line, col = position(text, "forbid: [^X-NOPE]")
    said = f"{path}:{line}:{col}: error: override forbids route 'X-NOPE', which the topology does not give"
    assert said in answers[0][2] and answers[0][2] == answers[1][2]


# ---- time in proportion to the station's size --------------------------------------------------------------------
def chain(n: int, step: float = 50.0) -> str:
    """A line of ``n`` 25 Hz sections between two boundaries, a block signal at every joint."""
    lines = ["id: chain", "name: {zh: 链, en: chain}", "ends:", "  - {id: XB, kind: boundary, at: 0}",
             f"  - {{id: SB, kind: boundary, at: {n * step}}}", "joints:"]
    lines += [f"  - {{id: J{i}, at: {i * step}}}" for i in range(1, n)]
    nodes = ["XB", *(f"J{i}" for i in range(1, n)), "SB"]
    lines += ["tracks:", *(f"  - {{id: t{i}, from: {nodes[i]}, to: {nodes[i + 1]}, section: S{i}}}" for i in range(n))]
    lines += ["sections:", *(f"  - {{id: S{i}, type: 25hz}}" for i in range(n))]
    lines += ["signals:", *(f"  - {{id: X{i}, kind: block, at: J{i}, direction: down, lamps: [L, U, H]}}"
                            for i in range(1, n))]
    return "\n".join(lines) + "\n"


class _Counted(list):  # type: ignore[type-arg]
    """A list that counts how often it is walked through."""

    walks = 0

    def __iter__(self):  # type: ignore[no-untyped-def]
        type(self).walks += 1
        return super().__iter__()


def _walks_over_tracks(n: int) -> int:
    src = read_yaml(chain(n), "chain.yaml")
    model = StationFile.model_validate(src.data, strict=False)
    _Counted.walks = 0
    object.__setattr__(model, "tracks", _Counted(model.tracks))
    assert cross_check(model, src) == []
    return _Counted.walks


def test_the_cross_checks_walk_the_tracks_as_often_for_any_size() -> None:
    """The section check listed each section's tracks by walking every track: 4,000 sections took 57 s."""
    assert _walks_over_tracks(40) == _walks_over_tracks(400)


def test_block_signals_are_evaluated_ahead_first() -> None:
    """One sweep settles a line of block signals: in file order a change at its far end took one sweep a signal."""
    ab = AutoBlock(load_text(chain(300)))
    order = {sig: i for i, (sig, _, _) in enumerate(ab.signals)}
    assert all(order[nxt] < order[sig] for sig, _, nxt in ab.signals if nxt in order)


def test_red_lamp_transfer_on_a_long_line_needs_few_simulations(monkeypatch: pytest.MonkeyPatch) -> None:
    """verify built one simulation per block signal, each as large as the line: a line of 4,000 never ended."""
    station = load_text(chain(200))
    built: list[object] = []
    probe = verify_station_items.Probe
    monkeypatch.setattr(verify_station_items, "Probe", lambda ctx: built.append(ctx) or probe(ctx))
    ctx = Bench.build(station, load_rules()).context()
    verify_station_items.red_lamp_transfer(ctx)
    assert not ctx.failures
    assert ctx.checks == 198  # every block signal but the first has one in rear, each checked
    assert len(built) <= 3


def test_a_failing_group_is_tried_again_signal_by_signal(monkeypatch: pytest.MonkeyPatch) -> None:
    """A failure found in a group comes with the script of its own signal only."""
    station = load_text(chain(12))
    ctx = Bench.build(station, load_rules()).context()
    real = verify_station_items.Probe

    class Blind(real):  # type: ignore[misc, valid-type]
        def aspect(self, signal: str) -> str:  # the block signal X4 never shows H: a defect to find
            return "L" if signal == "X4" else super().aspect(signal)

    monkeypatch.setattr(verify_station_items, "Probe", Blind)
    verify_station_items.red_lamp_transfer(ctx)
    assert [f.subject for f in ctx.failures] == ["signal X5"]
    steps = ctx.failures[0].steps
    assert "fault filament X5 lamp=H which=both" in steps
    assert not any(s.startswith("fault filament") and "X5" not in s for s in steps)


def test_verify_passes_on_a_long_line() -> None:
    report = verify_station(load_text(chain(120)))
    assert report.ok, [f.detail for f in report.failures]


def test_every_limit_says_why() -> None:
    found = [v for v in vars(limits).values() if isinstance(v, limits.Limit)]
    assert len(found) > 20
    assert all(x.why and x.low < x.high for x in found)


def test_the_docs_list_every_limit() -> None:
    text = (ROOT / "docs" / "robustness.md").read_text(encoding="utf-8")
    for x in vars(limits).values():
        if isinstance(x, limits.Limit):
            assert f"| {x.what} | {x.range_text()} |" in text, x.what


def test_a_station_past_its_size_limit_is_refused_at_its_list(tmp_path: Path) -> None:
    """Issue 45, item 7: 10,000 signals passed check and then took gigabytes in table and verify. Each list of a
    station file has a size limit (stations/limits.py); past it, check refuses the file where the list starts."""
    from liansuo.stations.limits import STATION_ITEMS

    most = STATION_ITEMS["signals"]
    joints = "".join(f"  - {{id: J{i}, at: {i}}}\n" for i in range(1, most + 2))
    tracks = "".join(f"  - {{id: t{i}, from: J{i}, to: J{i + 1}, section: S}}\n" for i in range(1, most + 1))
    signals = "".join(f"  - {{id: D{i}, kind: shunting, at: J{i}, direction: down, lamps: [A, B], buttons: [shunt]}}\n"
                      for i in range(1, most + 2))
    text = ("id: big\nname: {zh: 大站, en: Big}\nends:\n  - {id: XB, kind: boundary, at: 0}\n"
            f"joints:\n{joints}tracks:\n  - {{id: t0, from: XB, to: J1, section: S}}\n{tracks}"
            f"sections:\n  - {{id: S, type: 25hz}}\nsignals:\n{signals}")
    path = write(tmp_path, text)
    proc = subprocess.run([sys.executable, "-m", "liansuo", "check", str(path)], capture_output=True, text=True,
                          check=False, timeout=300)
    line = text[:text.index("signals:\n")].count("\n") + 2  # the list's first item
    assert proc.returncode == Exit.BAD_INPUT, proc.stderr
    assert proc.stderr.startswith(f"{path}:{line}:3: error: signals: a station has at most {most:,} signals, not "
                                  f"{most + 1:,}: larger than any real station"), proc.stderr
    assert "Traceback" not in proc.stderr
