"""One EMLA over a duty period: hot windings and the hold, against hand calculations and finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiab_sim.emla import load_emla_set
from hiab_sim.emla.duty_energy import DutyOptions, drive_duty
from hiab_sim.emla.hold import rest_hold, static_hold_torque
from hiab_sim.emla.thermal import Duty
from hiab_sim.errors import InvalidInputError

EMLAS = load_emla_set()
PAPER = load_emla_set("paper")
LIFT = EMLAS["lift"]


def _samples(K: int = 17) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 6.25, K)
    f = 30e3 + 8e3 * np.sin(2 * np.pi * t / 6.25)
    v = 0.06 * np.sin(2 * np.pi * t / 6.25) + 0.01
    a = 0.06 * 2 * np.pi / 6.25 * np.cos(2 * np.pi * t / 6.25)
    return t, f, v, a


def test_static_hold_torque_is_force_over_transmission_ratio() -> None:
    """At standstill the motor holds f_x rho / (2 pi G): 30 kN on the lift is 11.94 N m."""
    assert static_hold_torque(LIFT, 30e3) == pytest.approx(30e3 * 0.010 / (2 * math.pi * 4.0), rel=1e-14)


def test_motor_hold_adds_its_copper_inverter_and_coil_energy_over_the_rest() -> None:
    """hold: motor, cold: E_rest = (3/2 R i^2 + c0 + c1 |i| + c2 i^2 + P_coil) T_rest with i = tau_h / K_t."""
    t, f, v, a = _samples()
    duty = Duty(6.25, 53.75)
    d = drive_duty(LIFT, t, f, v, a, DutyOptions(duty, "motor", hot=False))
    i = f[-1] / LIFT.transmission_ratio / LIFT.motor.torque_constant
    loss = LIFT.losses
    p = 1.5 * 0.268 * i**2 + loss.inverter_constant_loss + loss.inverter_current_loss * abs(i)
    p += loss.inverter_resistance * i**2 + 21.6
    assert d.rest_energy == pytest.approx(p * 53.75, rel=1e-12)


def test_motor_hold_enters_the_rms_torque_over_the_period() -> None:
    """tau_rms^2 = (cycle integral + tau_h^2 T_rest) / P, against a hand trapezoid."""
    t, f, v, a = _samples(2001)
    duty = Duty(6.25, 53.75)
    brake = drive_duty(LIFT, t, f, v, a, DutyOptions(duty, "brake"))
    motor = drive_duty(LIFT, t, f, v, a, DutyOptions(duty, "motor"))
    tau_h = f[-1] / LIFT.transmission_ratio
    assert motor.rms_torque**2 == pytest.approx(brake.rms_torque**2 + tau_h**2 * 53.75 / 60.0, rel=1e-12)


def test_brake_hold_counts_release_and_engagement_and_checks_the_holding_torque() -> None:
    """hold: brake: standby c0 over the rest plus the 180 ms release and 35 ms engagement at the poses' currents."""
    t, f, v, a = _samples()
    duty = Duty(6.25, 53.75)
    d = drive_duty(LIFT, t, f, v, a, DutyOptions(duty, "brake", hot=False))
    loss = LIFT.losses

    def p_hold(force: float) -> float:
        i = force / LIFT.transmission_ratio / LIFT.motor.torque_constant
        return 1.5 * 0.268 * i**2 + loss.inverter_constant_loss + loss.inverter_current_loss * abs(i) + 0.075 * i**2

    expected = 20.0 * 53.75 + (p_hold(f[0]) + 21.6 - 20.0) * 0.180 + (p_hold(f[-1]) - 20.0) * 0.035
    assert d.rest_energy == pytest.approx(expected, rel=1e-12)
    assert d.hold is not None and d.hold.brake_margin == pytest.approx(1 - f[0] / LIFT.transmission_ratio / 28.0)
    weak = rest_hold(PAPER["lift"], "motor", 1e5, 1e5, 6.25)
    assert weak.brake_margin is None


def test_paper_model_brake_hold_adds_the_coil_over_the_cycle() -> None:
    """Without a sample-by-sample brake model the released coil's P_coil T is added to the cycle's power."""
    from dataclasses import replace

    t, f, v, a = _samples()
    lift = replace(PAPER["lift"], brake=LIFT.brake)
    d = drive_duty(lift, t, f, v, a, DutyOptions(Duty(6.25, 53.75), "brake"))
    assert d.power - d.reference_power == pytest.approx(np.full(t.size, 21.6), rel=1e-14)


