"""Thermal limits of an EMLA along a trajectory: values agree with the operating point, gradients with FD."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hiab_sim.emla import load_emla_set, operating_point
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.emla.thermal import Duty, periodic_winding_temperature, rms_torque
from hiab_sim.emla.thermal_check import thermal_check
from hiab_sim.errors import InvalidInputError

EMLAS = load_emla_set("paper")
T = np.linspace(0.0, 2.0, 41)
F = 4.0e4 * np.sin(2 * np.pi * T / 2.0) + 1.0e4
V = 0.1 * np.sin(2 * np.pi * T / 2.0) ** 2 - 0.02
A = np.gradient(V, T)


def test_values_are_the_operating_points_rms_torque_and_copper_loss_temperature() -> None:
    """tau_rms and T_peak equal those of the operating point's torque and copper loss (brake off)."""
    params = EMLAS.lift
    duty = Duty(2.0, 3.0)
    check = thermal_check(params, T, F, V, A, duty, exact=True)
    op = operating_point(params, F, V, A, exact=True)
    assert params.thermal is not None
    assert check.rms_torque == pytest.approx(rms_torque(T, op.motor_torque, duty)[0], rel=1e-14)
    peak = periodic_winding_temperature(T, op.copper_loss, params.thermal, duty).peak
    assert check.peak_temperature == pytest.approx(peak, rel=1e-14)
    assert check.torque_margin == pytest.approx(1.0 - check.rms_torque / 14.0, rel=1e-15)


@pytest.mark.parametrize("brake", [False, True])
def test_gradients_with_respect_to_the_load_samples_match_finite_differences(brake: bool) -> None:
    """Gradients of tau_rms and T_peak w.r.t. f_x, v_x, a_x samples agree with central differences (smooth model)."""
    assert EMLAS.tilt.thermal is not None
    thermal = dataclasses.replace(EMLAS.tilt.thermal, time_constant=3.0)
    losses = DriveLosses(transmission_efficiency_forward=0.87, transmission_efficiency_backdriven=0.862,
                         brake_speed=0.03 if brake else 0.0)  # fmt: skip
    params = dataclasses.replace(EMLAS.tilt, thermal=thermal, losses=losses)
    duty = Duty(2.0, 1.0)
    check = thermal_check(params, T, F, V, A, duty)
    steps = (1.0, 1e-6, 1e-5)
    for j, h in enumerate(steps):
        for k in (0, 7, 19, 33, 40):
            up = [F.copy(), V.copy(), A.copy()]
            dn = [F.copy(), V.copy(), A.copy()]
            up[j][k] += h
            dn[j][k] -= h
            hi = thermal_check(params, T, up[0], up[1], up[2], duty)
            lo = thermal_check(params, T, dn[0], dn[1], dn[2], duty)
            assert check.d_rms[j, k] == pytest.approx((hi.rms_torque - lo.rms_torque) / (2 * h), rel=1e-5, abs=1e-12)
            fd = (hi.peak_temperature - lo.peak_temperature) / (2 * h)
            assert check.d_peak[j, k] == pytest.approx(fd, rel=1e-5, abs=1e-12)


def test_an_emla_without_thermal_data_is_rejected() -> None:
    """The check needs the EMLA file's thermal section."""
    with pytest.raises(InvalidInputError, match=r"lift\.thermal"):
        thermal_check(dataclasses.replace(EMLAS.lift, thermal=None), T, F, V, A, Duty(2.0))
