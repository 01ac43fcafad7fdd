"""How rattle compiles its kernels (numba), and how the command line loads them from numba's cache.

:func:`njit` is the one compile setting of the kernels: ``numba.njit(cache=True,
error_model="numpy", nogil=True)`` — machine code written to numba's cache at the first call
and read back by later processes; ``numba`` is None when it cannot be imported (the callers then
keep their array code).

Loading a cached kernel (``numba.core.caching.Cache.load_overload``) first calls the CPU target's
``refresh()``, which imports numba's whole lowering library — some thirty modules
(``numba.cpython.setobj``, ``unicode``, ``numba.np.arraymath``, the typed containers …) that only
a *compilation* needs — and initialises numba's reference-counting runtime (NRT), which the
loaded machine code calls. The code loaded needs the runtime only: :func:`load_cached_lightly`
makes the load initialise just that; a kernel that must be compiled still gets the full refresh
(numba's compiler refreshes the contexts itself before it types anything). It is installed in
the command-line process only (the module imports it there when ``rattle …`` runs): a program
that imports rattle keeps numba as it is. Measured (``benchmarks/bench_command.py``, ``rattle frf``
on the reference case, whose four kernels all come from the cache): the computation in the command
0.85 → 0.75 s of CPU, the same frf.csv.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from . import _signals

try:  # numba is a dependency; the callers keep their array code without it
    import numba
except ImportError:  # pragma: no cover - exercised only without numba
    numba = None

#: numba's options for every kernel of rattle.
OPTIONS: dict[str, Any] = {"cache": True, "error_model": "numpy", "nogil": True}


def njit(function: Callable[..., Any]) -> Any:
    """``function`` compiled with :data:`OPTIONS` (a numba dispatcher; compiled at its first
    call, or loaded from numba's cache)."""
    if numba is None:  # pragma: no cover
        raise ImportError("numba is not installed")
    return numba.njit(**OPTIONS)(function)


def load_cached_lightly() -> bool:
    """Make numba's cache loads initialise only its runtime, not its whole lowering library
    (module docstring); True when installed (now or before), False where numba's caching does
    not look as expected (then nothing is changed)."""
    if numba is None:  # pragma: no cover
        return False
    try:
        from numba.core.caching import Cache
        from numba.core.runtime import rtsys
    except ImportError:  # pragma: no cover - a numba without these modules
        return False
    original = Cache.load_overload
    if getattr(original, "rattle_light", False):
        return True
    if not (hasattr(Cache, "_load_overload") and hasattr(Cache, "_guard_against_spurious_io_errors")
            and hasattr(rtsys, "initialize")):  # pragma: no cover - another numba's internals
        return False

    def load_overload(self: Any, sig: Any, target_context: Any) -> Any:
        rtsys.initialize(target_context)  # the runtime the loaded code calls (NRT); idempotent
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    load_overload.rattle_light = True  # type: ignore[attr-defined]
    load_overload.__doc__ = original.__doc__
    Cache.load_overload = load_overload
    return True


if _signals.installed_at_start():  # the command-line process (rattle …, python -m rattle …)
    load_cached_lightly()

__all__ = ["OPTIONS", "njit", "numba", "load_cached_lightly"]
