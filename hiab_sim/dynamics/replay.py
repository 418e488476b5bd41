"""Forward replay: apply actuator forces to the motors of the MJCF model and integrate, no feedback.

Used to check the inverse dynamics (the replay must track the joint trajectory the forces were
computed for) and by ``hiab-sim render --mode simulate``.

Forces on a time grid. ``forces`` (T, 3) [N] in the order lift, tilt, telescope are given at
the sample times ``time`` (T,) [s], strictly increasing. They are interpolated in time by a
cubic spline (not-a-knot; linear for two samples), whose O(dt^4) error keeps a 1 ms force
grid from limiting the replay (linear interpolation there costs ~1e-3 rad over 5 s), and held
over each integrator step at their value at the step's midpoint, t + dt/2 (RK4 holds ``ctrl``
constant over a step; the midpoint value makes the applied impulse second-order accurate in
dt). Before the first and after the last sample the end values are held.

Closed loops. The ``connect`` equalities are soft constraints; their ``solref`` (timeconst,
dampratio) = (2 dt, 1) is the stiffest MuJoCo recommends for the integrator step (a time
constant below 2 dt is not resolved by the step and is clamped), critically damped so that a
loop error decays without ringing. With ``solimp`` d = 0.9999 the constraint's regularisation
is 1e-4 of its effective inverse mass, so under a load f the loop stretches only by about
(1 - d) (f / m_eff) timeconst^2 (micrometres at the XS 031's 100 kN loads): the replayed joints
follow the rigid crane to well inside 1 mm. The default step is 0.25 ms with RK4.

Open-loop instability. A crane whose cylinders push with prescribed forces is unstable: the
linearised replay dynamics at rest have growth rates of 1.5-4.5 1/s over the XS 031's working
range and about 16 1/s with both booms near their upper limits (measured with
``mjd_transitionFD``). Any error (integration, force interpolation, loop compliance) grows like
exp(rate t), so a 5 s replay tracks to 1e-3 only with errors of 1e-8 per step: hence the small
step and the midpoint force hold. Tracking over longer horizons needs feedback, which a replay
deliberately does not have.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import CubicSpline

from hiab_sim.arrays import Array
from hiab_sim.crane.description import CHAIN_NAMES, Crane, LinkLengths
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.model.mjcf import ACTUATORS, JOINTS, source_to_world

#: Default integrator step of a replay [s] (RK4), see the module docstring.
DEFAULT_TIMESTEP = 2.5e-4


@dataclass(frozen=True)
class Replay:
    """A forward simulation sampled at the requested times.

    ``time`` (T,) [s]; ``qpos``, ``qvel`` (T, nq) full MuJoCo state (for rendering);
    ``position``, ``velocity`` (T, 3) of the independent joints Θ1 [rad], Θ2 [rad], xt2 [m];
    ``loop_residual`` (T,) largest pin gap of the closed chains [m].
    """

    time: Array
    qpos: Array
    qvel: Array
    position: Array
    velocity: Array
    loop_residual: Array


def _check_time_forces(time: Array, forces: Array) -> None:
    if time.ndim != 1 or time.size < 2 or not np.all(np.isfinite(time)) or np.any(np.diff(time) <= 0.0):
        raise InvalidInputError("time", f"shape {time.shape}", "must be >= 2 finite, strictly increasing samples", "s")
    if forces.shape != (time.size, 3):
        raise InvalidInputError("forces", f"shape {forces.shape}", f"must have shape ({time.size}, 3)", "N")
    if not np.all(np.isfinite(forces)):
        raise InvalidInputError("forces", "NaN or inf", "must be finite", "N")


def replay(
    crane: Crane,
    lengths: LinkLengths | None,
    time: ArrayLike,
    joints: JointSamples,
    forces: ArrayLike,
    *,
    timestep: float | None = None,
    tcp_force: ArrayLike | None = None,
) -> Replay:
    """Integrate the crane from the first joint sample with the given actuator forces on the motors.

    Args:
        crane: the crane description.
        lengths: link lengths Xi (default: the crane's own).
        time: sample times (T,) [s], strictly increasing; the simulation runs from time[0].
        joints: joint samples; only the first (position, velocity) sets the initial state,
            completed to a loop-consistent state with MuJoCo's kinematics.
        forces: actuator forces f_x (T, 3) [N] at ``time``, order lift, tilt, telescope,
            positive extending; interpolated as the module docstring says.
        timestep: integrator step [s] (default :data:`DEFAULT_TIMESTEP`); the loops' ``solref``
            time constant follows it (2 dt).
        tcp_force: constant force of the environment on the TCP in {W} [N], (3,).

    Returns:
        The simulated trajectory at ``time``.

    Raises:
        InvalidInputError: malformed time or forces, or an invalid first joint sample.

    """
    t = np.asarray(time, dtype=float)
    f = np.asarray(forces, dtype=float)
    _check_time_forces(t, f)
    inverse = MujocoInverseDynamics(crane, lengths)
    first = JointSamples(joints.position[:1], joints.velocity[:1], joints.acceleration[:1])
    qpos0, qvel0, _ = inverse.state(first)

    model = inverse.model  # the same model as the inverse dynamics, with motors on x1, x2, xt2
    model.opt.jacobian = mujoco.mjtJacobian.mjJAC_AUTO
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    timestep = DEFAULT_TIMESTEP if timestep is None else timestep
    if not (np.isfinite(timestep) and timestep > 0.0):
        raise InvalidInputError("timestep", timestep, "must be > 0", "s")
    model.opt.timestep = float(timestep)
    dt = float(model.opt.timestep)
    model.eq_solref[:] = (2.0 * dt, 1.0)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0[0]
    data.qvel[:] = qvel0[0]
    data.time = float(t[0])
    mujoco.mj_forward(model, data)

    external = None
    if tcp_force is not None:
        external = source_to_world(np.asarray(tcp_force, dtype=float).reshape(3))
        jac = np.empty((3, model.nv))
        tcp = model.site("tcp").id
    actuator = [model.actuator(name).id for name in ACTUATORS]
    joint = [model.joint(name).qposadr[0] for name in JOINTS]
    sites = [(model.site(f"{c}_rod_end").id, model.site(f"{c}_boom_pivot").id) for c in CHAIN_NAMES]

    n_steps = int(np.ceil((t[-1] - t[0]) / dt - 1e-9))
    midpoints = t[0] + (np.arange(n_steps) + 0.5) * dt
    if t.size > 2:
        ctrl = CubicSpline(t, f, axis=0)(np.clip(midpoints, t[0], t[-1]))
    else:
        ctrl = np.stack([np.interp(midpoints, t, f[:, k]) for k in range(3)], axis=1)
    ctrl_full = np.zeros((n_steps, model.nu))
    ctrl_full[:, actuator] = ctrl

    T = t.size
    qpos = np.empty((T, model.nq))
    qvel = np.empty((T, model.nv))
    residual = np.empty(T)
    step_times = t[0] + np.arange(n_steps + 1) * dt
    k = 0
    for step in range(n_steps + 1):
        while k < T and t[k] <= step_times[step] + 0.5 * dt:
            # Record at the step time nearest t[k], corrected to first order with qvel.
            lag = t[k] - data.time
            qpos[k] = data.qpos + lag * data.qvel
            qvel[k] = data.qvel
            mujoco.mj_kinematics(model, data)
            residual[k] = max(float(np.linalg.norm(data.site_xpos[a] - data.site_xpos[b])) for a, b in sites)
            k += 1
        if step == n_steps:
            break
        data.ctrl[:] = ctrl_full[step]
        if external is not None:
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            mujoco.mj_jacSite(model, data, jac, None, tcp)
            data.qfrc_applied[:] = jac.T @ external
        mujoco.mj_step(model, data)
    return Replay(
        time=t,
        qpos=qpos,
        qvel=qvel,
        position=qpos[:, joint],
        velocity=qvel[:, joint],
        loop_residual=residual,
    )
