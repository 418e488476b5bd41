"""SQP driver: scipy SLSQP with exact gradients, per-iteration history, atomic checkpoints, resume, multi-start.

Every SQP iteration appends (cost, scaled cost, max constraint violation, Xi) to the history and
rewrites ``checkpoint_<k>.json`` in the output folder atomically (temp file + ``os.replace``),
so a killed run continues from its last iterate with ``resume=True`` (the quasi-Newton Hessian
restarts from the identity there). Each checkpoint records what it belongs to (:func:`checkpoint_identity`:
the study's path and content hash, the ID path and the start's Xi); resuming from a checkpoint of
another run is refused with the differing field named, and a fresh run deletes the folder's old
checkpoints first (:func:`remove_checkpoints`).
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import CHAIN_NAMES, LinkLengths
from hiab_sim.errors import InvalidInputError, SolverError
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.design_values import DesignValues
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_setup import start_error
from hiab_sim.study.solvers.single_solve import solve_once

#: Largest violation [scaled units] of a nominal constraint (:meth:`TaskProblem.margins`) a start
#: may have: round-off only (the built crane's strokes reach exactly 0 at the ends of its joint range).
START_TOLERANCE = 1e-9


@dataclass
class Iterate:
    """One row of the history: iteration, objective (W^2 s costf2, J battery_energy), scaled, violation, Xi [m]."""

    iteration: int
    cost: float
    scaled_cost: float
    max_violation: float
    xi: list[float]
    wall_time: float


@dataclass
class SolveResult:
    """Outcome of one start."""

    start: int
    initial_lengths: DesignValues
    z0: Array
    z: Array
    history: list[Iterate] = field(default_factory=list)
    success: bool = False
    status: int = -1
    message: str = ""
    iterations: int = 0
    wall_time: float = 0.0
    n_evaluations: int = 0
    n_gradients: int = 0


def check_start(problem: StudyProblem, z: Array, label: str = "initial_lengths") -> None:
    """Raise :class:`InvalidInputError` naming the worst violated constraint at a start point."""
    try:
        ev = problem.evaluate(z)
    except InvalidInputError as error:
        raise start_error(error, label, problem.model) from None
    margins = ev.constraints + problem.clearance
    worst = int(np.argmin(margins))
    if margins[worst] < -START_TOLERANCE:
        raise InvalidInputError(
            f"{label} (constraint {problem.constraint_names[worst]})",
            float(margins[worst]),
            "the start must satisfy every constraint (scaled margin >= 0)",
        )


def start_points(problem: StudyProblem, count: int, seed: int = 6) -> list[DesignValues]:
    """The study's start and ``count - 1`` other feasible starts, drawn in the Xi bounds.

    Per chain: L uniform in its bounds, the retracted length x0 = Lc0 + Lc so that the stroke is
    >= 0 at the low end of the working range and within the stroke at its high end, Lc just
    above the largest stroke; kept when every constraint holds with the inverse-kinematics
    coefficients. A crane file's draw (its triangle trigonometry); a machine file's study has none
    (:func:`hiab_sim.study.solvers.feasibility.feasible_points` draws its starts uniformly).

    Raises:
        InvalidInputError: too few feasible starts, or a machine file's study (field ``starts``).

    """
    from hiab_sim.crane import mechanism

    if problem.study.crane_description is None:
        raise InvalidInputError("starts", count, "the solver's own draw of starts needs a crane file")
    low, up = np.asarray(problem.study.bounds.xi_low), np.asarray(problem.study.bounds.xi_up)
    starts = [problem.study.initial_lengths]
    rng = np.random.default_rng(seed)
    for _ in range(2000):
        if len(starts) >= count:
            break
        xi = np.zeros(6)
        for j, chain in enumerate(problem.study.crane.chains):
            L = rng.uniform(low[3 * j], up[3 * j])
            lo, hi = problem.working[j]
            q = mechanism.hinge_angle(chain, np.array([lo, hi]))
            s_lo, s_hi = mechanism.stroke_from_hinge_angle(q, L, chain.L1, 0.0)
            slack = chain.stroke - (s_hi - s_lo)
            if slack <= 0.0:
                continue
            x0 = s_lo - rng.uniform(0.0, 0.5) * slack
            Lc = max(low[3 * j + 2], s_hi - x0) + rng.uniform(0.0, 0.05)
            xi[3 * j : 3 * j + 3] = (L, x0 - Lc, Lc)
        if np.any(xi == 0.0) or np.any(xi < low) or np.any(xi > up):
            continue
        lengths = LinkLengths.from_array(xi)
        try:
            if problem.margins(problem.initial_point(lengths)).min() >= 0.0:
                starts.append(lengths)
        except InvalidInputError:
            continue
    if len(starts) < count:
        raise InvalidInputError("starts", count, f"only {len(starts)} feasible starts found in the bounds")
    return starts


def _checkpoint_path(out: Path, start: int) -> Path:
    return out / f"checkpoint_{start}.json"


def study_digest(problem: StudyProblem) -> str:
    """SHA-256 of the study's content: every setting, the crane and the EMLA set.

    The file path is recorded separately, and ``solver.maxiter`` is left out: it is the run's
    iteration budget, not part of the problem, and resuming a run that hit it with a larger one is
    what ``--resume`` is for.
    """
    study = problem.study
    content = replace(study, path="", solver=replace(study.solver, maxiter=1))  # any fixed value
    described = study.crane_description if study.crane_description is not None else study.machine
    text = "\n".join((repr(content), repr(described), repr(problem.emlas)))
    return hashlib.sha256(text.encode()).hexdigest()


def checkpoint_identity(problem: StudyProblem, initial: DesignValues) -> dict[str, Any]:
    """What a checkpoint belongs to: study path and content hash, ID path, start Xi [m]."""
    return {
        "study": str(Path(problem.study.path).resolve()),
        "study_sha256": study_digest(problem),
        "id_path": problem.id_path,
        "initial_xi": initial.as_array().tolist(),
    }


def check_checkpoint(problem: StudyProblem, initial: DesignValues, out: Path, start: int) -> dict[str, Any] | None:
    """The checkpoint of a start if it belongs to this run, None if there is none.

    Raises:
        InvalidInputError: The checkpoint was written for another study, ID path or start,
            named by the first field that differs (``--resume (checkpoint_<k>.json <field>)``).

    """
    data = load_checkpoint(out, start)
    if data is None:
        return None
    name = _checkpoint_path(out, start).name
    for key, expected in checkpoint_identity(problem, initial).items():
        found = data.get(key)
        if found != expected:
            raise InvalidInputError(
                f"--resume ({name} {key})",
                "missing" if found is None else found,
                f"the checkpoint belongs to another run; this run has {key} = {expected} "
                "(run without --resume to start afresh)",
            )
    return data


def remove_checkpoints(out: Path) -> list[Path]:
    """Delete the ``checkpoint_*.json`` files of earlier runs in ``out``; return them."""
    removed = sorted(out.glob("checkpoint_*.json")) if out.is_dir() else []
    for path in removed:
        path.unlink(missing_ok=True)
    return removed


def _save_checkpoint(out: Path, result: SolveResult, z: Array, done: bool, identity: dict[str, Any]) -> None:
    data = {
        **identity,
        "start": result.start,
        "initial_xi": result.initial_lengths.as_array().tolist(),
        "z0": result.z0.tolist(),
        "z": np.asarray(z).tolist(),
        "history": [vars(h) for h in result.history],
        "done": done,
        "success": result.success,
        "status": result.status,
        "message": result.message,
        "wall_time": result.wall_time,
    }
    write_atomic(_checkpoint_path(out, result.start), json.dumps(data))


def load_checkpoint(out: Path, start: int) -> dict[str, Any] | None:
    """The checkpoint of a start, or None."""
    path = _checkpoint_path(out, start)
    if not path.is_file():
        return None
    try:
        data: dict[str, Any] = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    return data


def solve(
    problem: StudyProblem,
    initial: DesignValues,
    start: int = 0,
    out: Path | None = None,
    resume: bool = False,
    progress: TextIO | None = sys.stderr,
    maxiter: int | None = None,
    use_gradients: bool = True,
    on_iterate: Callable[[Iterate], None] | None = None,
    z0: Array | None = None,
) -> SolveResult:
    """Solve the NLP from ``initial`` with SLSQP; checkpoint into ``out`` after every iteration.

    Args:
        problem: The scaled NLP.
        initial: Start link lengths (coefficients from inverse kinematics).
        start: Index of this start (names its checkpoint).
        out: Output folder for checkpoints, or None.
        resume: Continue from ``out``'s checkpoint of this start if there is one (it must belong
            to this study, ID path and start: :func:`check_checkpoint`).
        progress: Stream for one line per iteration, or None (quiet).
        maxiter: Iteration limit (default: the study's).
        use_gradients: False uses scipy's finite-difference jacobians (the benchmark's baseline).
        on_iterate: Called with each new history row.
        z0: Start point (default: ``initial`` with the inverse-kinematics coefficients), e.g. the
            point of the feasibility phase (:mod:`hiab_sim.study.solvers.feasibility`).

    Raises:
        InvalidInputError: The start violates a constraint (named), or the checkpoint to resume
            from belongs to another run.
        SolverError: SLSQP did not report success; the checkpoint keeps the partial history.

    """
    z0 = problem.initial_point(initial) if z0 is None else np.asarray(z0, dtype=float)
    check_start(problem, z0)
    result = SolveResult(start=start, initial_lengths=initial, z0=z0, z=z0.copy())
    identity = checkpoint_identity(problem, initial)
    z_begin = z0
    previous_wall = 0.0
    if resume and out is not None:
        data = check_checkpoint(problem, initial, out, start)
        if data is not None:
            result.history = [Iterate(**h) for h in data["history"]]
            z_begin = np.asarray(data["z"], dtype=float)
            previous_wall = float(data.get("wall_time", 0.0))
            if data.get("done"):
                result.z = z_begin
                result.success, result.status, result.message = data["success"], data["status"], data["message"]
                result.iterations = len(result.history) - 1
                result.wall_time = previous_wall
                return result
    limit = maxiter or problem.study.solver.maxiter
    limit = max(1, limit - max(0, len(result.history) - 1))
    t0 = time.perf_counter()

    def record(z: Array) -> None:
        ev = problem.evaluate(z)
        row = Iterate(
            iteration=len(result.history),
            cost=ev.cost,
            scaled_cost=ev.cost / problem.cost_scale,
            max_violation=problem.max_violation(z),
            xi=ev.lengths.as_array().tolist(),
            wall_time=previous_wall + time.perf_counter() - t0,
        )
        result.history.append(row)
        result.z = np.array(z, dtype=float)
        result.wall_time = row.wall_time
        if out is not None:
            _save_checkpoint(out, result, z, done=False, identity=identity)
        if progress is not None:
            xi = " ".join(f"{v:.4f}" for v in row.xi)
            progress.write(
                f"[start {start}] iter {row.iteration:3d}  cost {row.cost:.6e} {problem.objective.unit} "
                f"({row.scaled_cost:.6f})"
                f"  viol {row.max_violation:.1e}  Xi [{xi}] m  {row.wall_time:.1f} s\n"
            )
            progress.flush()
        if on_iterate is not None:
            on_iterate(row)

    if not result.history:
        record(z_begin)
    try:
        outcome = solve_once(
            problem, z_begin, limit, problem.study.solver.ftol, callback=record, use_gradients=use_gradients
        )
    except InvalidInputError as error:
        result.message = f"a trial point left the model's domain: {error}"
        if out is not None:
            _save_checkpoint(out, result, result.z, done=False, identity=identity)
        raise SolverError(f"start {start}: {result.message} (partial history kept)") from error
    result.z, result.success, result.status, result.message = (
        outcome.z,
        outcome.success,
        outcome.status,
        outcome.message,
    )
    result.iterations = len(result.history) - 1
    result.wall_time = previous_wall + time.perf_counter() - t0
    result.n_evaluations = problem.n_evaluations
    result.n_gradients = problem.n_gradients
    if result.history and not np.array_equal(np.asarray(result.history[-1].xi), problem.unpack(result.z)[0].as_array()):
        record(result.z)
        result.iterations = len(result.history) - 1
    if out is not None:
        _save_checkpoint(out, result, result.z, done=result.success, identity=identity)
    if not result.success:
        raise SolverError(
            f"start {start}: {problem.study.solver.method.upper()} status {result.status}: {result.message} "
            f"after {result.iterations} iterations "
            "(partial history kept in the output folder)"
        )
    return result


def xi_table(lengths: DesignValues) -> dict[str, Any]:
    """A crane's {"lift": {"L":..,"Lc0":..,"Lc":..}, "tilt": {...}}, a machine file's {"chain.variable": value} [m]."""
    if isinstance(lengths, MachineDesign):
        return dict(zip(lengths.names, map(float, lengths.values), strict=True))
    return {name: {k: float(getattr(getattr(lengths, name), k)) for k in ("L", "Lc0", "Lc")} for name in CHAIN_NAMES}
