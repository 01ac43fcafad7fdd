"""The one handle type every plot returns with its figure: :class:`PlotAxes`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

_OWN = frozenset({"_primary", "_aliases"})


class PlotAxes(dict):  # type: ignore[type-arg]
    """The axes of one plot: a dict panel name → matplotlib ``Axes``, in drawing order, with a
    ``primary`` axes.

    Attribute access that the dict does not answer itself goes to the primary axes, so code
    written for a single panel keeps working: ``fig, ax = frf.plot(); ax.set_xlim(0.5, 1.5)``,
    ``ax.get_lines()``, ``ax.texts``. The panels are ``ax["gear"]``, ``list(ax)`` (their
    names), ``ax.values()``, ``ax.items()``. The dict's own methods stay the dict's: ``clear``
    and ``update`` act on the mapping — call ``ax.primary.clear()`` for the axes'.

    Some plots also answer a few *aliases* by key (``ax["delta"]`` of a chain's orbit plot is
    the first element's δ panel; ``ax["histories"]`` of a comparison is the list of its
    time-history panels). Aliases are found by ``ax[key]``, ``key in ax`` and ``ax.get(key)``
    but are not panels: iteration, ``len``, ``keys()`` and ``values()`` give each panel once.

    Parameters
    ----------
    panels : mapping or iterable of (name, Axes)
        The panels, in drawing order (at least one).
    primary : str, optional
        Name of the primary panel (default: the first).
    aliases : mapping, optional
        Extra keys answered by ``ax[key]``: another name of a panel, or a group of panels.
    """

    __slots__ = ("_primary", "_aliases")

    def __init__(
        self,
        panels: "Mapping[str, Any] | Iterable[tuple[str, Any]]",
        primary: str | None = None,
        aliases: "Mapping[str, Any] | None" = None,
    ) -> None:
        super().__init__(panels)
        if not self:
            raise ValueError("`panels` must name at least one axes, got none")
        if primary is None:
            primary = next(iter(self))
        if primary not in dict.keys(self):
            raise ValueError(f"`primary` must be one of the panel names {list(self)}, got {primary!r}")
        object.__setattr__(self, "_primary", primary)
        object.__setattr__(self, "_aliases", dict(aliases or {}))

    @classmethod
    def single(cls, ax: Any, name: str = "response") -> "PlotAxes":
        """One panel ``name`` (the primary), e.g. the axes a caller passed as ``ax=``."""
        return cls({name: unwrap(ax)})

    @property
    def primary(self) -> Any:
        """The primary axes (the one attribute access falls through to)."""
        return dict.__getitem__(self, self._primary)

    @property
    def primary_name(self) -> str:
        """The name of the primary panel."""
        return self._primary

    @property
    def aliases(self) -> dict[str, Any]:
        """The extra keys (name → axes or group of axes) answered by ``ax[key]``."""
        return dict(self._aliases)

    def __missing__(self, key: str) -> Any:
        try:
            return self._aliases[key]
        except KeyError:
            known = list(self) + list(self._aliases)
            raise KeyError(f"no panel {key!r} in this plot; its panels are {known}") from None

    def __contains__(self, key: object) -> bool:
        return dict.__contains__(self, key) or key in self._aliases

    def get(self, key: str, default: Any = None) -> Any:  # type: ignore[override]
        """The panel (or alias) ``key``, or ``default``."""
        return self[key] if key in self else default

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: forward to the primary axes (not dunders, not
        # our own slots, so that copying and pickling see a plain dict).
        if name in _OWN or (name.startswith("__") and name.endswith("__")):
            raise AttributeError(name)
        return getattr(self.primary, name)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(dir(self.primary)))

    def __repr__(self) -> str:
        names = ", ".join(repr(k) for k in self)
        return f"PlotAxes([{names}], primary={self._primary!r})"

    def __reduce__(self) -> Any:
        return (type(self), (dict(self), self._primary, self._aliases))


def unwrap(ax: Any) -> Any:
    """A matplotlib ``Axes`` from ``ax``: the primary axes of a :class:`PlotAxes`, else ``ax``."""
    return ax.primary if isinstance(ax, PlotAxes) else ax


__all__ = ["PlotAxes", "unwrap"]


def fit_ylim(ax: Any, room: float = 0.0, margin: float = 0.05) -> None:
    """Set the y limits of ``ax`` to hold every point of its data lines (those drawn in data
    coordinates: not ``axvline``/``axhline``), with ``margin`` of the span below and above and
    ``room`` more above (space for labels at the top). ``set_ylim`` elsewhere freezes the
    autoscale, so a plot that adds lines after it calls this at the end."""
    import numpy as np

    lo, hi = np.inf, -np.inf
    for line in ax.get_lines():
        if line.get_transform() != ax.transData or not line.get_visible():
            continue
        y = np.asarray(line.get_ydata(), dtype=float)
        y = y[np.isfinite(y)]
        if y.size:
            lo, hi = min(lo, float(y.min())), max(hi, float(y.max()))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return
    span = hi - lo or (abs(hi) * 0.1 or 1.0)
    ax.set_ylim(lo - margin * span, hi + (margin + room) * span)


#: How many times :func:`separate_texts` moves a label (by its own height) before hiding it.
MAX_TEXT_MOVES = 4


def separate_texts(fig: Any, axes: Iterable[Any]) -> None:
    """Move the labels of ``axes`` (their ``ax.texts``) so that none overlaps another, a tick
    label or the axes' title, and none sticks out of its axes sideways.

    The figure's layout is done first (the labels' places in pixels depend on it). Labels are
    taken left to right; one that overlaps something placed already is moved by its own height
    in the direction of its attribute ``rattle_move`` (−1 down, the default for labels in the
    upper half of the axes; +1 up below it), at most :data:`MAX_TEXT_MOVES` times, then hidden
    (what it says is in the legend or the ring colours); one moved out of the axes is hidden too. Only labels given as an annotation
    with an offset in points (``textcoords="offset points"``) and ``rattle_move`` other than 0 are
    moved; the others are obstacles."""
    from matplotlib.text import Annotation, Text

    def extent(t: Any) -> Any:  # the text's box, without an annotation's arrow
        return Text.get_window_extent(t, renderer)

    axes = list(axes)
    engine = fig.get_layout_engine()
    if engine is not None:
        engine.execute(fig)
    renderer = fig.canvas.get_renderer()
    scale = 72.0 / fig.dpi  # pixels → points
    for ax in axes:
        box = ax.get_window_extent(renderer)
        placed = [t.get_window_extent(renderer) for t in (*ax.get_xticklabels(), *ax.get_yticklabels(), ax.title,
                                                           ax.xaxis.label, ax.yaxis.label)
                  if t.get_visible() and t.get_text()]
        movable, fixed = [], []
        for t in ax.texts:
            if not (t.get_visible() and t.get_text()):
                continue
            if isinstance(t, Annotation) and t.anncoords == "offset points" and getattr(t, "rattle_move", None) != 0:
                movable.append(t)
            else:
                fixed.append(t)
        placed += [extent(t) for t in fixed]
        movable.sort(key=lambda t: extent(t).x0)
        for t in movable:
            bb = extent(t)
            dx = max(0.0, box.x0 + 1.0 - bb.x0) - max(0.0, bb.x1 - (box.x1 - 1.0))  # inside the axes sideways
            if dx:
                t.xyann = (t.xyann[0] + dx * scale, t.xyann[1])
            direction = getattr(t, "rattle_move", None)
            if direction is None:
                direction = -1 if ax.transAxes.inverted().transform(bb.get_points().mean(axis=0))[1] > 0.5 else 1
            for _ in range(MAX_TEXT_MOVES + 1):
                bb = extent(t).padded(1.0)
                inside = bb.y0 >= box.y0 - 1.0 and bb.y1 <= box.y1 + 1.0
                if inside and not any(bb.overlaps(other) for other in placed):
                    placed.append(bb)
                    break
                t.xyann = (t.xyann[0], t.xyann[1] + direction * (bb.height + 2.0) * scale)
            else:
                t.set_visible(False)


__all__ += ["fit_ylim", "separate_texts", "MAX_TEXT_MOVES"]


def speed_axis(result: Any) -> tuple[float, str]:
    """(x-axis units per rad/s, x-axis label) of a result's plots: crankshaft rpm when its model
    has an engine (``speed_order`` q_0: rpm = Ω · 60 / (2π q_0)), else Ω in rad/s."""
    order = getattr(getattr(result, "model", None), "speed_order", None)
    if order is None:
        return 1.0, "forcing frequency Ω (rad/s)"
    return 60.0 / (2.0 * np.pi * float(order)), "engine speed (rpm)"


def stick_ylim(ax: Any, values: Any) -> None:
    """y limits of a stick-fraction panel: 0 … a little above the largest fraction drawn (at
    most 1), so that fractions of a few per cent are not flattened against a 0 … 1 axis."""
    finite = [np.asarray(v, dtype=float)[np.isfinite(v)] for v in values]
    top = max([float(v.max()) for v in finite if v.size] or [0.0])
    top = min(1.0, top * 1.15) if top > 0.0 else 1.0
    ax.set_ylim(-0.02 * top, top * 1.02)


__all__ += ["speed_axis", "stick_ylim"]
