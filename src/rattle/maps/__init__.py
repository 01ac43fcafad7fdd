"""Response maps over design parameters (SPEC §7): a frequency response with every attractor
for every combination of the varied parameters, summarised on one Ω grid, computed serially, on
local processes or on a Dask cluster, and resumable.

Layer: above :mod:`rattle.analysis` (which computes one combination) and :mod:`rattle.io`
(configuration tables, atomic writes); below the command line.
"""

from ..analysis._attractors import AttractorSearch
from ._map import DEFAULT_OMEGA_POINTS, response_map
from ._result import GRID_COLUMNS, INTERVAL_KINDS, MAP_COLUMNS, CellResult, Parameter, ResponseMap

__all__ = ["response_map", "AttractorSearch", "CellResult", "ResponseMap", "Parameter", "GRID_COLUMNS",
           "MAP_COLUMNS", "INTERVAL_KINDS", "DEFAULT_OMEGA_POINTS"]
