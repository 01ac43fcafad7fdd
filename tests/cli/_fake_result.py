"""A stand-in for FrequencyResponse: the part of it the command line uses (shared by the CLI
tests that replace the solver)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rattle.io import write_csv
from rattle.results import FRF_COLUMNS


class FakeResponse:
    """``n`` rows; ``on_plot`` runs while drawing; ``settings``/``timings`` go into metadata()."""

    def __init__(self, n: int = 3, on_plot: Any = None, settings: dict[str, Any] | None = None,
                 timings: dict[str, Any] | None = None) -> None:
        self.n, self.on_plot = n, on_plot
        self.settings, self.timings = settings or {}, timings or {}

    def __len__(self) -> int:
        return self.n

    def to_csv(self, path: Path) -> None:
        cols: dict[str, Any] = {name: np.linspace(0.1, 1.0, self.n) for name in FRF_COLUMNS}
        cols.update(branch=np.zeros(self.n, int), period=np.ones(self.n, int), iterations=np.ones(self.n, int),
                    regime=["no_impact"] * self.n, stable=np.ones(self.n, bool), bifurcation=[""] * self.n)
        write_csv(path, cols, FRF_COLUMNS)

    def plot(self, ax: Any = None) -> tuple[Any, Any]:
        if self.on_plot is not None:
            self.on_plot()
        from matplotlib.figure import Figure

        fig = Figure()
        ax = fig.add_subplot()
        ax.plot([0, 1], [0, 1])
        return fig, ax

    def summary(self) -> str:
        return f"{self.n} solution points (fake)"

    def metadata(self) -> dict[str, Any]:
        return {"settings": dict(self.settings), "timings": dict(self.timings), "status": "success"}
