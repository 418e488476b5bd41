"""The mounting space as NLP rows: base pivots inside their polygons and clear of pins and booms (Xi only).

Rows are :func:`hiab_sim.crane.mounting.mounting_margins` [m] (polygons, then clearances) divided
by :data:`MOUNTING_SCALE`; they depend on the two L's only, so the Jacobian is ``DenseRows(dxi=...)``.
The problem wraps the block in :class:`hiab_sim.study.analysis.buildable.RobustXi`, so the polygons (linear in
L) hold exactly for every design within the manufacturing tolerance.
"""

from __future__ import annotations

from collections.abc import Hashable

from hiab_sim.crane.description import Crane
from hiab_sim.crane.mounting import MountingSpace, mounting_margins
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.study.nlp.interface import Array, ConstraintBlock, DenseRows, Relaxation, SamplePartials, SampleState

#: Scale of the mounting rows [m per unit].
MOUNTING_SCALE = 0.1


class MountingRows(ConstraintBlock):
    """Signed distance of each base pivot to its polygon's edges and pin / boom clearances, scaled.

    Args:
        space: the polygons and the pin clearance.
        crane: the crane (boom hinges, booms and the working joint range swept for the boom clearance).
        clearance: scaled margin the optimiser's rows keep (added back in the nominal margins).

    """

    def __init__(self, space: MountingSpace, crane: Crane, clearance: float = 0.0) -> None:
        self.name = "mounting"
        self._clearance = clearance
        self.space = space
        self.crane = crane
        self._names = list(mounting_margins(space, crane, crane.default_lengths).names)

    def row_names(self) -> list[str]:
        """``mounting.<chain> base pivot inside edge <i>`` and ``... clear of the <pin or boom>``."""
        return list(self._names)

    def values(self, state: SampleState) -> Array:
        """Margins [m] / MOUNTING_SCALE."""
        return (
            mounting_margins(self.space, self.crane, crane_lengths(state.lengths)).values / MOUNTING_SCALE
            - self._clearance
        )

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """Exact dg/dXi [per m] / MOUNTING_SCALE (rows of Xi only)."""
        return DenseRows(
            dxi=mounting_margins(self.space, self.crane, crane_lengths(state.lengths)).jacobian / MOUNTING_SCALE
        )

    def clearance(self) -> float:
        """The optimiser's clearance (scaled)."""
        return self._clearance

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of a polygon edge or clearance: 1e-3 / MOUNTING_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / MOUNTING_SCALE, len(values))

    def shared_key(self) -> Hashable:
        """Rows of Xi only: the same for every task of one study (its mounting space and crane)."""
        return (self.name, repr(self.space), repr(self.crane), self._clearance)
