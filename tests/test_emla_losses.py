"""Optional drive losses: off reproduces the paper's powers, on balances energy, exact and smooth forms agree."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.emla import (
    EmlaParams,
    electrical_power,
    electrical_power_partials,
    load_emla_set,
    operating_point,
    peak_force,
)
from hiab_sim.emla.config import emla_set_from_mapping
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import shipped

EMLAS = load_emla_set("paper")
ON = DriveLosses(
    transmission_efficiency_forward=0.87,
    transmission_efficiency_backdriven=0.862,
    inverter_constant_loss=20.0,
    inverter_current_loss=4.0,
    inverter_resistance=0.075,
    brake_speed=1.0e-3,
    brake_coil_power=15.0,
)


def _samples(seed: int, n: int = 200) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-6e4, 6e4, n), rng.uniform(-0.2, 0.2, n), rng.uniform(-0.5, 0.5, n)


def _paper_power(params: EmlaParams, f: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """P_elec = 3/2 R_s i_q^2 + tau_m omega_m of the EMLA reference sheet, written out independently."""
    m = params.motor
    k = 2.0 * np.pi * params.gear_ratio / params.screw_lead
    tau = (
        (f + params.screw_moving_mass * a + params.viscous_friction * v)
        * params.screw_lead
        / (2 * np.pi * params.gear_ratio)
        + m.rotor_inertia * k * a
        + m.rotor_coulomb_friction * np.tanh(k * v / m.friction_smoothing_speed)
    )
    i_q = tau / (1.5 * m.pole_pairs * m.flux_linkage)
    return 1.5 * m.stator_resistance * i_q**2 + tau * k * v


@pytest.mark.parametrize("exact", [False, True])
def test_every_option_off_reproduces_the_paper_powers(exact: bool) -> None:
    """Defaults (and the preset's ``enabled: false``) give the paper's P_elec to 1e-12 relative."""
    f, v, a = _samples(0)
    for params in EMLAS:
        assert params.losses == DriveLosses(label=params.losses.label)
        p = electrical_power(params, f, v, a, exact=exact)
        np.testing.assert_allclose(p, _paper_power(params, f, v, a), rtol=1e-12, atol=1e-12 * np.abs(p).max())
        op = operating_point(params, f, v, a, exact=exact)
        assert not np.any(op.transmission_loss) and not np.any(op.inverter_loss) and not np.any(op.brake_held_power)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31), exact=st.booleans(), name=st.sampled_from(["lift", "tilt", "telescope"]))
def test_electrical_power_is_mechanical_power_plus_every_loss_when_on(seed: int, exact: bool, name: str) -> None:
    """P_elec = f v + copper + friction + viscous + inertial + transmission + inverter + coil + brake-held."""
    params = dataclasses.replace(EMLAS[name], losses=ON)
    f, v, a = _samples(seed)
    v[:20] = np.linspace(-2e-3, 2e-3, 20)  # around the brake's hold band
    op = operating_point(params, f, v, a, exact=exact)
    parts = (
        op.mechanical_power + op.copper_loss + op.rotor_friction_loss + op.screw_viscous_loss + op.inertial_power
        + op.transmission_loss + op.inverter_loss + op.brake_coil_power + op.brake_held_power
    )  # fmt: skip
    scale = np.abs(op.mechanical_power).max()
    np.testing.assert_allclose(op.electrical_power, parts, rtol=0, atol=1e-12 * scale)
    assert np.all(op.transmission_loss >= 0.0) and np.all(op.inverter_loss >= 0.0)


def test_exact_transmission_loss_follows_the_forward_and_backdriving_efficiencies() -> None:
    """Without rotor friction or screw viscosity: loss = f v (1/eta_fwd - 1) forward, |f v| (1 - eta_back) back."""
    base = EMLAS.lift
    params = dataclasses.replace(
        base,
        motor=dataclasses.replace(base.motor, rotor_coulomb_friction=0.0),
        viscous_friction=0.0,
        losses=DriveLosses(transmission_efficiency_forward=0.8, transmission_efficiency_backdriven=0.7),
    )
    f = np.array([4e4, -4e4, 4e4, -4e4])
    v = np.array([0.1, -0.1, -0.1, 0.1])
    op = operating_point(params, f, v, 0.0, exact=True)
    expected = np.array([4e3 * 0.25, 4e3 * 0.25, 4e3 * 0.3, 4e3 * 0.3])
    np.testing.assert_allclose(op.transmission_loss, expected, rtol=1e-13)


def test_exact_power_at_standstill_does_not_depend_on_the_sign_of_round_off() -> None:
    """A rest's speed is zero to round-off (+-1e-16 m/s): the exact power there is the holding one at v = 0."""
    params = dataclasses.replace(EMLAS.lift, losses=dataclasses.replace(ON, brake_speed=0.0))
    f = np.full(3, 3e4)
    p = electrical_power(params, f, np.array([-4e-16, 0.0, 3e-16]), 0.0, exact=True)
    np.testing.assert_allclose(p, p[1], rtol=1e-12)  # the smooth rotor friction moves it by 1e-15
    # at v = 0 the motor holds f / k: its copper and inverter loss and the released coil, no transmission loss
    i = 3e4 / params.transmission_ratio / params.motor.torque_constant
    hold = 1.5 * params.motor.stator_resistance * i * i + 20.0 + 4.0 * i + 0.075 * i * i + 15.0
    assert p[1] == pytest.approx(hold, rel=1e-12)


def test_smooth_losses_converge_to_the_exact_ones_away_from_standstill() -> None:
    """Away from standstill |P_smooth - P_exact| <= c1 i_eps (+ tanh tails), and -> 0 with the smoothing widths."""
    f = np.array([3e4, -3e4, 2e4, -1e4])
    v = np.array([0.05, 0.08, -0.1, -0.02])
    gaps = []
    for shrink in (1.0, 1e-3):
        losses = dataclasses.replace(ON, current_smoothing=0.01 * shrink, force_smoothing=10.0 * shrink)
        params = dataclasses.replace(EMLAS.tilt, losses=losses)
        gap = np.abs(electrical_power(params, f, v, 0.3) - electrical_power(params, f, v, 0.3, exact=True))
        assert np.all(gap <= 4.0 * losses.current_smoothing * (1 + 1e-6) + 1e-9 * np.abs(f * v))
        gaps.append(gap.max())
    assert gaps[1] < 2e-3 * gaps[0]


def test_engaged_brake_leaves_only_the_inverter_standby_loss() -> None:
    """Below the brake speed (exact) and at standstill (smooth) no current flows: P_elec = c0."""
    params = dataclasses.replace(EMLAS.lift, losses=ON)
    op = operating_point(params, np.array([5e4, -3e4]), np.array([5e-4, -2e-4]), 0.0, exact=True)
    np.testing.assert_array_equal(op.electrical_power, [20.0, 20.0])
    assert op.brake_held_power == pytest.approx([-25.0, -6.0], rel=1e-14)
    smooth = electrical_power(params, np.array([5e4]), np.array([0.0]), 0.0)
    assert smooth == pytest.approx([20.0], rel=1e-15)


def test_inverter_loss_is_c0_plus_c1_i_plus_c2_i_squared() -> None:
    """The exact inverter loss at a known q-axis current, by hand."""
    params = dataclasses.replace(EMLAS.lift, losses=DriveLosses(inverter_constant_loss=20.0, inverter_current_loss=4.0,
                                                                inverter_resistance=0.075))  # fmt: skip
    op = operating_point(params, 3e4, 0.05, 0.0, exact=True)
    i = abs(float(op.i_q))
    assert float(op.inverter_loss) == pytest.approx(20.0 + 4.0 * i + 0.075 * i * i, rel=1e-14)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31), name=st.sampled_from(["lift", "tilt", "telescope"]))
