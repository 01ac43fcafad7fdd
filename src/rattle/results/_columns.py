"""The columns of the result tables (SPEC §3): the names and order of the result attributes
that ``frf.csv``, ``sweep.csv`` and ``orbit.csv`` hold.

They belong to the results (the data); :mod:`rattle.io` writes whatever columns it is given,
in the order it is given.
"""

from __future__ import annotations

__all__ = ["FRF_COLUMNS", "SWEEP_COLUMNS", "ORBIT_COLUMNS"]

#: ``frf.csv`` columns (SPEC §3), one row per solution point in continuation order.
FRF_COLUMNS: tuple[str, ...] = (
    "branch", "period", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p",
    "delta_min", "delta_max", "regime", "stable", "bifurcation", "iterations", "residual",
)
#: ``sweep.csv`` columns (SPEC §3); ``period`` is 0 when no period up to 8 was found.
SWEEP_COLUMNS: tuple[str, ...] = (
    "direction", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "period",
)
#: ``orbit.csv`` columns (SPEC §3).
ORBIT_COLUMNS: tuple[str, ...] = ("t", "delta", "velocity", "acceleration")
