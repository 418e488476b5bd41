"""Cross-validation of the MuJoCo and analytic inverse dynamics, behind ``hiab-sim validate``.

Cases (``validate/cases.yaml``), each run without and with a TCP payload force:

- ``random_states``: random loop-consistent states over each joint's full working range;
- ``trajectory``: a smooth trajectory sweeping each joint's range;
- ``random_lengths``: random states on >= 20 random feasible link-length sets;
- ``static``: gravity-only static poses.

For each case: the maximum absolute and relative error of the actuator forces (relative to
each actuator's peak |f| over the case) and the maximum absolute error of the velocities
between the two paths, and the energy balance of each path: the power balance
``sum f v + F_tcp . v_tcp = dE/dt`` (relative to the peak power) for moving samples, the
virtual-work balance ``f_j = d(U - F_tcp . p_tcp)/dx_j`` (relative to the peak force) for
static ones. The math lives here; file output is in :mod:`hiab_sim.validation_report`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.checks import check_choice, check_range
from hiab_sim.crane import kinematics, mechanism
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.dynamics.analytic_id import (
    analytic_inverse_dynamics,
    energy_rate,
    spatial_inverse_dynamics,
    state_energy,
    tcp_velocity,
)
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import DEFAULT_CASES, Source, locate
from hiab_sim.yaml_fields import mapping, read_yaml, section, text, vector

IdFunction = Callable[[LinkLengths, JointSamples, Array], ActuatorSamples]

CASE_KINDS = ("random_states", "trajectory", "random_lengths", "static")


@dataclass(frozen=True)
class Tolerances:
    """Pass thresholds: forces relative to each actuator's peak |f| [-], velocities [m/s], balance [-]."""

    force_relative: float = 1e-6
    velocity_absolute: float = 1e-9
    balance_relative: float = 1e-6

    def __post_init__(self) -> None:
        check_range("tolerances.force_relative", self.force_relative, 0.0, low_open=True)
        check_range("tolerances.velocity_absolute", self.velocity_absolute, 0.0, unit="m/s", low_open=True)
        check_range("tolerances.balance_relative", self.balance_relative, 0.0, low_open=True)


@dataclass(frozen=True)
class CaseSpec:
    """One validation case as read from the case file."""

    name: str
    kind: str
    samples: int
    seed: int = 0
    payload: tuple[float, float, float] | None = None  # TCP force in {W} [N]
    length_sets: int = 1
    description: str = ""

    def __post_init__(self) -> None:
        where = f"cases.{self.name}"
        check_choice(f"{where}.kind", self.kind, CASE_KINDS)
        check_range(f"{where}.samples", self.samples, 1, integral=True)
        check_range(f"{where}.seed", self.seed, 0, integral=True)
        check_range(f"{where}.length_sets", self.length_sets, 1, integral=True)


@dataclass(frozen=True)
class CaseResult:
    """Errors of one case; arrays are per actuator (lift, tilt, telescope)."""

    name: str
    kind: str
    description: str
    samples: int
    length_sets: int
    payload: tuple[float, float, float] | None
    peak_force: list[float]
    force_abs_error: list[float]
    force_rel_error: list[float]
    velocity_abs_error: list[float]
    spatial_force_rel_error: list[float]  # the 6D reference form vs MuJoCo
    balance_kind: str  # "power" or "virtual work"
    balance_analytic: float
    balance_mujoco: float
    passed: bool
    traces: dict[str, Any] = field(repr=False, default_factory=dict)


# ---------------------------------------------------------------------------------------------
# Inputs: link lengths and joint samples
# ---------------------------------------------------------------------------------------------


