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

CasADi's own OpenBLAS under IPOPT's MUMPS is not limited: threadpoolctl does not find it under its
name, and IPOPT's iterates on the shipped XS 031 duty mix depend on it (docs/results/excavator.md).
"""

from __future__ import annotations

from contextlib import AbstractContextManager

from threadpoolctl import threadpool_limits


def single_blas_thread() -> AbstractContextManager[object]:
    """Limit numpy's and scipy's BLAS to one thread inside a ``with`` block (restored after it)."""
    return threadpool_limits(limits=1, user_api="blas")
