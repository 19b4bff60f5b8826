"""Speed and distance measurement (Liu Bin et al., docs/references.md): the tacho formula, slip and slide detection,
compensation, corrections."""

from __future__ import annotations

import math

import pytest

from liansuo.simulation.trains.odometry import G, Odometer
from liansuo.simulation.trains.research.sliprun import simulate_run


def run_wheel(o: Odometer, seconds: float, speed: float, accel: float = 0.0, dt: float = 0.1,
              accelerometer: float | None = None, gradient_permille: float = 0.0) -> float:
    """Drive ``o`` for ``seconds`` with the wheel at ``speed`` changing by ``accel``; returns the wheel's speed."""
    v = speed
    for _ in range(round(seconds / dt)):
        v_new = max(v + accel * dt, 0.0)
        o.update(dt, (v + v_new) / 2, accelerometer, gradient_permille)
        v = v_new
    return v


def test_speed_follows_the_tacho_formula() -> None:
    o = Odometer(wheel_diameter_m=1.05, pulses_per_rev=200)
    for _ in range(10):
        o.pulses(100, 0.1)
    assert o.speed_ms == pytest.approx(math.pi * 1.05 * 100 / (200 * 0.1))  # v = pi d n / (N t)
    assert o.position_m == pytest.approx(1000 * math.pi * 1.05 / 200)
    assert not o.slipping and not o.sliding


def test_clean_run_error_stays_small() -> None:
    run = simulate_run(slip=None, slide=None)
    fig = run.figures()
    assert fig["max_error_m"] < 0.05 and abs(fig["stop_error_m"]) < 0.05
    assert fig["slip_s"] == 0 and fig["slide_s"] == 0
    assert run.true_m[-1] == pytest.approx(600.0)


@pytest.mark.parametrize(("wheel_accel", "slips"), [(0.4, False), (1.0, True), (3.0, True)])
def test_slip_is_detected_by_the_acceleration_threshold(wheel_accel: float, slips: bool) -> None:
    o = Odometer(a_max=0.6)
    run_wheel(o, 1.0, run_wheel(o, 3.0, 2.0), accel=wheel_accel)
    assert o.slipping is slips
    assert not o.sliding


@pytest.mark.parametrize(("wheel_accel", "slides"), [(-0.8, False), (-2.0, True), (-6.0, True)])
def test_slide_is_detected_by_the_deceleration_threshold(wheel_accel: float, slides: bool) -> None:
    o = Odometer(a_min=-1.2)
    run_wheel(o, 1.0, run_wheel(o, 3.0, 4.0), accel=wheel_accel)
    assert o.sliding is slides
    assert not o.slipping


def test_compensation_keeps_the_slip_error_well_below_the_plain_odometer() -> None:
    fig = simulate_run().figures()
    assert fig["slip_max_error_naive_m"] > 4.0  # the spinning wheel counts metres the locomotive never ran
    assert fig["slip_max_error_m"] < 0.1 * fig["slip_max_error_naive_m"]
    assert 3.0 < fig["slip_s"] < 6.0  # the episode ends soon after the wheel grips again


def test_a_balise_resets_the_error() -> None:
    run = simulate_run()
    fig = run.figures()
    assert run.corrections[0].kind == "balise"
    assert fig["first_correction_naive_m"] < -4.0  # the plain odometer was metres ahead ...
    i = next(i for i, t in enumerate(run.t) if t >= run.corrections[0].t)
    assert abs(run.naive_error_m[i]) < 0.05  # ... and is right again after the balise
    assert abs(fig["after_correction_error_m"]) < 0.05


def test_slide_in_the_last_section_is_the_dangerous_error_and_compensation_bounds_it() -> None:
    run = simulate_run()
    fig = run.figures()
    last = [c for c in run.corrections if c.kind == "section"][-1]  # the front enters the last section
    i = run.t.index(last.t)
    assert run.true_m[i - 1] < run.last_section_m <= run.true_m[i] and abs(run.error_m[i]) < 0.05
    assert fig["slide_s"] > 4.0
    assert fig["stop_error_naive_m"] < -5.0  # believes it is short of the stop: it would overrun
    assert abs(fig["stop_error_m"]) < 0.1 * abs(fig["stop_error_naive_m"])


def test_without_an_accelerometer_the_held_acceleration_still_compensates() -> None:
    fig = simulate_run(accelerometer=False).figures()
    assert fig["slip_max_error_m"] < 1.0 and abs(fig["stop_error_m"]) < 1.5


def test_the_accelerometer_is_corrected_for_the_gradient() -> None:
    def speed_after_slip(gradient_given: float) -> float:
        o = Odometer()
        rise = G * 0.010  # what the accelerometer feels at a steady speed up a 10 per mille rise
        v = run_wheel(o, 3.0, 3.0, accelerometer=rise, gradient_permille=gradient_given)
        v = run_wheel(o, 0.5, v, accel=4.0, accelerometer=rise, gradient_permille=gradient_given)  # the wheel spins
        run_wheel(o, 2.5, v, accelerometer=rise, gradient_permille=gradient_given)
        assert o.slipping
        return o.speed_ms

    assert speed_after_slip(10.0) == pytest.approx(3.0, abs=0.1)
    assert speed_after_slip(0.0) > 3.2  # the gradient read as acceleration


def test_correct_and_section_transition_set_the_position() -> None:
    o = Odometer()
    run_wheel(o, 5.0, 2.0)
    assert o.error_m(10.0) == pytest.approx(0.0, abs=0.05)
    assert o.correct(12.0) == pytest.approx(2.0, abs=0.05)
    assert o.position_m == 12.0 and o.error_m(12.0) == 0.0
    o.section_transition(20.0, since_s=0.5)  # the joint was passed half a second ago
    assert o.position_m == pytest.approx(21.0, abs=0.05)
    assert [c.kind for c in o.corrections] == ["balise", "section"]


def test_bad_inputs_are_refused() -> None:
    with pytest.raises(ValueError):
        Odometer(a_min=0.5)
    with pytest.raises(ValueError):
        Odometer().pulses(-1, 0.1)
