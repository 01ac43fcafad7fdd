"""A harmonic count you can trust: truncation error per point, and adaptive H.

The truncation error of a harmonic-balance point is estimated by solving the same point again
with twice the harmonics (Newton at the same Ω, from the solution padded with zeros) and taking
the relative change of the rms. The coefficients' decay alone is a poor predictor here (δ''
has kinks, so the coefficients decay like k⁻⁴ only on average and with sign changes); the 2H
comparison measured on the reference case tracks the error against the exact orbit within a
factor of a few.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _limits, _validate
from .._typing import FloatArray
from ..continuation import ContinuationOptions
from ..hb import HarmonicBalance, HBOptions, NewtonOptions, resize_harmonics, solve_harmonic_balance
from ..model import Model, check_analysable_model
from ..results import FrequencyResponse
from ._settings import DEFAULT_ADAPTIVE_HARMONICS, StabilityMethod, scaled_hb


def truncation_error(frf: FrequencyResponse, rows: Sequence[int] | None = None, *, factor: int = 2,
                     newton: NewtonOptions | None = None, hb: HBOptions | None = None) -> FloatArray:
    """|rms(factor·H) / rms(H) − 1| for the given rows (default all); NaN where the finer
    problem does not converge at fixed Ω (fold tips, where ∂R/∂q is singular). The finer
    problem uses ``newton`` and the HB options ``hb`` of the run (an explicit sample count scaled
    with the harmonic count; default: the samples recorded in ``frf.settings``, else default)."""
    _validate.check_instance(frf, "frf", FrequencyResponse, "a FrequencyResponse", optional=False)
    factor = _validate.check_int("factor", factor, 2)
    if factor * frf.harmonics > _limits.PROBLEM_MAX_HARMONICS:
        raise ValueError(
            f"`factor` must be <= {max(2, _limits.PROBLEM_MAX_HARMONICS // frf.harmonics)} for a response with "
            f"{frf.harmonics} harmonics, got {factor}: the finer problem would carry {factor * frf.harmonics} "
            f"harmonics (at most {_limits.PROBLEM_MAX_HARMONICS}; memory grows as H², time as H³); use 2"
        )
    _validate.check_instance(newton, "newton", NewtonOptions, "a NewtonOptions")
    idx = np.arange(len(frf)) if rows is None else np.asarray(rows, dtype=int)
    out = np.full(idx.size, np.nan)
    problems: dict[tuple[int, int], HarmonicBalance] = {}
    H_all = frf.harmonics
    if hb is None:
        given = frf.settings.get("samples_given")
        h0 = int(frf.settings.get("harmonics", H_all))
        hb = HBOptions(harmonics=h0, samples=int(given) if given is not None else None)
    for n, i in enumerate(idx):
        p = int(frf.period[i])
        # The row's own harmonic count: the highest non-zero harmonic (branches may be padded).
        q = frf.coefficients[i]
        nz = np.nonzero(np.abs(q[1 : H_all + 1]) + np.abs(q[H_all + 1 :]))[0]
        H = int(nz.max()) + 1 if nz.size else 1
        H = max(H, p)
        key = (factor * H, p)
        if key not in problems:
            problems[key] = HarmonicBalance(frf.model, scaled_hb(hb, factor * H), period=p)
        hb2 = problems[key]
        r = solve_harmonic_balance(hb2, resize_harmonics(q, factor * H), float(frf.omega[i]), newton)
        if r.converged:
            rms2 = np.sqrt(r.q[0] ** 2 + 0.5 * np.sum(r.q[1:] ** 2))
            out[n] = abs(rms2 / frf.rms[i] - 1.0)
    return out


@_validate.numerical_failures
def adaptive_frequency_response(
    model: Model,
    omega: tuple[float, float] = (0.1, 3.0),
    *,
    tolerance: float = 1e-3,
    harmonics: int = DEFAULT_ADAPTIVE_HARMONICS,
    max_harmonics: int = 128,
    every: int = 4,
    subharmonics: bool = False,
    newton: NewtonOptions | None = None,
    samples: int | None = None,
    hb: HBOptions | None = None,
    continuation: ContinuationOptions | None = None,
    stability: StabilityMethod = "monodromy",
) -> FrequencyResponse:
    """Frequency response whose harmonic count is raised (doubled) until the estimated rms
    truncation error, checked at every ``every``-th point, is below ``tolerance`` everywhere
    (or ``max_harmonics`` is reached). A count too small for a periodic solution to be found at
    all is doubled too. The estimates and the count used go in ``settings``.

    ``hb`` (or ``harmonics``/``samples``) is the starting discretisation; each doubling keeps
    its sample ratio (an explicit ``samples`` doubles with H). ``newton``, ``continuation`` and
    ``stability`` go unchanged to every run and every truncation estimate."""
    from ..errors import ConvergenceError
    from ._frequency_response import frequency_response
    from ._settings import resolve_hb

    # Argument checks: the rules of rattle._limits / rattle._validate, shared with the file.
    check_analysable_model(model)
    _limits.check_frequency_range(model, *_validate.check_range(omega))
    tolerance = _validate.check_real(tolerance, "tolerance")
    if not 0 < tolerance < 1:
        raise ValueError(f"`tolerance` must be in (0, 1), got {tolerance!r}")
    subharmonics = _validate.check_bool(subharmonics, "subharmonics")
    largest = 4 if subharmonics else 1  # frequency_response's default max_period
    _limits.check_hb_settings(harmonics, samples, hb, period=largest)
    max_harmonics = _limits.check_harmonics(max_harmonics, "max_harmonics", period=largest)
    every = _validate.check_int("every", every, 1)
    hb0 = resolve_hb(harmonics, samples, hb)
    H = hb0.harmonics
    history: list[dict[str, object]] = []
    while True:
        hb_H = scaled_hb(hb0, H)
        try:
            frf = frequency_response(model, omega=omega, hb=hb_H, subharmonics=subharmonics, newton=newton,
                                     continuation=continuation, stability=stability)
        except ConvergenceError as exc:
            history.append({"harmonics": H, "max_truncation_error": None, "failed": str(exc)})
            if 2 * H > max_harmonics:
                raise
            H *= 2
            continue
        rows = np.arange(0, len(frf), max(1, every))
        rows = rows[frf.bifurcation[rows] == ""]
        err = truncation_error(frf, rows, newton=newton, hb=hb_H)
        worst = float(np.nanmax(err)) if np.isfinite(err).any() else np.inf
        history.append({"harmonics": H, "max_truncation_error": worst, "checked": int(np.isfinite(err).sum())})
        if worst <= tolerance or 2 * H > max_harmonics:
            break
        H *= 2
    from dataclasses import replace

    return replace(frf, settings=dict(frf.settings, adaptive_harmonics=history, truncation_tolerance=tolerance))


__all__ = ["truncation_error", "adaptive_frequency_response"]
