"""The imported machine file's text, and the round trip that proves it against the original MJCF.

:func:`machine_yaml` writes the file with a comment on every value (where in the MJCF it came
from). :func:`round_trip` compares actuator forces [N] on random loop-consistent states inside the
working ranges: the original MJCF's bare mechanism (armature, damping, stiffness, friction loss,
gravity compensation and fluid forces set to zero; actuators play no part in inverse dynamics) by
``mj_inverse`` of its open tree and the projection on its own ``connect`` pins,

    tau - J_tcp^T F = S^T Q + J^T lambda,

S selecting the actuator slides and the locked joints, against both ID paths of the machine built
from the written file (:mod:`hiab_sim.machine.dynamics.paths`). The original's state is closed by
Newton on its own pins with the machine's joints held (continuation from the reference pose in
steps), so the two models share only the joint values, never their kinematics.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import yaml

from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.paths import MACHINE_ID_PATHS, make_machine_dynamics
from hiab_sim.machine.mjcf_import.frames import Imported, Note
from hiab_sim.machine.mjcf_import.pose import close, jac_dot_qvel, plane_axes, residual_and_jacobian

#: Continuation steps from the reference pose to each sample.
STEPS = 8


def plain(node: Any) -> Any:
    """The values of a tree of :class:`Note` (what the loader reads)."""
    if isinstance(node, Note):
        return plain(node.value)
    if isinstance(node, dict):
        return {k: plain(v) for k, v in node.items()}
    return node


def _flow(value: Any) -> str:
    text = yaml.safe_dump(plain(value), default_flow_style=True, width=10**6).strip()
    return text.removesuffix("...").strip()  # a lone scalar's document end marker


def _emit(node: dict[str, Any], indent: int, lines: list[str]) -> None:
    pad = " " * indent
    for key, value in node.items():
        if isinstance(value, Note):
            lines.append(f"{pad}{key}: {_flow(value.value)}  # {value.origin}")
        elif isinstance(value, dict) and value:
            lines.append(f"{pad}{key}:")
            _emit(value, indent + 2, lines)
        else:
            lines.append(f"{pad}{key}: {_flow(value)}")


def machine_yaml(imported: Imported, command: str) -> str:
    """The machine file: a header (the command, the reference pose, the plane) and every value commented."""
    axes = plane_axes(imported.mech)
    lines = [
        f"# Imported from MJCF by: {command}",
        "# Every value's comment says where in the MJCF it came from (MuJoCo's compiled model).",
        f"# Plane of motion: machine x = MuJoCo {np.round(axes[:, 0], 9).tolist()}, y (up) = "
        f"{np.round(axes[:, 1], 9).tolist()}, z (normal) = {np.round(axes[:, 2], 9).tolist()}.",
        *(f"# {note}" for note in imported.notes),
        *(f"# warning: {line}" for line in imported.warnings),
        "",
    ]
    _emit(imported.tree, 0, lines)
    return "\n".join(lines) + "\n"


def fit_ranges(imported: Imported) -> Machine:
    """The imported machine, each working range narrowed to what its chain's stroke reaches (noted in the file).

    A range given by the MJCF may need a little more stroke than the slide's range gives (rounded
    numbers in the file); the working range is then the part the stroke serves.
    """
    from hiab_sim.machine.kinematics.assembly import reachable_joint_range
    from hiab_sim.machine.loader import machine_from_dict

    machine = machine_from_dict(plain(imported.tree), check_assembly=False)
    for chain in machine.chains:
        link = machine.joint_link(chain.joint)
        if chain.kind == "direct" or link.joint_range is None:
            continue
        reach = reachable_joint_range(machine, chain)
        low, high = link.joint_range
        if reach is None or (reach[0] <= low and high <= reach[1]):
            continue
        fitted = [max(low, reach[0]), min(high, reach[1])]
        note = imported.tree["links"][link.name]["joint_range"]
        imported.tree["links"][link.name]["joint_range"] = Note(
            fitted, f"{note.origin}, narrowed to what the stroke of chain {chain.name} reaches"
        )
        imported.notes.append(
            f"working range of {link.joint} narrowed from [{low:.9g}, {high:.9g}] to [{fitted[0]:.9g}, {fitted[1]:.9g}]"
        )
    return machine_from_dict(plain(imported.tree), check_assembly=False)


def _bare(model: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of the model's mechanism only: no armature, damping, springs, friction loss, fluid, gravcomp."""
    bare = model.__copy__()
    bare.dof_armature[:] = 0.0
    bare.dof_damping[:] = 0.0
    bare.dof_frictionloss[:] = 0.0
    bare.jnt_stiffness[:] = 0.0
    bare.body_gravcomp[:] = 0.0
    bare.opt.density = 0.0
    bare.opt.viscosity = 0.0
    bare.opt.wind[:] = 0.0
    bare.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    return bare