def test_partials_with_every_loss_on_match_finite_differences(seed: int, name: str) -> None:
    """dP/df, dP/dv, dP/da of the smooth P_elec (transmission, inverter, brake on) agree with central differences."""
    params = dataclasses.replace(EMLAS[name], losses=ON)
    f, v, a = _samples(seed, 30)
    v[:6] = np.array([-1.5e-3, -8e-4, -1e-4, 3e-4, 9e-4, 2e-3])
    d = electrical_power_partials(params, f, v, a)
    for j, h in enumerate((1e-3, 1e-8, 1e-7)):
        args_up = [f.copy(), v.copy(), a.copy()]
        args_dn = [f.copy(), v.copy(), a.copy()]
        args_up[j] += h
        args_dn[j] -= h
        fd = (electrical_power(params, *args_up) - electrical_power(params, *args_dn)) / (2 * h)
        np.testing.assert_allclose(d[j], fd, rtol=2e-5, atol=1e-6 * np.abs(fd).max())


@pytest.mark.parametrize(
    ("field", "changes"),
    [
        ("drive_losses.transmission_efficiency_forward", {"transmission_efficiency_forward": 0.0}),
        ("drive_losses.transmission_efficiency_backdriven", {"transmission_efficiency_backdriven": 1.1}),
        ("drive_losses.inverter_resistance", {"inverter_resistance": -0.1}),
        ("drive_losses.brake_speed", {"brake_speed": -1e-3}),
        ("drive_losses.force_smoothing", {"force_smoothing": 0.0}),
    ],
)
def test_bad_loss_parameters_name_the_field(field: str, changes: dict[str, float]) -> None:
    """Efficiencies outside (0, 1], negative coefficients or speeds, zero smoothing are rejected by name."""
    with pytest.raises(InvalidInputError, match=re.escape(field)):
        DriveLosses(**changes)


