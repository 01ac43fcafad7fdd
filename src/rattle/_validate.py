"""Argument checks shared by the front ends (the messages name the argument in backticks).

The type rules are the same for the library's arguments and the configuration file's values:
numbers may be Python or numpy scalars (``np.int64(8)``, ``np.float32(0.5)``); booleans,
strings and None are refused where a number is expected; every real number must be finite.
The size bounds are in :mod:`rattle._limits`. numpy is imported only when a state is checked,
so the command line can check its options before the numerics are loaded.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from numbers import Integral, Real
from typing import Any, TypeVar

_F = TypeVar("_F", bound=Callable[..., Any])


def _is_bool(value: object) -> bool:
    return isinstance(value, bool) or type(value).__name__ == "bool_"


def show(value: object) -> str:
    """``repr(value)``, with integers of more than 20 digits shortened (1e400 has 401)."""
    text = repr(value)
    if isinstance(value, Integral) and len(text) > 20:
        digits = len(str(abs(int(value))))
        text = f"{str(value)[:5]}… (an integer of {digits} digits)"
    return text


def check_real(value: object, name: str) -> float:
    """A real number (int, float or numpy scalar; not a bool or a string), finite."""
    if _is_bool(value) or not isinstance(value, Real):
        raise TypeError(f"`{name}` must be a real number, got {value!r} ({type(value).__name__})")
    try:
        x = float(value)
    except OverflowError:  # an int beyond the float range
        raise ValueError(f"`{name}` must be a finite number, got {show(value)} (beyond the floating-point range)") from None
    if not math.isfinite(x):
        raise ValueError(f"`{name}` must be finite, got {value!r}")
    return x


def check_positive(value: object, name: str) -> float:
    """A real number (not a bool or a string), finite and > 0."""
    if _is_bool(value) or not isinstance(value, Real):
        raise TypeError(f"`{name}` must be a real number, got {value!r} ({type(value).__name__})")
    try:
        x = float(value)
    except OverflowError:  # an int beyond the float range
        x = math.inf
    if not (math.isfinite(x) and x > 0.0):
        raise ValueError(f"`{name}` must be a finite number > 0, got {x!r}")
    return x


def check_omega(value: object, name: str = "omega") -> float:
    """A forcing frequency: a real number, finite and > 0 (rad/s)."""
    if _is_bool(value) or not isinstance(value, Real):
        raise TypeError(f"`{name}` must be a forcing frequency in rad/s (a number), got {value!r}")
    try:
        w = float(value)
    except OverflowError:
        w = math.inf
    if not (math.isfinite(w) and w > 0.0):
        raise ValueError(f"`{name}` must be a finite forcing frequency > 0 rad/s, got {show(value)}; use e.g. 0.8")
    return w


def check_vector(value: object, name: str) -> Any:
    """A read-only copy of ``value`` as a one-dimensional array of finite floats (a table column)."""
    import numpy as np

    arr = np.array(as_float_array(value, name, "a sequence of numbers"), dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"`{name}` must be one-dimensional, got shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"`{name}` must hold finite numbers, got {arr[bad[0]]!r} at row {int(bad[0])}")
    arr.setflags(write=False)
    return arr


def check_shooting(period: object, tol: object, max_iterations: object) -> tuple[int, float, int]:
    """The arguments every Newton shooting takes: ``period`` an integer >= 1 (forcing periods),
    ``tol`` a number > 0, ``max_iterations`` an integer >= 0."""
    if isinstance(period, bool) or not isinstance(period, Integral) or period < 1:
        raise ValueError(f"`period` must be an integer >= 1, got {period!r}")
    if isinstance(tol, bool) or not (isinstance(tol, (int, float)) and tol > 0.0):
        raise ValueError(f"`tol` must be a positive number, got {tol!r}")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, Integral) or max_iterations < 0:
        raise ValueError(f"`max_iterations` must be an integer >= 0, got {max_iterations!r}")
    return int(period), float(tol), int(max_iterations)


def check_range(omega: object, name: str = "omega") -> tuple[float, float]:
    """A frequency range (min, max) in rad/s: two finite numbers, 0 < min < max."""
    if isinstance(omega, (str, bytes)) or not hasattr(omega, "__iter__") or hasattr(omega, "items"):
        raise TypeError(f"`{name}` must be a pair (min, max) of frequencies in rad/s, got {omega!r}")
    if isinstance(omega, (set, frozenset)):  # no order: which is min and which max would be chance
        raise TypeError(f"`{name}` must be a pair (min, max) of frequencies in rad/s, got the set {omega!r}, which "
                        "has no order; give a tuple such as (0.5, 0.8)")
    values = list(omega)  # type: ignore[call-overload]
    if len(values) != 2:
        raise ValueError(
            f"`{name}` must be a pair (min, max) of frequencies in rad/s, got {omega!r} ({len(values)} values)"
        )
    for v in values:
        if _is_bool(v) or not isinstance(v, Real):
            raise TypeError(f"`{name}` must be a pair (min, max) of numbers (rad/s), got {omega!r}")
    lo, hi = (check_real(v, name) for v in values)
    if not 0 < lo < hi:
        raise ValueError(f"`{name}` must satisfy 0 < min < max, got ({lo}, {hi}); give the range as (min, max) rad/s")
    return lo, hi


def as_float_array(value: object, name: str, what: str) -> Any:
    """``value`` as a float array; a string, or what numpy cannot read as numbers, is a
    TypeError "`name` must be <what>, got …"."""
    import numpy as np

    if isinstance(value, (str, bytes)):
        raise TypeError(f"`{name}` must be {what}, got {value!r}")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise TypeError(f"`{name}` must be {what}, got {value!r}") from None


def check_state(value: object, name: str = "x0") -> Any:
    """A state (δ, δ') of shape (2,), finite."""
    import numpy as np

    x = as_float_array(value, name, "a state (delta, velocity) of two numbers")
    if x.shape != (2,) or not np.all(np.isfinite(x)):
        raise ValueError(f"`{name}` must be a finite state (delta, velocity) of shape (2,), got {value!r}")
    return x


def check_int(name: str, value: object, low: int) -> int:
    """An integer (Python or numpy; not a bool) >= ``low``."""
    if _is_bool(value) or not isinstance(value, Integral):
        raise TypeError(f"`{name}` must be an integer, got {value!r} ({type(value).__name__})")
    if value < low:
        raise ValueError(f"`{name}` must be >= {low}, got {show(value)}")
    return int(value)


def check_bool(value: object, name: str) -> bool:
    """True or False (numpy booleans accepted)."""
    if not _is_bool(value):
        raise TypeError(f"`{name}` must be True or False, got {value!r} ({type(value).__name__})")
    return bool(value)


def check_choice(value: object, name: str, choices: tuple[str, ...]) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str) or value not in choices:
        allowed = " or ".join(repr(c) for c in choices) if len(choices) == 2 else \
            "one of " + ", ".join(repr(c) for c in choices)
        raise ValueError(f"`{name}` must be {allowed}, got {value!r}")
    return value


