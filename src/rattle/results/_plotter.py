"""The results' ``plot()`` methods call the plotting layer by name, at call time.

The plotting layer (:mod:`rattle.plotting`) reads the results; the results do not import it.
Each ``plot()`` method names its drawing function, and :func:`plot_with` loads
:mod:`rattle.plotting` (matplotlib with it) only when a plot is asked for, the way a data frame's
``plot`` looks up its plotting backend by name. So ``import rattle.results`` needs no
matplotlib, and the imports run one way: plotting → results.
"""

from __future__ import annotations

import importlib
from typing import Any

#: The module that holds the drawing functions, looked up when a plot is asked for.
PLOTTING_MODULE = "rattle.plotting"


def plot_with(name: str, result: object, /, **kwargs: Any) -> Any:
    """``rattle.plotting.<name>(result, **kwargs)``: the figure and axes of ``result``."""
    return getattr(importlib.import_module(PLOTTING_MODULE), name)(result, **kwargs)


__all__ = ["PLOTTING_MODULE", "plot_with"]
