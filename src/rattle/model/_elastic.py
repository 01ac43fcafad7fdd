"""Elastic laws f(δ): continuous, piecewise linear, f(0) = 0.

Every law is stored as breakpoints d_1 < … < d_k and k + 1 slopes s_0 … s_k (relative to the
stiffness K of the unit-slope stage). On stage j (d_j ≤ δ < d_{j+1}, with d_0 = −∞,
d_{k+1} = +∞)

    f(δ) = s_j δ + e_j,

with offsets e_j fixed by continuity at the breakpoints and by f(0) = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from .._limits import MAX_LIST_LENGTH, check_magnitude, warn_clearance
from .._typing import FloatArray, IntArray


def _check_real(name: str, value: object) -> float:
    """A finite real number (Python or numpy scalar, not a bool) of magnitude <= MAX_MAGNITUDE.

    The same rule as the library's arguments and the configuration file's values
    (:func:`rattle._limits.check_magnitude`)."""
    return check_magnitude(value, name)


def _check_real_sequence(name: str, values: object) -> tuple[float, ...]:
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__") or hasattr(values, "items"):
        raise TypeError(f"`{name}` must be a list of real numbers, got {values!r}")
    values = list(values)  # type: ignore[call-overload]
    if len(values) > MAX_LIST_LENGTH:
        raise ValueError(
            f"`{name}` must hold at most {MAX_LIST_LENGTH} numbers, got {len(values)}: every entry is a stage "
            "or a forcing harmonic the harmonic balance must carry; use fewer"
        )
    return tuple(_check_real(f"{name}[{i}]", v) for i, v in enumerate(values))


@dataclass(frozen=True, slots=True)
class Stages:
    """Breakpoints, slopes and continuity offsets of a piecewise-linear law."""

    breakpoints: FloatArray  # (k,)
    slopes: FloatArray  # (k+1,)
    offsets: FloatArray  # (k+1,)


def _stages(breakpoints: tuple[float, ...], slopes: tuple[float, ...]) -> Stages:
    d = np.asarray(breakpoints, dtype=float)
    s = np.asarray(slopes, dtype=float)
    e = np.zeros_like(s)
    # e_{j+1} = e_j + (s_j − s_{j+1}) d_j (continuity at d_j); then shift so that f(0) = 0.
    for j in range(len(d)):
        e[j + 1] = e[j] + (s[j] - s[j + 1]) * d[j]
    j0 = int(np.searchsorted(d, 0.0, side="right"))
    e -= e[j0]
    for arr in (d, s, e):
        arr.setflags(write=False)
    return Stages(d, s, e)


def check_delta(delta: Any, name: str = "delta") -> Any:
    """``delta`` (rad) for a law's ``force``/``stiffness``: a real number or an array (or
    sequence) of real numbers. A float or integer array and a number pass as they are (the hot
    path of the numerics); a sequence becomes a float array. A string, a boolean, None or what
    is not numbers is refused naming ``name`` and showing the value (TypeError)."""
    if isinstance(delta, np.ndarray):
        if delta.dtype.kind in "fiu":
            return delta
    elif isinstance(delta, (float, int, np.floating, np.integer)) and not isinstance(delta, (bool, np.bool_)):
        return delta
    what = "a deflection in rad: a number or an array of numbers"
    shown = repr(delta) if len(repr(delta)) <= 80 else repr(delta)[:60] + "…"
    if isinstance(delta, (str, bytes, bool, np.bool_)) or delta is None:
        raise TypeError(f"`{name}` must be {what}, got {shown} ({type(delta).__name__})")
    try:
        raw = np.asarray(delta)
    except (TypeError, ValueError):  # ragged nesting
        raise TypeError(f"`{name}` must be {what}, got {shown}") from None
    if raw.dtype.kind not in "fiu":  # booleans, strings, None or other objects among the values
        raise TypeError(f"`{name}` must be {what}, got {shown} ({type(delta).__name__} of {raw.dtype})")
    return raw.astype(float)


class StageLaw:
    """A law f(δ) = s_j δ + e_j on stages d_j ≤ δ < d_{j+1}, read from its ``stages`` (breakpoints,
    slopes, offsets): the continuous laws here and the laws with jumps of
    :mod:`rattle.model._discontinuous` (where f is the right limit at a jump)."""

    @property
    def stages(self) -> Any:  # pragma: no cover - overridden
        raise NotImplementedError

    def stage(self, delta: FloatArray | float) -> IntArray:
        """Index j of the stage holding δ (d_j ≤ δ < d_{j+1}); same shape as ``delta``."""
        return np.searchsorted(self.stages.breakpoints, check_delta(delta), side="right")

    def force(self, delta: FloatArray | float) -> FloatArray:
        """f(δ) = s_j δ + e_j, elementwise (the right limit at a breakpoint); ``delta`` a number or
        an array of numbers (rad), else TypeError naming it."""
        delta = check_delta(delta)
        st = self.stages
        j = np.searchsorted(st.breakpoints, delta, side="right")
        return st.slopes[j] * delta + st.offsets[j]

    def stiffness(self, delta: FloatArray | float) -> FloatArray:
        """∂f/∂δ = s_j, elementwise (right derivative at a breakpoint; a jump not included);
        ``delta`` a number or an array of numbers (rad), else TypeError naming it."""
        st = self.stages
        return st.slopes[np.searchsorted(st.breakpoints, check_delta(delta), side="right")]


class AbstractElastic(StageLaw):
    """Base class of the elastic laws: pure data, vectorised ``force`` and ``stiffness``."""

    name: ClassVar[str] = "abstract"

    @property
    def _stage_data(self) -> Stages:  # pragma: no cover - overridden
        raise NotImplementedError

    @property
    def stages(self) -> Stages:
        """Breakpoints, slopes and offsets of the law as read-only arrays."""
        return self._stage_data

    def force_and_stiffness(self, delta: FloatArray) -> tuple[FloatArray, FloatArray]:
        """f(δ) and ∂f/∂δ with one stage look-up."""
        delta = check_delta(delta)
        st = self._stage_data
        j = np.searchsorted(st.breakpoints, delta, side="right")
        s = st.slopes[j]
        return s * delta + st.offsets[j], s

    def to_dict(self) -> dict[str, object]:  # pragma: no cover - overridden
        raise NotImplementedError


@dataclass(frozen=True, slots=True, kw_only=True)
class Linear(AbstractElastic):
    """The reference linear law f(δ) = δ.

    ::

        f |      /
          |    /
        --+--/------ δ
          |/
    """

    name: ClassVar[str] = "linear"
    _data: Stages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_data", _stages((), (1.0,)))

    @property
    def _stage_data(self) -> Stages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "linear"}


@dataclass(frozen=True, slots=True, kw_only=True)
class Backlash(AbstractElastic):
    """Gear-pair or spline backlash of half-gap ``b`` (rad): f = 0 for |δ| ≤ b, δ ∓ b outside.

    ::

        f |        /
          |       /
        --+-=====-----  δ      (dead zone −b … b)
          /
    """

    name: ClassVar[str] = "backlash"
    b: float
    _data: Stages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        b = _check_real("b", self.b)
        if b <= 0:
            raise ValueError(f"`b` (backlash) must be > 0 rad, got {b!r}")
        warn_clearance(b, "b", stacklevel=4)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "_data", _stages((-b, b), (1.0, 0.0, 1.0)))

    @property
    def _stage_data(self) -> Stages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "backlash", "b": self.b}


@dataclass(frozen=True, slots=True, kw_only=True)
class Clutch(AbstractElastic):
    """Two-stage clutch damper: f = α δ for |δ| ≤ b, δ − (1 − α) b sign δ outside (0 ≤ α < 1).

    α = 0 is the backlash law of gap b (a free first stage), so that a design map may vary α
    from 0; it behaves exactly as :class:`Backlash` with the same b.

    ::

        f |         /     slope 1
          |     _.-'      slope α inside ±b
        --+--.-'-------  δ
         /
    """

    name: ClassVar[str] = "clutch"
    alpha: float
    b: float
    _data: Stages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        alpha = _check_real("alpha", self.alpha)
        b = _check_real("b", self.b)
        if not 0.0 <= alpha < 1.0:
            raise ValueError(
                f"`alpha` (clutch first-stage slope) must satisfy 0 <= alpha < 1, got {alpha!r} "
                "(alpha = 0 is the backlash; use type = \"piecewise\" for other laws)"
            )
        if b <= 0:
            raise ValueError(f"`b` (clutch first-stage half-width) must be > 0 rad, got {b!r}")
        warn_clearance(b, "b", stacklevel=4)
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "_data", _stages((-b, b), (1.0, alpha, 1.0)))

    @property
    def _stage_data(self) -> Stages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "clutch", "alpha": self.alpha, "b": self.b}


@dataclass(frozen=True, slots=True, kw_only=True)
class Piecewise(AbstractElastic):
    """General continuous piecewise-linear law with f(0) = 0 (multi-stage, asymmetric).

    ``breakpoints`` d_1 < … < d_k (rad) and ``slopes`` s_0 … s_k (k + 1 values, ≥ 0, not all
    zero). An outer slope 0 (s_0 or s_k) is a one-sided stop — unilateral contact, see
    :class:`Unilateral`; the model then needs a mean load that holds the element against the
    stop (a static equilibrium), or a link that restores it.

    ::

        f |            /  s_k
          |      __.--'
        --+--.--'-------- δ
          |/  s_0      (d_1 … d_k)
    """

    name: ClassVar[str] = "piecewise"
    breakpoints: tuple[float, ...]
    slopes: tuple[float, ...]
    _data: Stages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        d = _check_real_sequence("breakpoints", self.breakpoints)
        s = _check_real_sequence("slopes", self.slopes)
        if len(s) != len(d) + 1:
            raise ValueError(
                f"`slopes` must have one more entry than `breakpoints` ({len(d)} breakpoints "
                f"need {len(d) + 1} slopes), got {len(s)}"
            )
        for i in range(len(d) - 1):
            if not d[i] < d[i + 1]:
                raise ValueError(
                    f"`breakpoints` must be strictly increasing, got {list(d)!r} "
                    f"(breakpoints[{i}] = {d[i]} is not < breakpoints[{i + 1}] = {d[i + 1]})"
                )
        for i, v in enumerate(s):
            if v < 0:
                raise ValueError(f"`slopes[{i}]` must be >= 0, got {v!r}")
        if not any(v > 0 for v in s):
            raise ValueError(f"`slopes` must have at least one stage with slope > 0 (all zero: no law), got {list(s)!r}")
        # An outer slope 0 is a one-sided stop (unilateral contact): the law confines the motion on
        # one side only. Whether the mean load holds the element against the stop (a static
        # equilibrium) is the model's and the chain's rule, where the load is known.
        if d:
            widest = max(abs(d[0]), abs(d[-1]))
            warn_clearance(widest, "breakpoints[0]" if abs(d[0]) >= abs(d[-1]) else f"breakpoints[{len(d) - 1}]",
                           stacklevel=4)
        object.__setattr__(self, "breakpoints", d)
        object.__setattr__(self, "slopes", s)
        object.__setattr__(self, "_data", _stages(d, s))

    @property
    def _stage_data(self) -> Stages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "piecewise", "breakpoints": list(self.breakpoints), "slopes": list(self.slopes)}


#: The sides of a :class:`Unilateral` stop.
UNILATERAL_SIDES = ("positive", "negative")


@dataclass(frozen=True, slots=True, kw_only=True)
class Unilateral(AbstractElastic):
    """Unilateral contact: a stop on one side of a gap, nothing on the other (NLvib's
    ``unilateralSpring``; a tooth against a stop).

    ``side = "positive"``: f(δ) = δ − gap for δ > gap, 0 for δ ≤ gap;
    ``side = "negative"``: f(δ) = δ + gap for δ < −gap, 0 for δ ≥ −gap (``gap`` ≥ 0, rad).

    ::

        f |          /            (side = "positive")
          |         /  slope 1
        --+--------'------ δ
          0       gap

    The piecewise law with breakpoints (gap,) and slopes (0, 1) (or (−gap,), (1, 0)). The free
    side has no restoring torque: the model's mean load must hold the element against the stop
    (a static equilibrium), or a link must restore it.
    """

    name: ClassVar[str] = "unilateral"
    gap: float
    side: str = "positive"
    _data: Stages = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        gap = _check_real("gap", self.gap)
        if gap < 0:
            raise ValueError(f"`gap` must be >= 0 (the free travel before the stop, rad), got {gap!r}")
        if not isinstance(self.side, str) or self.side not in UNILATERAL_SIDES:
            raise ValueError(f"`side` must be \"positive\" or \"negative\" (where the stop is), got {self.side!r}")
        if gap > 0:
            warn_clearance(gap, "gap", stacklevel=4)
        object.__setattr__(self, "gap", gap)
        d, sl = ((gap,), (0.0, 1.0)) if self.side == "positive" else ((-gap,), (1.0, 0.0))
        object.__setattr__(self, "_data", _stages(d, sl))

    @property
    def _stage_data(self) -> Stages:
        return self._data

    def to_dict(self) -> dict[str, object]:
        return {"type": "unilateral", "gap": self.gap, "side": self.side}


ELASTIC_LAWS: dict[str, type[AbstractElastic]] = {
    "linear": Linear,
    "backlash": Backlash,
    "clutch": Clutch,
    "piecewise": Piecewise,
    "unilateral": Unilateral,
}

__all__ = ["Stages", "AbstractElastic", "Linear", "Backlash", "Clutch", "Piecewise", "Unilateral",
           "UNILATERAL_SIDES", "ELASTIC_LAWS"]
