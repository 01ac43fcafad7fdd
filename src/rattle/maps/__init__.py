"""Response maps over design parameters (SPEC §7): a frequency response with every attractor
for every combination of the varied parameters, summarised on one Ω grid, computed serially, on
local processes or on a Dask cluster, and resumable.

Layer: above :mod:`rattle.analysis` (which computes one combination) and :mod:`rattle.io`
(configuration tables, atomic writes); below the command line.

The names are loaded on first use (PEP 562), so that ``rattle map`` can check its ``--vary``
arguments (:func:`parse_all`, :func:`parameters`, :func:`build_all`) without importing the numerics.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

_LAZY: dict[str, str] = {
    "AttractorSearch": "..analysis",
    **dict.fromkeys(["response_map", "DEFAULT_OMEGA_POINTS", "StoreWarning", "CallbackError"], "._map"),
    **dict.fromkeys(["map_report", "common_intervals", "format_intervals"], "._report"),
    **dict.fromkeys(["CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS", "MAP_COLUMNS", "INTERVAL_KINDS"],
                    "._result"),
    **dict.fromkeys(["parse_all", "parameters", "combinations", "build_all", "mark_degrees", "given_in_degrees"], "._vary"),
}

__all__ = ["response_map", "map_report", "AttractorSearch", "CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS",
           "MAP_COLUMNS", "INTERVAL_KINDS", "DEFAULT_OMEGA_POINTS", "StoreWarning", "CallbackError",
           # the summary's Ω intervals (``rattle map``'s report and map.json)
           "common_intervals", "format_intervals",
           # the --vary arguments: parsed, resolved to parameters, every combination's model built
           "parse_all", "parameters", "combinations", "build_all",
           # angles the case file gave in degrees: shown in degrees by the report
           "mark_degrees", "given_in_degrees"]


if TYPE_CHECKING:
    from ..analysis import AttractorSearch
    from ._map import DEFAULT_OMEGA_POINTS, CallbackError, StoreWarning, response_map
    from ._report import common_intervals, format_intervals, map_report
    from ._result import GRID_COLUMNS, INTERVAL_KINDS, MAP_COLUMNS, CellResult, Parameter, ResponseMap
    from ._vary import build_all, combinations, given_in_degrees, mark_degrees, parameters, parse_all

__getattr__, __dir__ = lazy_exports(__name__, globals(), _LAZY, __all__)