def check_instance(value: object, name: str, cls: type, what: str, optional: bool = True) -> Any:
    """``value`` is an instance of ``cls`` (or None when ``optional``)."""
    if value is None and optional:
        return None
    if not isinstance(value, cls):
        raise TypeError(f"`{name}` must be {what}{' or None' if optional else ''}, got {value!r} ({type(value).__name__})")
    return value


def numerical_failures(func: _F) -> _F:
    """Decorator of the analysis front ends: an OverflowError or FloatingPointError raised in
    the numerics (values beyond double precision, despite the magnitude bounds of
    :mod:`rattle._limits`) becomes a :class:`~rattle.errors.ConvergenceError` (a clear numerical
    failure, command-line exit status 1) naming the front end, instead of a raw traceback."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except (OverflowError, FloatingPointError) as exc:
            from .errors import ConvergenceError

            raise ConvergenceError(
                f"numerical failure in {func.__name__}: {exc} ({type(exc).__name__}): values beyond the "
                "range of double precision appeared; choose units in which the model's numbers are moderate "
                "(damping, stiffness and forcing within a few orders of magnitude of each other)"
            ) from exc

    return wrapper  # type: ignore[return-value]


__all__ = ["numerical_failures", "show", "check_real", "check_omega", "check_shooting", "check_vector", "check_range", "check_state", "as_float_array", "check_int", "check_bool", "check_choice",
           "check_instance"]


#: Largest time history drawn from harmonic-balance coefficients, as samples × (2H + 1) numbers
#: (the synthesis matrix of one array): 2**25 doubles are 256 MiB.
MAX_HISTORY_CELLS = 1 << 25


def check_history_size(samples: object, periods: object, harmonics: int, periods_name: str = "periods") -> tuple[int, int]:
    """``samples`` (per period, an integer >= 2) and ``periods`` (an integer >= 1) of a time
    history synthesised from ``harmonics`` harmonics, refused (ValueError/TypeError naming the
    argument) before anything is allocated when samples · periods · (2H + 1) exceeds
    :data:`MAX_HISTORY_CELLS`."""
    import numpy as np

    for name, value, low in (("samples", samples, 2), (periods_name, periods, 1)):
        if _is_bool(value) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"`{name}` must be an integer, got {show(value)} ({type(value).__name__})")
        if value < low:
            raise ValueError(f"`{name}` must be an integer >= {low}, got {show(value)}")
    n, p = int(samples), int(periods)  # type: ignore[arg-type]
    cells = (n * p + 1) * (2 * max(int(harmonics), 0) + 1)
    if cells > MAX_HISTORY_CELLS:
        most = max(2, MAX_HISTORY_CELLS // ((2 * max(int(harmonics), 0) + 1) * p))
        raise ValueError(
            f"`samples` × `{periods_name}` = {show(n)} × {show(p)} time samples of {harmonics} harmonics would need "
            f"{cells:.3g} numbers, more than the limit of {MAX_HISTORY_CELLS} (256 MiB); use `samples` <= {most}"
        )
    return n, p
