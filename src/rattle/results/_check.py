"""What a law with jumps or friction reports beside its rows: the sub-harmonic branches' lines
and metadata, shared by the exact-check groups of the single equation
(:class:`~rattle.results.NonsmoothCheck`) and of a chain (:class:`~rattle.results.FrictionCheck`)
that a :class:`~rattle.results.FrequencyResponse` carries in ``check``.

Numbers only, no I/O: the command line prints :meth:`FrequencyResponse.summary` and writes
:meth:`FrequencyResponse.metadata` (``frf.json``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._speed import SpeedText


def held_runs(omega: np.ndarray, held: np.ndarray) -> list[tuple[float, float]]:
    """The Ω-ranges (min, max) of the consecutive runs of rows where ``held`` is true.

    Parameters
    ----------
    omega : ndarray, shape (P,)
        The forcing frequency Ω of every row, in branch order.
    held : ndarray of bool, shape (P,)
        The rows to gather (e.g. where the exact orbit sticks or locks).

    Returns
    -------
    list of (float, float)
        One ``(min Ω, max Ω)`` per run of consecutive true rows, in row order; empty when none.
    """
    runs: list[tuple[float, float]] = []
    idx = np.flatnonzero(held)
    if idx.size == 0:
        return runs
    breaks = np.flatnonzero(np.diff(idx) > 1)
    for part in np.split(idx, breaks + 1):
        w = omega[part]
        runs.append((float(np.min(w)), float(np.max(w))))
    return runs


def largest(values: Any, rows: Any) -> float | None:
    """max |values| over ``rows`` (finite ones), None when there is none."""
    if values is None:
        return None
    v = np.abs(np.asarray(values, dtype=float)[rows])
    v = v[np.isfinite(v)]
    return float(np.max(v)) if v.size else None


def stable_spans(branch: Any, speed: SpeedText = SpeedText()) -> str:
    """The Ω ranges of a branch's consecutive matched stable rows, as text (the runs its plot
    shades, :func:`held_runs`): ``Ω = 0.5 … 0.7, 0.9 … 1`` or, with an engine (``speed``),
    ``500 … 700 rpm, …``."""
    ok = np.asarray(branch.matched, dtype=bool) & np.asarray(branch.stable, dtype=bool)
    runs = held_runs(np.asarray(branch.omega, dtype=float), ok)
    return speed.spans(runs) if runs else "nowhere"


def branch_metadata(branch: Any) -> dict[str, Any]:
    """One sub-harmonic branch (a discontinuous law's or a chain's) in ``frf.json``: its number,
    period, where it was born, how its continuation ended, its rows (all, matched, stable), its Ω
    range, the HB's largest |rms_error| over the matched rows and its stability changes."""
    matched = np.asarray(branch.matched, dtype=bool)
    labels = branch.bifurcation
    return {
        "branch": int(branch.branch), "period": int(branch.period), "origin": branch.origin,
        "followed": branch.followed,
        "status": branch.status.name.lower(), "message": branch.message or branch.status.message,
        "points": len(branch), "matched": int(np.count_nonzero(matched)),
        "stable": int(np.count_nonzero(matched & np.asarray(branch.stable, dtype=bool))),
        "omega_min": float(np.min(branch.omega)), "omega_max": float(np.max(branch.omega)),
        "rms_error_max": largest(branch.rms_error, matched),
        "bifurcations": [{"kind": str(labels[i]), "index": int(i), "omega": float(branch.omega[i])}
                         for i in range(len(branch)) if labels[i]],
    }


def branch_lines(check: Any, subharmonics: bool, speed: SpeedText = SpeedText()) -> list[str]:
    """The summary's lines on the sub-harmonic branches of ``check`` (a discontinuous law's or a
    chain's), or on the period doublings that started none (``subharmonics``: whether they were
    asked for); speeds as ``speed`` writes them (rpm with an engine)."""
    lines = []
    for b in check.branches:
        m = np.asarray(b.matched, dtype=bool)
        worst = largest(b.rms_error, m)
        how = (f"{int(np.count_nonzero(m))} matched by exact shooting over {b.period} periods"
               if b.followed == "harmonic balance" else "every row an exact orbit (exact shooting continuation)")
        lines.append(f"branch {b.branch} (period {b.period}, {b.origin}): {len(b)} points over "
                     f"{speed.span(np.min(b.omega), np.max(b.omega))}, {how}; stable over {stable_spans(b, speed)}"
                     + (f"; HB rms error at most {worst:.2g}" if worst is not None else ""))
    if "period_doubling" in set(check.bifurcation.tolist()) and not check.branches:
        lines.append("no period-2 orbit was found next to the period doubling(s)" if subharmonics else
                     "period doubling found: run with --subharmonics for the period-2 branches born there")
    return lines


__all__ = ["held_runs", "largest", "stable_spans", "branch_metadata", "branch_lines"]