def test_gear_ratio_of_one_or_less_is_rejected() -> None:
    """G <= 1 is not a reduction gearbox: the error names lift.gear_ratio."""
    for g in (1.0, 0.5, -2.0):
        with pytest.raises(InvalidInputError, match=re.escape("lift.gear_ratio")):
            dataclasses.replace(EMLAS.lift, gear_ratio=g)


def _preset() -> dict:
    return yaml.safe_load(shipped("emla", "paper").read_text())


def test_enabling_the_presets_drive_losses_loads_them_with_per_actuator_overrides() -> None:
    """``enabled: true`` loads the shipped values; an actuator may override one; provenance is kept."""
    doc = _preset()
    doc["drive_losses"]["enabled"] = True
    doc["battery"]["inverter_efficiency"]["value"] = 1.0
    doc["actuators"]["telescope"]["drive_losses"] = {"transmission_efficiency_forward": 0.9}
    emlas = emla_set_from_mapping(doc)
    assert emlas.lift.losses.transmission_efficiency_forward == 0.87
    assert emlas.telescope.losses.transmission_efficiency_forward == 0.9
    assert emlas.lift.losses.brake_speed == 1.0e-3
    assert emlas.lift.source_of("drive_losses.inverter_resistance").startswith("estimate")
    assert "holding brake" in emlas.lift.losses.describe()


def test_inverter_counted_twice_is_rejected() -> None:
    """The drive-loss inverter model with a battery inverter efficiency < 1 would count it twice."""
    doc = _preset()
    doc["drive_losses"]["enabled"] = True
    with pytest.raises(InvalidInputError, match=re.escape("battery.inverter_efficiency")):
        emla_set_from_mapping(doc)


def test_misspelt_or_non_boolean_switch_is_a_config_error() -> None:
    """An unknown drive-loss key and ``enabled: "no"`` are reported with the section."""
    doc = _preset()
    doc["drive_losses"]["inverter_los"] = 1.0
    with pytest.raises(ConfigError, match="inverter_los"):
        emla_set_from_mapping(doc)
    doc = _preset()
    doc["drive_losses"]["enabled"] = "no"
    with pytest.raises(ConfigError, match="enabled"):
        emla_set_from_mapping(doc)


def test_efficiency_map_names_the_losses_that_are_on_and_they_cap_its_efficiency() -> None:
    """The map title names the options; with eta_fwd = 0.87 no motoring point exceeds 0.87."""
    from hiab_sim.emla.maps import efficiency_map, plot_efficiency_map

    params = dataclasses.replace(EMLAS.lift, losses=ON)
    emap = efficiency_map(params, n_force=41, n_velocity=41)
    title = plot_efficiency_map(emap).axes[0].get_title().replace("\n", " ")
    assert "transmission eta 0.87 fwd / 0.862 back" in title and "inverter" in title and "holding brake" in title
    motoring = emap.within_envelope & (emap.mechanical_power > 0)
    assert np.nanmax(emap.efficiency[motoring]) <= 0.87
    plain = plot_efficiency_map(efficiency_map(EMLAS.lift, n_force=21, n_velocity=21)).axes[0].get_title()
    assert "drive losses: off (paper model)" in plain


def test_peak_push_force_pays_the_forward_transmission_efficiency() -> None:
    """At the peak force, moving out at 10 mm/s, the exact motor torque is tau_peak + b v / (k eta_fwd)."""
    params = dataclasses.replace(EMLAS.lift, losses=ON)
    f = peak_force(params)
    assert f == pytest.approx(0.87 * peak_force(EMLAS.lift), rel=1e-15)
    op = operating_point(params, f, 0.01, 0.0, exact=True)
    k = params.transmission_ratio
    expected = params.motor.peak_torque + params.viscous_friction * 0.01 / (k * 0.87)
    assert float(op.motor_torque) == pytest.approx(expected, rel=1e-6)
