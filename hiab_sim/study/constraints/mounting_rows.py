"""The mounting space as NLP rows: moved pivots inside their polygons and clear of pins and swept links (Xi only).

Rows are the study's mounting margins [m] (polygons, then clearances) divided by
:data:`MOUNTING_SCALE`: :func:`hiab_sim.crane.mounting.mounting_margins` for a crane file's study
(its two base pivots), :func:`hiab_sim.machine.mounting.machine_mounting_margins` for a machine
file's (every pivot a decision variable moves). They depend on the decision variables only, so the
Jacobian is ``DenseRows(dxi=...)``. The problem wraps the block in
:class:`hiab_sim.study.analysis.buildable.RobustXi`, so the polygons (linear in Xi) hold exactly
for every design within the manufacturing tolerance.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, Any

from hiab_sim.arrays import Array
from hiab_sim.crane.mounting import MountingSpace, mounting_margins
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.mounting import MachineMountingSpace, machine_mounting_margins
from hiab_sim.machine.mounting_geometry import Margins
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.study.nlp.interface import ConstraintBlock, DenseRows, Relaxation, SamplePartials, SampleState

if TYPE_CHECKING:
    from hiab_sim.study.spec.study import Study

#: Scale of the mounting rows [m per unit].
MOUNTING_SCALE = 0.1


def study_mounting_margins(study: Study) -> Callable[[Any], Margins] | None:
    """The study's mounting margins as a function of a design (None when the study has no ``mounting``)."""
    space = study.mounting
    if space is None:
        return None
    if isinstance(space, MachineMountingSpace):
        machine = study.machine
        assert machine is not None  # the machine form's loader builds it from the study's machine
        return lambda design: machine_mounting_margins(space, machine, design.as_array())
    assert isinstance(space, MountingSpace)
    crane = study.crane
    return lambda design: mounting_margins(space, crane, crane_lengths(design))


class MountingRows(ConstraintBlock):
    """Signed distance of each moved pivot to its polygon's edges and pin / swept-link clearances, scaled.

    Args:
        study: the study (its ``mounting`` space and its crane or machine).
        clearance: scaled margin the optimiser's rows keep (added back in the nominal margins).

    """

    def __init__(self, study: Study, clearance: float = 0.0) -> None:
        margins = study_mounting_margins(study)
        if margins is None:
            raise InvalidInputError("mounting", "none", "the mounting rows need a study with a mounting section")
        self.name = "mounting"
        self._clearance = clearance
        self._margins = margins
        self._key = (repr(study.mounting), repr(study.crane_description), repr(study.machine))
        self._names = list(margins(study.initial_lengths).names)

    def row_names(self) -> list[str]:
        """``mounting.<chain> <pivot> pivot inside edge <i>`` and ``... clear of the <pin or link>``."""
        return list(self._names)

    def values(self, state: SampleState) -> Array:
        """Margins [m] / MOUNTING_SCALE."""
        return self._margins(state.lengths).values / MOUNTING_SCALE - self._clearance

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """Exact dg/dXi [per m] / MOUNTING_SCALE (rows of Xi only)."""
        return DenseRows(dxi=self._margins(state.lengths).jacobian / MOUNTING_SCALE)

    def clearance(self) -> float:
        """The optimiser's clearance (scaled)."""
        return self._clearance

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of a polygon edge or clearance: 1e-3 / MOUNTING_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / MOUNTING_SCALE, len(values))

    def shared_key(self) -> Hashable:
        """Rows of Xi only: the same for every task of one study (its mounting space and machine)."""
        return (self.name, *self._key, self._clearance)
