"""The figures of the validation page: the two inverse-dynamics paths over the cases of ``hiab-sim validate``.

``python -m hiab_sim.docs_site.validation_figures [--out docs/figures] [--samples N]`` runs every case
of the shipped case file (:func:`hiab_sim.validation.load_cases`) through MuJoCo and the analytic
path, as ``hiab-sim validate`` does, and writes

* ``validation_forces.png``: the trajectory case's actuator forces f_x [kN] on both paths (top), and
  for every case the per-sample difference |f_MuJoCo - f_analytic| over the actuator's peak |f| in the
  case, on a log scale, against the force tolerance (bottom);
* ``validation_balance.png``: per sample, the power balance residual
  |sum f v + F_tcp . v_tcp - dE/dt| over the case's peak power (dynamic cases) and the virtual-work
  residual max_j |f_j - d(U - F_tcp . p_tcp)/dx_j| over the case's peak force (static cases), on
  both paths, against the balance tolerance; log scale.

The numbers are the same measurements the validation table reports as maxima (same cases, seeds and
normalisations: :func:`hiab_sim.validation.run_case`); a residual of exactly 0 is drawn at the
bottom of the axis (a log scale has no 0).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.samples import ACTUATOR_NAMES
from hiab_sim.figure_io import new_figure, save_png

#: Drawn in place of an exact 0 on the log axes (below every round-off residual the cases show).
FLOOR = 1e-18
FIGURES = ("validation_forces.png", "validation_balance.png")


@dataclass(frozen=True)
class CaseTrace:
    """Per-sample measurements of one validation case (samples of all its link-length sets in order).

    Attributes:
        name: Case name (``+payload`` for the payload copy).
        kind: Case kind (``trajectory``, ``static``, ...).
        axis: Time [s] for a trajectory, else the sample index.
        analytic: Actuator forces (T, 3) of the analytic (planar se(2)) path [N].
        mujoco: Actuator forces (T, 3) of the MuJoCo path [N].
        balance_analytic: Balance residual per sample, normalised as in the table [-].
        balance_mujoco: The same for the MuJoCo forces [-].
        balance_kind: ``power`` or ``virtual work``.

    """

    name: str
    kind: str
    axis: Array
    analytic: Array
    mujoco: Array
    balance_analytic: Array
    balance_mujoco: Array
    balance_kind: str

    @property
    def force_relative(self) -> Array:
        """|f_MuJoCo - f_analytic| over each actuator's peak |f_analytic| in the case (T, 3) [-]."""
        peak = np.maximum(np.max(np.abs(self.analytic), axis=0), np.finfo(float).tiny)
        return np.abs(self.mujoco - self.analytic) / peak


def case_trace(crane: Any, spec: Any, mujoco: Any) -> CaseTrace:
    """Run case ``spec`` through both paths and keep every sample's force difference and balance residual."""
    from hiab_sim import validation

    groups, time = validation._case_inputs(crane, spec)  # the validate command's own samples and seeds
    payload = np.zeros(3) if spec.payload is None else np.asarray(spec.payload, dtype=float)
    static = spec.kind == "static"
    f_an, f_mj, r_an, r_mj, scale = [], [], [], [], []
    for lengths, joints in groups:
        analytic = analytic_inverse_dynamics(crane, lengths, joints, tcp_force=payload)
        reference = mujoco(lengths, joints, payload)
        f_an.append(analytic.force)
        f_mj.append(reference.force)
        if static:
            r_an.append(np.max(np.abs(validation.virtual_work_residual(crane, lengths, joints, analytic, payload)), 1))
            r_mj.append(np.max(np.abs(validation.virtual_work_residual(crane, lengths, joints, reference, payload)), 1))
        else:
            residual, power = validation.power_residual(crane, lengths, joints, analytic, payload)
            r_an.append(np.abs(residual))
            r_mj.append(np.abs(validation.power_residual(crane, lengths, joints, reference, payload)[0]))
            scale.append(power)
    fa, fm = np.concatenate(f_an), np.concatenate(f_mj)
    norm = float(np.max(np.abs(fa))) if static else float(np.max(np.abs(np.concatenate(scale))))
    return CaseTrace(
        name=spec.name,
        kind=spec.kind,
        axis=np.asarray(time, dtype=float) if time is not None else np.arange(fa.shape[0], dtype=float),
        analytic=fa,
        mujoco=fm,
        balance_analytic=np.concatenate(r_an) / norm,
        balance_mujoco=np.concatenate(r_mj) / norm,
        balance_kind="virtual work" if static else "power",
    )


