"""The one handle type every plot returns with its figure: :class:`PlotAxes`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

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
