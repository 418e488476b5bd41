"""Pin forces computed when first read: what the Newton-Euler path returns as ``pins``.

The forces through every joint and pin of T samples (:class:`~hiab_sim.machine.dynamics.tree.PinForces`,
5 numbers per pin and sample) are several times the size of the actuator forces an optimiser
asks for; :class:`DeferredPinForces` computes them on first use of ``world`` or ``local``.
"""

from __future__ import annotations

from collections.abc import Callable

from hiab_sim.arrays import Array
from hiab_sim.machine.dynamics.tree import PinForces


class DeferredPinForces(PinForces):
    """:class:`PinForces` whose ``world`` and ``local`` arrays are computed on first use, then kept.

    For callers that need only the actuator forces (an optimiser): the pin forces of T samples
    are several times the size of the actuator forces. ``compute`` returns (world, local); a
    pickled copy carries the computed arrays as a plain :class:`PinForces`.
    """

    def __init__(
        self,
        names: tuple[str, ...],
        kinds: tuple[str, ...],
        on: tuple[str, ...],
        by: tuple[str, ...],
        compute: Callable[[], tuple[Array, Array]],
    ) -> None:
        for key, value in (("names", names), ("kinds", kinds), ("on", on), ("by", by)):
            object.__setattr__(self, key, value)
        object.__setattr__(self, "_compute", compute)
        object.__setattr__(self, "_arrays", None)

    def _computed(self) -> tuple[Array, Array]:
        arrays: tuple[Array, Array] | None = self.__dict__["_arrays"]
        if arrays is None:
            arrays = self.__dict__["_compute"]()
            object.__setattr__(self, "_arrays", arrays)
            object.__setattr__(self, "_compute", None)  # let go of what it held
        return arrays

    @property
    def world(self) -> Array:
        """World force (T, P, 2) [N] (see :class:`PinForces`)."""
        return self._computed()[0]

    @property
    def local(self) -> Array:
        """Body-frame force (T, P, 3) [N] (see :class:`PinForces`)."""
        return self._computed()[1]

    def __reduce__(self) -> tuple[type, tuple[object, ...]]:
        return PinForces, (self.names, self.kinds, self.on, self.by, self.world, self.local)
