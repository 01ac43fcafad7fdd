"""Response maps over design parameters (SPEC §7): a frequency response with every attractor
for every combination of the varied parameters, summarised on one Ω grid, computed serially, on
local processes or on a Dask cluster, and resumable.

Layer: above :mod:`rattle.analysis` (which computes one combination) and :mod:`rattle.io`
(configuration tables, atomic writes); below the command line.

The names are loaded on first use (PEP 562), so that ``rattle map`` can check its ``--vary``
arguments (:mod:`rattle.maps._vary`) without importing the numerics.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_LAZY: dict[str, str] = {
    "AttractorSearch": "..analysis._attractors",
    **dict.fromkeys(["response_map", "DEFAULT_OMEGA_POINTS"], "._map"),
    "map_report": "._report",
    **dict.fromkeys(["CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS", "MAP_COLUMNS", "INTERVAL_KINDS"],
                    "._result"),
}

__all__ = ["response_map", "map_report", "AttractorSearch", "CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS",
           "MAP_COLUMNS", "INTERVAL_KINDS", "DEFAULT_OMEGA_POINTS"]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'rattle.maps' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:
    from ..analysis._attractors import AttractorSearch
    from ._map import DEFAULT_OMEGA_POINTS, response_map
    from ._report import map_report
    from ._result import GRID_COLUMNS, INTERVAL_KINDS, MAP_COLUMNS, CellResult, Parameter, ResponseMap