def test_default_brake_coil_is_counted_once_over_the_cycle() -> None:
    """Default file: the brake closes only at rest; the coil's 21.6 W is in every cycle sample once, not twice."""
    from dataclasses import replace

    from hiab_sim.emla.model import electrical_power

    t, f, v, a = _samples()
    assert not LIFT.losses.brake_on
    no_coil = replace(LIFT, losses=replace(LIFT.losses, brake_coil_power=0.0))
    coil = electrical_power(LIFT, f, v, a) - electrical_power(no_coil, f, v, a)
    assert coil == pytest.approx(np.full(t.size, 21.6), rel=1e-12)
    d = drive_duty(LIFT, t, f, v, a, DutyOptions(Duty(6.25, 53.75), "brake", hot=False))
    assert d.hold is not None and d.hold.cycle_coil_energy == 0.0
    assert d.power == pytest.approx(d.reference_power, rel=1e-14)


def test_brake_hold_needs_brake_data() -> None:
    """hold: brake on an EMLA without a holding_brake section is one line naming the field."""
    t, f, v, a = _samples()
    with pytest.raises(InvalidInputError, match=r"lift\.holding_brake"):
        drive_duty(PAPER["lift"], t, f, v, a, DutyOptions(Duty(6.25, 53.75), "brake"))
    with pytest.raises(InvalidInputError, match=r"duty\.hold"):
        DutyOptions(Duty(6.25, 1.0), "clamp")


def test_hot_windings_raise_the_copper_loss_by_the_resistance_factor() -> None:
    """P_hot - P_ref = (g - 1) c with g = 1 + alpha (T - 20 C) at the coupled temperatures; T above ambient."""
    t, f, v, a = _samples()
    d = drive_duty(LIFT, t, f, v, a, DutyOptions(Duty(6.25, 53.75), "motor", hot=True))
    assert d.winding is not None
    g = 1.0 + 0.00393 * (d.winding.temperature - 20.0)
    assert d.power - d.reference_power == pytest.approx((g - 1.0) * d.copper_loss_ref, rel=1e-12)
    assert d.peak_temperature > 40.0 and not d.runaway


@pytest.mark.parametrize("hold", [None, "brake", "motor"])
@pytest.mark.parametrize("hot", [False, True])
def test_duty_partials_match_finite_differences(hold: str | None, hot: bool) -> None:
    """Energy, RMS-torque and peak-temperature partials w.r.t. every (f, v, a) sample agree with central differences."""
    t, f, v, a = _samples(9)
    f = 0.5 * f
    opts = DutyOptions(Duty(6.25, 20.0), hold, hot)
    rng = np.random.default_rng(5)
    y = rng.uniform(0.1, 1.0, t.size)
    z = 0.9
    base = drive_duty(LIFT, t, f, v, a, opts)
    de = base.energy_partials(y, z)
    dr = base.rms_partials()
    dt_ = base.peak_partials()
    j = base.winding.peak_index if base.winding is not None else 0

    def values(x: list[np.ndarray]) -> np.ndarray:
        d = drive_duty(LIFT, t, x[0], x[1], x[2], opts)
        temp = d.winding.temperature[j] if d.winding is not None else 0.0
        return np.array([float(y @ d.power) + z * d.rest_energy, d.rms_torque, temp])

    steps = (1.0, 1e-6, 1e-5)
    for q, step in enumerate(steps):
        for k in range(t.size):
            up = [f.copy(), v.copy(), a.copy()]
            down = [f.copy(), v.copy(), a.copy()]
            up[q][k] += step
            down[q][k] -= step
            fd = (values(up) - values(down)) / (2 * step)
            assert de[q][k] == pytest.approx(fd[0], rel=1e-6, abs=1e-9)
            assert dr[q, k] == pytest.approx(fd[1], rel=1e-6, abs=1e-11)
            assert dt_[q, k] == pytest.approx(fd[2], rel=1e-5, abs=1e-11)


def test_rms_and_peak_partials_are_computed_once_and_cannot_be_changed_by_a_caller() -> None:
    """The second call returns the first call's (read-only) arrays; a fresh duty of the same samples gives the same."""
    t, f, v, a = _samples(9)
    opts = DutyOptions(Duty(6.25, 20.0), "motor", hot=True)
    d = drive_duty(LIFT, t, 0.5 * f, v, a, opts)
    first = d.peak_partials(), d.rms_partials()
    assert d.peak_partials() is first[0] and d.rms_partials() is first[1]
    for array in first:
        with pytest.raises(ValueError, match="read-only"):
            array[0, 0] = 1.0
    again = drive_duty(LIFT, t, 0.5 * f, v, a, opts)
    np.testing.assert_array_equal(again.peak_partials(), first[0])
    np.testing.assert_array_equal(again.rms_partials(), first[1])
    assert np.any(first[0] != 0.0) and np.any(first[1] != 0.0)