def _floored(values: Array) -> Array:
    return np.maximum(values, FLOOR)


def forces_figure(traces: list[CaseTrace], force_tolerance: float) -> Any:
    """Top: the trajectory case's forces on both paths; bottom: every case's relative difference (log)."""
    fig = new_figure((11, 7.5))
    top, bottom = fig.subplots(2, 1)
    trajectory = next((t for t in traces if t.kind == "trajectory"), traces[0])
    every = max(1, len(trajectory.axis) // 60)  # about 60 MuJoCo markers, so the analytic line shows between
    for j, name in enumerate(ACTUATOR_NAMES):
        top.plot(trajectory.axis, trajectory.analytic[:, j] / 1e3, color=f"C{j}", label=f"{name}, analytic")
        top.plot(
            trajectory.axis[::every],
            trajectory.mujoco[::every, j] / 1e3,
            color=f"C{j}",
            linestyle="none",
            marker="o",
            markerfacecolor="none",
            label=f"{name}, MuJoCo",
        )
    top.set_xlabel("t [s]" if trajectory.kind == "trajectory" else "sample")
    top.set_ylabel("actuator force f_x [kN]")
    top.set_title(f"{trajectory.name}: the two inverse-dynamics paths")
    top.legend(ncol=3, fontsize="small")
    start = 0
    for k, trace in enumerate(traces):
        relative = _floored(np.max(trace.force_relative, axis=1))
        index = start + np.arange(relative.size)
        bottom.plot(index, relative, linestyle="none", marker=".", markersize=2, color=f"C{k % 10}", label=trace.name)
        start += relative.size
    bottom.axhline(force_tolerance, color="k", linestyle="--", label=f"tolerance {force_tolerance:g}")
    bottom.set_yscale("log")
    bottom.set_xlabel("sample (cases in the order of the table)")
    bottom.set_ylabel("max_j |f_MuJoCo - f_analytic| / peak |f_j|")
    bottom.set_title("MuJoCo minus analytic, every sample of every case")
    bottom.legend(ncol=3, fontsize="small", markerscale=4)
    return fig


def balance_figure(traces: list[CaseTrace], balance_tolerance: float) -> Any:
    """Per-sample balance residuals of both paths over every case (log)."""
    fig = new_figure((11, 5.5))
    ax = fig.subplots(1, 1)
    start = 0
    for k, trace in enumerate(traces):
        index = start + np.arange(trace.balance_analytic.size)
        label = f"{trace.name} ({trace.balance_kind})"
        ax.plot(index, _floored(trace.balance_analytic), ".", markersize=2, color=f"C{k % 10}", label=label)
        ax.plot(index, _floored(trace.balance_mujoco), "x", markersize=2, color=f"C{k % 10}", alpha=0.4)
        start += trace.balance_analytic.size
    ax.axhline(balance_tolerance, color="k", linestyle="--", label=f"tolerance {balance_tolerance:g}")
    ax.set_yscale("log")
    ax.set_xlabel("sample (cases in the order of the table); dots: analytic, crosses: MuJoCo")
    ax.set_ylabel("balance residual / peak power or force")
    ax.set_title("Power balance sum f v + F_tcp.v_tcp = dE/dt, and virtual work at rest")
    fig.legend(loc="outside lower center", ncol=5, fontsize="small", markerscale=4)
    return fig


def write_figures(out: Path, samples: int | None = None) -> list[Path]:
    """Run the shipped cases (``samples`` per case, as ``hiab-sim validate --samples``) and write :data:`FIGURES`."""
    from hiab_sim.crane.loader import load_crane
    from hiab_sim.validation import DEFAULT_CASES, load_cases, mujoco_path, with_samples

    crane = load_crane("xs031")
    tolerances, specs = load_cases(DEFAULT_CASES)
    if samples is not None:
        specs = with_samples(specs, samples)
    mujoco = mujoco_path(crane)
    traces = [case_trace(crane, spec, mujoco) for spec in specs]
    out.mkdir(parents=True, exist_ok=True)
    figures = (forces_figure(traces, tolerances.force_relative), balance_figure(traces, tolerances.balance_relative))
    return [save_png(fig, out / name, dpi=110) for fig, name in zip(figures, FIGURES, strict=True)]


def main(argv: list[str] | None = None) -> int:
    """Command line: write the validation figures into ``--out``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/figures"), help="folder (default docs/figures)")
    parser.add_argument("--samples", type=int, default=None, help="samples per case (default: the case file's)")
    args = parser.parse_args(argv)
    for path in write_figures(args.out, args.samples):
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
