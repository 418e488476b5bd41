"""What one solve returned, whichever solver ran it (SLSQP through scipy, IPOPT through CasADi)."""

from __future__ import annotations

from dataclasses import dataclass

from hiab_sim.arrays import Array


@dataclass(frozen=True)
class Outcome:
    """The point (scaled z), success, status (0 success; SLSQP's code, IPOPT 1 on failure), message, iterations."""

    z: Array
    success: bool
    status: int
    message: str
    iterations: int
