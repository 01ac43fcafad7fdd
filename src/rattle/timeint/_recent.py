"""What the exact flows keep of their recent work: the last few trajectories (by their exact
arguments), stage solutions (by Ω) and matrix exponentials (by τ) that a shooting continuation
asks for again — a dict of bounded size that forgets its oldest entry first."""

from __future__ import annotations

from typing import Any


class Recent(dict):  # type: ignore[type-arg]
    """A dict that keeps its last ``size`` entries: :meth:`put` of a new key past ``size`` drops the
    entry put first (lookups do not refresh an entry: the flows ask again for what they have just
    made, not for what they used long ago)."""

    __slots__ = ("size",)

    def __init__(self, size: int) -> None:
        super().__init__()
        self.size = int(size)

    def put(self, key: Any, value: Any) -> Any:
        """``self[key] = value``, the oldest entry dropped first when full; returns ``value``."""
        if key not in self and len(self) >= self.size:
            del self[next(iter(self))]
        self[key] = value
        return value


__all__ = ["Recent"]