def original_forces(
    imported: Imported, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, tcp_force: np.ndarray
) -> np.ndarray:
    """Actuator forces f_x [N] of the original MJCF (T, n_chains) at machine joint samples (module docstring)."""
    mech = imported.mech
    model = _bare(mech.model)
    data = mujoco.MjData(model)
    held_dofs = [int(model.jnt_dofadr[j]) for j, _, _ in imported.joint_map] + [
        int(model.jnt_dofadr[j]) for j in mech.locked
    ]
    dependent = [d for d in range(model.nv) if d not in held_dofs]
    act = [int(model.jnt_dofadr[j]) for j, _ in imported.actuators]
    kappa = np.array([k for _, k in imported.actuators])
    select = np.zeros((model.nv, len(act) + len(mech.locked)))
    for c, dof in enumerate([*act, *(int(model.jnt_dofadr[j]) for j in mech.locked)]):
        select[dof, c] = 1.0
    axes = plane_axes(mech)
    body, point = imported.tcp
    jtcp = np.zeros((3, model.nv))
    out = np.empty((q.shape[0], len(act)))
    adr = [int(model.jnt_qposadr[j]) for j, _, _ in imported.joint_map]
    start = np.array([imported.qpos_ref[a] for a in adr])
    for i in range(q.shape[0]):
        data.qpos[:] = imported.qpos_ref
        target = np.array([(q[i, k] - b) / a for k, (_, a, b) in enumerate(imported.joint_map)])
        for t in np.linspace(0.0, 1.0, STEPS + 1)[1:]:
            data.qpos[adr] = start + t * (target - start)
            close(mech, data, dependent)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        _, jac = residual_and_jacobian(mech, data)
        held = np.zeros(model.nv)
        held_acc = np.zeros(model.nv)
        for k, (j, a, _) in enumerate(imported.joint_map):
            held[model.jnt_dofadr[j]] = dq[i, k] / a
            held_acc[model.jnt_dofadr[j]] = ddq[i, k] / a
        jd = jac[:, dependent]
        data.qvel[:] = held
        data.qvel[dependent] = np.linalg.solve(jd, -jac @ held)
        mujoco.mj_comVel(model, data)  # mj_jacDot reads the bodies' velocities
        bias = jac_dot_qvel(mech, data)
        data.qacc[:] = held_acc
        data.qacc[dependent] = np.linalg.solve(jd, -(jac @ held_acc + bias))
        mujoco.mj_inverse(model, data)
        world = axes[:, :2] @ tcp_force[i]
        mujoco.mj_jac(model, data, jtcp, None, data.xpos[body] + data.xmat[body].reshape(3, 3) @ point, body)
        tau = data.qfrc_inverse - jtcp.T @ world
        solution = np.linalg.solve(np.hstack([select, jac.T]), tau)
        out[i] = solution[: len(act)] * kappa
    return out


def round_trip(imported: Imported, machine: Machine, samples: int = 40, seed: int = 0) -> dict[str, float]:
    """Largest relative difference (per actuator, of its peak force) between the original and each machine path."""
    rng = np.random.default_rng(seed)
    ranges = np.array([machine.joint_link(j).joint_range for j in machine.joint_names], dtype=float)
    low, high = ranges[:, 0], ranges[:, 1]
    q = low + (high - low) * rng.uniform(0.02, 0.98, (samples, len(low)))
    dq = rng.normal(0.0, 0.5, q.shape)
    ddq = rng.normal(0.0, 1.0, q.shape)
    tcp_force = rng.normal(0.0, 1000.0, (samples, 2))
    reference = original_forces(imported, q, dq, ddq, tcp_force)
    peak = np.maximum(np.max(np.abs(reference), axis=0), 1e-300)
    out = {}
    for path in MACHINE_ID_PATHS:
        force = make_machine_dynamics(machine, path=path)(q, dq, ddq, tcp_force).force
        out[path] = float(np.max(np.max(np.abs(force - reference), axis=0) / peak))
    return out