def lengths_from_fractions(crane: Crane, fractions: Array, spread: float = 0.2) -> LinkLengths | None:
    """A link-length set that serves both working joint ranges, from fractions in [0, 1]^(2x3).

    Per chain: L = L_default (1 - spread + 2 spread u0); the pin-to-pin length x0 in the window
    [s_high - stroke, s_low] that keeps the stroke inside [0, stroke] over the joint range
    (s: the triangle side {Bc}-{Tc} at the range ends), at fraction u1; Lc in
    [max(stroke, s_high - x0), x0) at fraction u2 (const_j), Lc0 = x0 - Lc. Returns None when the
    window is empty for this L. The result passes :func:`hiab_sim.crane.mechanism.check_lengths`.
    """
    chains = []
    for chain, u in zip(crane.chains, np.asarray(fractions, dtype=float).reshape(2, 3), strict=True):
        L = chain.default_lengths.L * (1.0 - spread + 2.0 * spread * u[0])
        ends = mechanism.hinge_angle(chain, np.asarray(chain.joint_range))
        s_low, s_high = mechanism.stroke_from_hinge_angle(ends, L, chain.L1, 0.0)
        margin = 1e-9
        x0_low, x0_high = max(s_high - chain.stroke, chain.stroke) + margin, s_low - margin
        if not x0_low < x0_high:
            return None
        x0 = x0_low + u[1] * (x0_high - x0_low)
        lc_low, lc_high = max(chain.stroke, s_high - x0) + margin, 0.95 * x0
        if not lc_low < lc_high:
            return None
        Lc = lc_low + u[2] * (lc_high - lc_low)
        chains.append(ChainLengths(L=float(L), Lc0=float(x0 - Lc), Lc=float(Lc)))
    lengths = LinkLengths(*chains)
    check_lengths(crane, lengths)
    return lengths


def random_link_lengths(crane: Crane, rng: np.random.Generator, count: int, spread: float = 0.2) -> list[LinkLengths]:
    """``count`` random feasible link-length sets (see :func:`lengths_from_fractions`)."""
    out: list[LinkLengths] = []
    while len(out) < count:
        lengths = lengths_from_fractions(crane, rng.uniform(0.0, 1.0, (2, 3)), spread)
        if lengths is not None:
            out.append(lengths)
    return out


def joint_ranges(crane: Crane) -> Array:
    """Working ranges (3, 2) of theta1 [rad], theta2 [rad], xt2 [m]."""
    return np.array([crane.lift.joint_range, crane.tilt.joint_range, crane.telescope.joint_range])


def random_states(crane: Crane, rng: np.random.Generator, n: int) -> JointSamples:
    """Random states over each joint's full working range, the range ends included.

    Positions uniform; velocities ~ N(0, 0.3) rad/s or m/s; accelerations ~ N(0, 1) rad/s^2 or m/s^2.
    """
    ranges = joint_ranges(crane)
    fraction = rng.uniform(0.0, 1.0, (n, 3))
    if n >= 4:  # the range ends themselves
        fraction[:2] = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 1.0]])
    position = ranges[:, 0] + fraction * (ranges[:, 1] - ranges[:, 0])
    return JointSamples(position, rng.normal(0.0, 0.3, (n, 3)), rng.normal(0.0, 1.0, (n, 3)))


def smooth_trajectory(crane: Crane, n: int, duration: float = 10.0) -> tuple[Array, JointSamples]:
    """Sinusoids sweeping 5 %..95 % of each joint's range over ``duration`` [s]: (t, samples)."""
    ranges = joint_ranges(crane)
    mid, amp = ranges.mean(axis=1), 0.45 * (ranges[:, 1] - ranges[:, 0])
    w = 2.0 * np.pi / duration * np.array([1.0, 1.5, 2.0])
    t = np.linspace(0.0, duration, n)
    arg = w * t[:, None] + np.array([0.0, 0.7, 1.9])
    return t, JointSamples(mid + amp * np.sin(arg), amp * w * np.cos(arg), -amp * w**2 * np.sin(arg))


# ---------------------------------------------------------------------------------------------
# Balances
# ---------------------------------------------------------------------------------------------


def _payload_array(payload: tuple[float, float, float] | None) -> Array:
    return np.zeros(3) if payload is None else np.asarray(payload, dtype=float)


def power_residual(
    crane: Crane, lengths: LinkLengths, joints: JointSamples, out: ActuatorSamples, payload: Array
) -> tuple[Array, Array]:
    """(sum f v + F_tcp . v_tcp - dE/dt, sum f v + F_tcp . v_tcp) per sample [W]."""
    power = out.power.sum(axis=1) + tcp_velocity(crane, lengths, joints) @ payload
    return power - energy_rate(crane, lengths, joints), power


