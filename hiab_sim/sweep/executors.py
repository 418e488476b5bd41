"""Executors for sweep points: local processes (default) or a Dask cluster, both ``concurrent.futures``."""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

from hiab_sim.errors import BackendUnavailableError, ConfigError, InvalidInputError

#: Environment of a local worker: one BLAS/OpenMP thread per process, as Dask's nanny sets for its
#: workers (``distributed.nanny.pre-spawn-environ``); the worker processes are the parallelism, and
#: threaded BLAS on the optimiser's small matrices only oversubscribes the cores.
SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


@contextmanager
def make_executor(workers: int | None = None, dask: str | None = None) -> Iterator[Executor]:
    """A ``concurrent.futures`` executor, shut down on exit.

    Args:
        workers: Local worker processes (``spawn``: no state shared with the parent; one BLAS thread
            each, :data:`SINGLE_THREADED`), default 1.
        dask: Address of a Dask scheduler (``tcp://HOST:PORT``): points run on its workers through
            ``distributed.Client(address).get_executor()``. The workers need hiab-sim installed and
            must see the study's crane and EMLA files (shipped presets always resolve).

    """
    if dask is not None:
        if workers is not None:
            raise InvalidInputError(
                "--workers", workers, "cannot be combined with --dask (the cluster has its workers)"
            )
        try:
            from distributed import Client
        except ImportError:
            raise BackendUnavailableError("--dask needs dask.distributed: pip install 'hiab-sim[dask]'") from None
        try:
            client = Client(dask, timeout="10s")
        except (OSError, TimeoutError) as error:
            raise ConfigError(f"--dask {dask}: no Dask scheduler reachable there ({error})") from None
        try:
            yield client.get_executor(pure=False)
        finally:
            client.close()
        return
    count = 1 if workers is None else workers
    if count < 1:
        raise InvalidInputError("--workers", count, "must be >= 1")
    saved = {key: os.environ.get(key) for key in SINGLE_THREADED}
    os.environ.update(SINGLE_THREADED)  # inherited by the workers, spawned on the first submit
    pool = ProcessPoolExecutor(max_workers=count, mp_context=multiprocessing.get_context("spawn"))
    try:
        yield pool
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
