"""One BLAS thread while a solver runs: the NLP's linear algebra is small, pooled threads only contend.

The study's evaluations (inverse dynamics over K samples, spline products, a cyclic winding-temperature
solve per drive) and SLSQP's least-squares subproblem call numpy's and scipy's OpenBLAS on matrices of
a few hundred rows. With a pool of one thread per core, OpenBLAS's threads spin-wait between calls;
on a 2-core machine shared with anything else (a test run's two workers, a sweep) they spin against
the other processes and every call waits for a time slice. Measured on the digging study
(``exact_digging``, 12 SLSQP iterations, the 2-core machine with a test run beside it): 48-56 s with
the default pool, 8.5-8.9 s with one thread (``benchmarks/bench_solver_threads.py`` measures both in
one process). One thread also makes the iterates independent of the machine's core count (the
pool's size changes BLAS's summation order in the last bits).

CasADi's wheels ship their own OpenBLAS (under MUMPS, IPOPT's linear solver) under a name threadpoolctl
does not know; :func:`register_casadi_blas` (called when the IPOPT backend loads CasADi) lets it limit
that one too, so IPOPT's iterates no longer depend on the core count either (with its default pool the
digging study took 168 iterations here and 131 with one thread; the XS 031 duty mix 124 and 181).
"""

from __future__ import annotations

import functools
from contextlib import AbstractContextManager

from threadpoolctl import OpenBLASController, register, threadpool_limits


def single_blas_thread() -> AbstractContextManager[object]:
    """Limit every loaded BLAS (numpy's, scipy's, CasADi's once registered) to one thread inside a ``with`` block."""
    return threadpool_limits(limits=1, user_api="blas")


class _CasadiOpenBLAS(OpenBLASController):
    """CasADi's bundled OpenBLAS (``libcasadi-tp-openblas``): the OpenBLAS API under CasADi's file name."""

    filename_prefixes = ("libcasadi-tp-openblas",)


@functools.cache
def register_casadi_blas() -> None:
    """Let threadpoolctl find and limit CasADi's OpenBLAS (once per process)."""
    register(_CasadiOpenBLAS)
