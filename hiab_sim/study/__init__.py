"""The study: B-spline trajectories, spiral reference, the NLP of eq. costf2, the SQP driver and reports.

Public API:

* :func:`~hiab_sim.study.config.load_study` -> :class:`~hiab_sim.study.config.Study`;
* :class:`~hiab_sim.study.problem.LinkLengthProblem` (cost, constraints, exact gradients);
* :func:`~hiab_sim.study.solve.solve` (SLSQP, history, checkpoints, resume) and
  :func:`~hiab_sim.study.run.run_study` (a whole run into a result folder);
* trajectory pieces in :mod:`hiab_sim.study.trajectory`, crane scaling in :mod:`hiab_sim.study.scaling`.
"""

from __future__ import annotations

from hiab_sim.study.config import DEFAULT_STUDY, Study, load_study, study_from_dict
from hiab_sim.study.problem import LinkLengthProblem
from hiab_sim.study.run import RunOutput, run_study
from hiab_sim.study.solve import SolveResult, solve

__all__ = [
    "DEFAULT_STUDY",
    "LinkLengthProblem",
    "RunOutput",
    "SolveResult",
    "Study",
    "load_study",
    "run_study",
    "solve",
    "study_from_dict",
]
