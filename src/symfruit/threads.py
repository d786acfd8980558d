"""numpy's BLAS (and OpenMP) on one thread in a worker process: as many workers as cores run as many threads.

A worker process forked after numpy is loaded keeps the BLAS threads numpy's OpenBLAS started with (one per core;
``OPENBLAS_NUM_THREADS`` set after the fork no longer reaches it), and so does a Dask worker started without a
nanny (``dask worker --no-nanny``; a nanny sets the variables before its worker starts): two workers on two cores
ran four BLAS threads, 10 % slower in the evaluation (stop 52) and 1.1-1.6x the CPU in ``detect
--scheduler`` (robust53; README "Speed")."""

from __future__ import annotations

import os

__all__ = ["one_blas_thread"]


def one_blas_thread() -> None:
    """Limit this process's BLAS and OpenMP to one thread: the variables for what it loads from now on, and
    numpy's OpenBLAS, already loaded, by threadpoolctl (the ``fast`` extra; without it, the variables alone)."""
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)
