"""The one list of the NLP's constraint blocks: named factories, each building a task's blocks from its problem.

:class:`~hiab_sim.study.nlp.task_problem.TaskProblem` builds its rows by calling every factory of
:data:`BLOCKS` in registration order with itself (its study, task, grid, reference, EMLA set and
working range are attributes) and concatenating what they return; row names, row layout,
clearances, the Jacobian, the IPOPT sparsity, the stacking of several tasks and the sensitivities
follow from that list. The built-in blocks (tracking bands, EMLA envelope, strokes, joints, joint
velocity, working range, thermal limits, buildable range and mounting space) are registered by
:mod:`hiab_sim.study.nlp.task_problem`; a new block is one module plus :func:`register_block`
(docs/extending.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from hiab_sim.errors import InvalidInputError
from hiab_sim.study.nlp.interface import ConstraintBlock

#: Builds a task's blocks of one kind from its :class:`~hiab_sim.study.nlp.task_problem.TaskProblem`
#: (typed ``Any`` here: the problem module imports this one), none where the study does not ask for them.
BlockFactory = Callable[[Any], Sequence[ConstraintBlock]]

#: Block factories by name, in row order.
BLOCKS: dict[str, BlockFactory] = {}


def register_block(name: str, factory: BlockFactory) -> None:
    """Add a factory of constraint blocks after the registered ones (its rows follow theirs)."""
    if name in BLOCKS:
        raise InvalidInputError("constraint block", name, f"already registered; registered: {', '.join(BLOCKS)}")
    BLOCKS[name] = factory


def unregister_block(name: str) -> None:
    """Remove a registered factory (problems built afterwards no longer have its rows)."""
    if name not in BLOCKS:
        raise InvalidInputError("constraint block", name, f"not registered; registered: {', '.join(BLOCKS)}")
    del BLOCKS[name]


def build_blocks(problem: Any) -> list[ConstraintBlock]:
    """Every registered factory's blocks for ``problem``, in registration order."""
    return [block for factory in BLOCKS.values() for block in factory(problem)]
