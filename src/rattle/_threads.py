"""BLAS threads for rattle's small dense problems.

The exact flows multiply and exponentiate matrices of a few to a few dozen rows (stage transition
matrices, saltation matrices, the scipy ``expm`` of a stuck mode's augmented matrix), thousands of
times per branch. A multi-threaded BLAS spends more on waking and synchronising its threads than
on such a product, and far more when the cores are busy with other work: measured on a 3-inertia
chain with friction (``examples/chain_clutch_friction.toml``, Ω 0.4–0.5 by exact shooting
continuation) on this 2-core machine under load, 142 s with OpenBLAS's two threads against 15 s
with one (scipy's Padé step of ``expm``: 96 s against < 1 s). :func:`one_blas_thread` runs a
computation with BLAS (and OpenMP) limited to one thread and restores the previous limits after
(``threadpoolctl``, which acts on the loaded BLAS libraries at run time: also inside a notebook
whose numpy was imported long before).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the body with BLAS and OpenMP limited to one thread (module docstring)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        yield


__all__ = ["one_blas_thread"]