def virtual_work_residual(
    crane: Crane,
    lengths: LinkLengths,
    joints: JointSamples,
    out: ActuatorSamples,
    payload: Array,
    step: float = 1e-5,
) -> Array:
    """f_j - d(U - F_tcp . p_tcp)/dx_j at static samples (T, 3) [N], 5-point stencils in x."""
    residual = out.force.copy()
    for j in range(3):
        value = []
        for k in (-2, -1, 1, 2):
            x = out.stroke.copy()
            x[:, j] += k * step
            theta1 = mechanism.stroke_to_joint(crane.lift, lengths.lift, x[:, 0])
            theta2 = mechanism.stroke_to_joint(crane.tilt, lengths.tilt, x[:, 1])
            position = np.stack([theta1, theta2, x[:, 2]], axis=1)
            potential = state_energy(crane, lengths, position, np.zeros_like(position)).potential
            tcp = kinematics.tcp_position(crane, theta1, theta2, x[:, 2])
            value.append(potential - tcp @ payload)
        residual[:, j] -= (value[0] - 8.0 * value[1] + 8.0 * value[2] - value[3]) / (12.0 * step)
    return residual


# ---------------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------------


def _case_inputs(crane: Crane, spec: CaseSpec) -> tuple[list[tuple[LinkLengths, JointSamples]], Array | None]:
    """(lengths, samples) groups of a case, and its time axis if it has one."""
    rng = np.random.default_rng(spec.seed)
    default = crane.default_lengths
    if spec.kind == "random_states":
        return [(default, random_states(crane, rng, spec.samples))], None
    if spec.kind == "trajectory":
        t, joints = smooth_trajectory(crane, spec.samples)
        return [(default, joints)], t
    if spec.kind == "static":
        return [(default, JointSamples.at_rest(random_states(crane, rng, spec.samples).position))], None
    if spec.kind == "random_lengths":
        per_set = max(1, spec.samples // spec.length_sets)
        return [
            (xi, random_states(crane, rng, per_set)) for xi in random_link_lengths(crane, rng, spec.length_sets)
        ], None
    raise ConfigError(f"case {spec.name}: unknown kind {spec.kind!r}; allowed: {list(CASE_KINDS)}")


def run_case(crane: Crane, spec: CaseSpec, mujoco: IdFunction, tolerances: Tolerances) -> CaseResult:
    """Run one case through both paths and measure the errors (see the module docstring)."""
    groups, time = _case_inputs(crane, spec)
    payload = _payload_array(spec.payload)
    static = spec.kind == "static"
    f_an, f_mj, f_6d, v_an, v_mj, res_an, res_mj, scale = [], [], [], [], [], [], [], []
    for lengths, joints in groups:
        analytic = analytic_inverse_dynamics(crane, lengths, joints, tcp_force=payload)
        reference = mujoco(lengths, joints, payload)
        f_6d.append(spatial_inverse_dynamics(crane, lengths, joints, tcp_force=payload).force)
        f_an.append(analytic.force)
        f_mj.append(reference.force)
        v_an.append(analytic.velocity)
        v_mj.append(reference.velocity)
        if static:
            res_an.append(virtual_work_residual(crane, lengths, joints, analytic, payload))
            res_mj.append(virtual_work_residual(crane, lengths, joints, reference, payload))
        else:
            residual, power = power_residual(crane, lengths, joints, analytic, payload)
            res_an.append(residual)
            res_mj.append(power_residual(crane, lengths, joints, reference, payload)[0])
            scale.append(power)
    fa, fm, f6, va, vm = (np.concatenate(a) for a in (f_an, f_mj, f_6d, v_an, v_mj))
    peak = np.max(np.abs(fa), axis=0)
    force_abs = np.max(np.abs(fm - fa), axis=0)
    force_rel = force_abs / np.maximum(peak, np.finfo(float).tiny)
    spatial_rel = np.max(np.abs(fm - f6), axis=0) / np.maximum(peak, np.finfo(float).tiny)
    velocity_abs = np.max(np.abs(vm - va), axis=0)
    if static:
        norm = float(np.max(peak))
        balance_an = float(np.max(np.abs(np.concatenate(res_an)))) / norm
        balance_mj = float(np.max(np.abs(np.concatenate(res_mj)))) / norm
    else:
        norm = float(np.max(np.abs(np.concatenate(scale))))
        balance_an = float(np.max(np.abs(np.concatenate(res_an)))) / norm
        balance_mj = float(np.max(np.abs(np.concatenate(res_mj)))) / norm
    passed = bool(
        np.all(force_rel <= tolerances.force_relative)
        and np.all(spatial_rel <= tolerances.force_relative)
        and np.all(velocity_abs <= tolerances.velocity_absolute)
        and balance_an <= tolerances.balance_relative
    )
    axis = time if time is not None else np.arange(fa.shape[0], dtype=float)
    return CaseResult(
        name=spec.name,
        kind=spec.kind,
        description=spec.description,
        samples=int(fa.shape[0]),
        length_sets=len(groups),
        payload=spec.payload,
        peak_force=peak.tolist(),
        force_abs_error=force_abs.tolist(),
        force_rel_error=force_rel.tolist(),
        velocity_abs_error=velocity_abs.tolist(),
        spatial_force_rel_error=spatial_rel.tolist(),
        balance_kind="virtual work" if static else "power",
        balance_analytic=balance_an,
        balance_mujoco=balance_mj,
        passed=passed,
        traces={"axis": axis, "time": time is not None, "analytic": fa, "mujoco": fm},
    )


def mujoco_path(crane: Crane) -> IdFunction:
    """The MuJoCo inverse dynamics as an :data:`IdFunction`, one model per link-length set."""
    from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics

    cache: dict[tuple[float, ...], Any] = {}

    def run(lengths: LinkLengths, joints: JointSamples, payload: Array) -> ActuatorSamples:
        key = tuple(lengths.as_array().tolist())
        if key not in cache:
            cache[key] = MujocoInverseDynamics(crane, lengths)
        result: ActuatorSamples = cache[key](joints, tcp_force=payload)
        return result

    return run


# ---------------------------------------------------------------------------------------------
# Case file
# ---------------------------------------------------------------------------------------------


def load_cases(path: str | Path | Source = DEFAULT_CASES) -> tuple[Tolerances, list[CaseSpec]]:
    """Read the tolerances and cases (a shipped name or a path); ``payload: both`` makes two cases.

    Raises:
        ConfigError: Missing file, malformed YAML, unknown or missing keys, wrong types.
        InvalidInputError: A value out of range, named by its field.

    """
    found = locate(path, "cases")
    top = mapping(read_yaml(found), found.label, {"tolerances", "payload_force", "cases"}, {"cases"})
    tolerances = Tolerances(**section(Tolerances, top.get("tolerances"), "tolerances"))
    payload = vector(top.get("payload_force", [0.0, -2452.0, 0.0]), "payload_force", 3)
    if not isinstance(top["cases"], list):
        raise ConfigError(f"{found.label}: cases: expected a list of cases, got {type(top['cases']).__name__}")
    choices: dict[str, list[tuple[float, ...] | None]] = {"none": [None], "payload": [payload], "both": [None, payload]}
    specs = []
    for k, entry in enumerate(top["cases"]):
        node = mapping(entry, f"cases[{k}]", None)
        where = f"cases.{node.get('name', k)}"
        values = section(CaseSpec, {key: v for key, v in node.items() if key != "payload"}, where, skip=("payload",))
        mode = text(node.get("payload", "both"), f"{where}.payload")
        if mode not in choices:
            raise InvalidInputError(f"{where}.payload", mode, "must be one of none, payload, both")
        for force in choices[mode]:
            suffix = "" if force is None else "+payload"
            specs.append(CaseSpec(**{**values, "name": f"{values['name']}{suffix}"}, payload=force))  # type: ignore[arg-type]
    return tolerances, specs


def with_samples(specs: list[CaseSpec], samples: int) -> list[CaseSpec]:
    """The same cases with ``samples`` samples each (random_lengths: at least one per set)."""
    if samples < 1:
        raise InvalidInputError("samples", samples, "must be >= 1")
    out = []
    for spec in specs:
        n = (
            max(samples, spec.length_sets)
            if spec.kind == "random_lengths"
            else max(samples, 4 if spec.kind != "trajectory" else 8)
        )
        out.append(CaseSpec(**{**asdict(spec), "samples": n}))
    return out
