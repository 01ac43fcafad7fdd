"""Sound pressure at a receiver from rattle sources and linear paths (the paper's eq. 1).

For a periodic solution of base frequency ω = Ω/period every quantity is a Fourier series in
harmonics k ω; with the complex convention q(t) = Re Σ_k Q_k e^{ikωt} (Q_k = a_k − i b_k for
q = a_0 + Σ a_k cos kωt + b_k sin kωt) the source's acceleration has the harmonics

    A_k = −(kω)² Q_k,

and the pressure at the receiver, summed harmonic by harmonic over all paths (each path j
with its source s(j) and its frequency response H_j = p/q'' in Pa per rad/s²),

    P_k = Σ_j H_j(f_k) A_{s(j),k},        f_k = k ω / 2π  (Hz),

    p_rms = sqrt(Σ_k |P_k|² / 2),         SPL = 20 log10(p_rms / 20 µPa)  (dB).

Paths add coherently: two paths from one source with opposite phase cancel. With A-weighting
every P_k is scaled by the IEC 61672-1 A-weighting gain at f_k (:func:`a_weighting_db`).

Sources
-------
* an element (``source = "NAME"``): its deflection δ_e = a_e · x, so A_k = a_e · X''_k;
* an inertia (``source = "inertia:N"``) of a grounded chain: θ = x, A_k = X''_{N,k};
* an inertia of a free chain, solved in the relative coordinates x_k = θ_k − θ_{k+1}
  (θ = Z x + θ_N 1): θ''_i = (Z x'')_i + θ''_N, with the rigid-body part from the balance of
  angular momentum. Every link and element acts between two inertias, so their torques cancel
  in the sum over inertias of M θ'' + C_θ θ' + K_θ θ + Σ_e w_eᵀ K_e f_e = T(t), leaving

      Σ_i I_i θ''_i = Σ_i T_i(t)    ⇒    θ''_N = (Σ_i T_i(t) − Σ_i I_i (Z x'')_i) / Σ_i I_i,

  linear in x'', so it holds harmonic by harmonic: harmonic k of θ''_N is
  (Σ_i T_i,k − Σ_i I_i (Z X''_k)_i) / Σ_i I_i with T_i,k the torque harmonic at kω (forcing
  harmonic h = k / period; zero when k is not a multiple of the period). The mean torques
  balance (Σ T_m = 0), so θ''_N has no mean.

The single-equation model (SPEC §1) knows only the effective inertia, not I1 and I2, so its
only source is its element ``"delta"``; write it as a two-inertia chain for inertia sources.

Outside a path's tabulated frequency range its transmission is zero (nothing is extrapolated);
``uncovered`` reports, per row and path, the fraction of that path's source mean-square
acceleration at harmonics outside the table, and a warning is issued when it exceeds
:data:`UNCOVERED_WARNING`.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ComplexArray, FloatArray
from .._validate import as_float_array
from ..model import SoundPath, check_analysable_model
from ..model import check_source, parse_source

__all__ = ["SoundPressure", "sound_pressure", "linear_sound_pressure", "a_weighting_db", "P_REF",
           "UNCOVERED_WARNING", "motion_sound_pressure", "coefficient_sound_pressure", "record_harmonics",
           "record_samples", "check_sound_paths"]

#: Reference sound pressure of the sound pressure level (Pa): 20 µPa.
P_REF = 20e-6
#: Fraction u of a source's mean-square acceleration outside a path's table above which
#: :func:`sound_pressure` warns (the level is then a lower bound): 1 %. Transmitted as strongly as
#: the covered harmonics, the uncovered ones would raise the level by −10 log10(1 − u) dB, under
#: 0.044 dB for u ≤ 1 % — below what a measured path table resolves; a warning at every trace of
#: content beyond the table (it fired at 0.007 % with 1e-6) says nothing about the result.
UNCOVERED_WARNING = 0.01


def a_weighting_db(f_hz: FloatArray | float) -> FloatArray:
    """The A-weighting gain A(f) in dB (IEC 61672-1:2013, analytic form), at ``f_hz`` (Hz, > 0):

        R_A(f) = 12194² f⁴ / ((f² + 20.6²) sqrt((f² + 107.7²)(f² + 737.9²)) (f² + 12194²)),
        A(f) = 20 log10 R_A(f) + 2.00 dB

    (A(1 kHz) ≈ 0 dB, A(100 Hz) ≈ −19.1 dB); −inf at f = 0."""
    f2 = np.asarray(f_hz, dtype=float) ** 2
    with np.errstate(divide="ignore"):
        ra = 12194.0**2 * f2**2 / ((f2 + 20.6**2) * np.sqrt((f2 + 107.7**2) * (f2 + 737.9**2)) * (f2 + 12194.0**2))
        return 20.0 * np.log10(ra) + 2.0


@dataclass(frozen=True, slots=True, eq=False)
class SoundPressure:
    """Pressure at the receiver for P periodic solutions (one per row of a frequency response).

    Attributes
    ----------
    omega : ndarray, shape (P,)
        Forcing frequency Ω (rad/s) of every row.
    period : ndarray of int, shape (P,)
        The solution's period as a multiple of the forcing period (base frequency ω = Ω/period).
    frequency_hz : ndarray, shape (P, K)
        f_k = k ω / 2π (Hz) of the harmonics k = 1 … K.
    pressure : ndarray of complex, shape (P, K)
        P_k (Pa): p(t) = Re Σ_k P_k e^{ikωt} (A-weighted if ``a_weighting``).
    p_rms : ndarray, shape (P,)
        sqrt(Σ_k |P_k|²/2) (Pa).
    spl_db : ndarray, shape (P,)
        20 log10(p_rms / 20 µPa) (dB; dB(A) if ``a_weighting``); −inf where p_rms = 0.
    uncovered : ndarray, shape (P, J)
        Per row and path: the fraction of the path's source mean-square acceleration at harmonics
        outside the path's table (transmitted as zero).
    paths : tuple of SoundPath
        The J paths.
    a_weighting : bool
        Whether the harmonics carry the A-weighting.
    linear_spl_db : ndarray, shape (P,), or None
        The level of the linear system (every element law replaced by f = δ, same excitation)
        at the same Ω, when computed.
    """

    omega: FloatArray
    period: np.ndarray
    frequency_hz: FloatArray
    pressure: ComplexArray
    p_rms: FloatArray
    spl_db: FloatArray
    uncovered: FloatArray
    paths: tuple[SoundPath, ...]
    a_weighting: bool = False
    linear_spl_db: FloatArray | None = None

    def __len__(self) -> int:
        return int(self.omega.size)

    @property
    def difference_db(self) -> FloatArray:
        """spl_db − linear_spl_db (dB): how much louder the rattling system is than the linear one."""
        if self.linear_spl_db is None:
            raise ValueError("no linear reference was computed: call sound_pressure(..., linear=True)")
        with np.errstate(invalid="ignore"):
            return self.spl_db - self.linear_spl_db

    def __repr__(self) -> str:
        unit = "dB(A)" if self.a_weighting else "dB"
        if not len(self):
            return f"SoundPressure(0 points, {len(self.paths)} path(s))"
        return (f"SoundPressure({len(self)} points, {len(self.paths)} path(s), SPL {np.nanmin(self.spl_db):.4g} … "
                f"{np.nanmax(self.spl_db):.4g} {unit}, largest uncovered fraction {np.max(self.uncovered, initial=0.0):.3g})")


# ---------------------------------------------------------------------------------------------
# Sources
# ---------------------------------------------------------------------------------------------
def check_sound_paths(paths: object, model: Any) -> tuple[SoundPath, ...]:
    """``paths`` as a tuple of SoundPath whose sources exist in ``model``.

    Parameters
    ----------
    paths : SoundPath or sequence of SoundPath
        One path or at least one.
    model : Model or Chain
        The model whose element names (and, for a chain, inertia numbers) the sources must name.

    Raises
    ------
    TypeError
        ``paths`` is neither a SoundPath nor a sequence of them.
    ValueError
        No path, or a source that names no element (or inertia) of ``model``.
    """
    if isinstance(paths, SoundPath):
        paths = (paths,)
    if isinstance(paths, (str, bytes)) or not isinstance(paths, Sequence):
        raise TypeError(f"`paths` must be a SoundPath or a sequence of them, got {paths!r}")
    out = tuple(paths)
    if not out:
        raise ValueError("`paths` must hold at least one SoundPath, got none")
    for j, path in enumerate(out):
        if not isinstance(path, SoundPath):
            raise TypeError(f"`paths[{j}]` must be a SoundPath, got {path!r}")
        check_source(path.source, model, f"paths[{j}].source")
    return out


def _source_accelerations(model: Any, Xdd: ComplexArray, k_forcing: np.ndarray, sources: list[str]) -> ComplexArray:
    """Acceleration harmonics (P, S, K) of every source from the coordinates' acceleration
    harmonics Xdd (P, n, K); ``k_forcing`` (P, K) the forcing harmonic h of each solution
    harmonic (0 where none), for the free chain's rigid-body part."""
    system = model.system()
    P, n, K = Xdd.shape
    out = np.zeros((P, len(sources), K), dtype=complex)
    names = [e.name for e in system.elements]
    theta_N = None
    for s, source in enumerate(sources):
        kind, target = parse_source(source)
        if kind == "element":
            out[:, s] = np.einsum("j,pjk->pk", system.elements[names.index(target)].a, Xdd)
            continue
        i = int(target) - 1
        rel = np.einsum("j,pjk->pk", system.angles[i], Xdd)  # (Z x'')_i
        if system.free:
            if theta_N is None:
                inertias = np.asarray(model.inertias, dtype=float)
                _, Th = model.torque_vectors()  # (H_f, N) complex
                Tsum = np.concatenate(([0.0], Th.sum(axis=1)))  # by forcing harmonic h = 0 … H_f
                h = np.where(k_forcing <= Th.shape[0], k_forcing, 0)
                torque = Tsum[h]  # (P, K)
                theta_N = (torque - np.einsum("i,ij,pjk->pk", inertias, system.angles, Xdd)) / inertias.sum()
            rel = rel + theta_N
        out[:, s] = rel
    return out


def _pressure(model: Any, paths: tuple[SoundPath, ...], Xdd: ComplexArray, w: FloatArray, period: np.ndarray,
              omega: FloatArray, a_weighting: bool, linear_spl: FloatArray | None) -> SoundPressure:
    P, n, K = Xdd.shape
    k = np.arange(1, K + 1)
    f_hz = w[:, None] * k[None, :] / (2 * np.pi)
    k_forcing = np.where(k[None, :] % period[:, None] == 0, k[None, :] // period[:, None], 0)
    sources = sorted({p.source for p in paths})
    A = _source_accelerations(model, Xdd, k_forcing, sources)
    pressure = np.zeros((P, K), dtype=complex)
    uncovered = np.zeros((P, len(paths)))
    for j, path in enumerate(paths):
        a = A[:, sources.index(path.source)]
        pressure += path.response(f_hz) * a
        power = np.abs(a) ** 2
        total = power.sum(axis=1)
        outside = np.where(path.covers(f_hz), 0.0, power).sum(axis=1)
        uncovered[:, j] = np.divide(outside, total, out=np.zeros(P), where=total > 0)
    if a_weighting:
        pressure = pressure * 10.0 ** (a_weighting_db(f_hz) / 20.0)
    p_rms = np.sqrt(0.5 * np.sum(np.abs(pressure) ** 2, axis=1))
    with np.errstate(divide="ignore"):
        spl = 20.0 * np.log10(p_rms / P_REF)
    return SoundPressure(omega=omega, period=period, frequency_hz=f_hz, pressure=pressure, p_rms=p_rms, spl_db=spl,
                         uncovered=uncovered, paths=paths, a_weighting=bool(a_weighting), linear_spl_db=linear_spl)


def _warn_uncovered(result: SoundPressure) -> None:
    if not result.uncovered.size or np.max(result.uncovered) <= UNCOVERED_WARNING:
        return
    lines = []
    for j, path in enumerate(result.paths):
        u = result.uncovered[:, j]
        if np.max(u) <= UNCOVERED_WARNING:
            continue
        i = int(np.argmax(u))
        lo, hi = path.frequency_range
        f = result.frequency_hz[i]
        lines.append(f"path {j} ({path.name or path.source}, {lo:g} … {hi:g} Hz): up to {100 * u[i]:.3g} % of the "
                     f"source's mean-square acceleration (at Ω = {result.omega[i]:.5g} rad/s, harmonics "
                     f"{f[0]:.4g} … {f[-1]:.4g} Hz) lies outside the table")
    warnings.warn(
        "sound paths transmit nothing outside their tables (no extrapolation), so the levels there are lower "
        "bounds: " + "; ".join(lines) + f"; extend the path tables to cover the harmonics, or keep fewer harmonics "
        f"(warned above {100 * UNCOVERED_WARNING:g} % of the mean square, where the level may be more than "
        f"{-10 * np.log10(1 - UNCOVERED_WARNING):.2g} dB low)",
        UserWarning, stacklevel=3)


def _linear_harmonics(model: Any, omega: FloatArray, K: int) -> ComplexArray:
    """Acceleration harmonics (P, n, K) of the linear system (every law f = δ) at forcing Ω."""
    system = model.system()
    n = system.n
    K_l = system.stiffness + sum(np.outer(e.b, e.a) for e in system.elements)
    out = np.zeros((omega.size, n, K), dtype=complex)
    for h in range(1, min(system.forced_harmonics, K) + 1):
        F = system.cos[h - 1] - 1j * system.sin[h - 1]
        if not np.any(F):
            continue
        wh = h * omega
        Z = K_l[None, :, :] - (wh**2)[:, None, None] * np.eye(n) + 1j * wh[:, None, None] * system.damping[None, :, :]
        X = np.linalg.solve(Z, np.broadcast_to(F, (wh.size, n))[..., None])[..., 0]
        out[:, :, h - 1] = -(wh**2)[:, None] * X
    return out


# ---------------------------------------------------------------------------------------------
# Front ends
# ---------------------------------------------------------------------------------------------
#: The fields of a frequency response that :func:`sound_pressure` reads.
_FRF_FIELDS = ("model", "omega", "period", "harmonics", "coefficients")


def sound_pressure(frf: Any, paths: SoundPath | Sequence[SoundPath], *, a_weighting: bool = False,
                   linear: bool = True) -> SoundPressure:
    """Sound pressure at the receiver for every row of a frequency response (module docstring).

    Parameters
    ----------
    frf : FrequencyResponse
        The solutions; their Fourier coefficients give the sources' acceleration harmonics.
    paths : SoundPath or sequence of SoundPath
        The paths (each with its source: an element name or ``"inertia:N"``), summed coherently.
    a_weighting : bool, default False
        Weight every pressure harmonic by the IEC 61672-1 A-weighting (levels in dB(A)).
    linear : bool, default True
        Also compute ``linear_spl_db``, the level of the linear system (laws f = δ) at the same
        Ω with the same harmonics (for ``difference_db``).

    Returns
    -------
    SoundPressure

    Warns
    -----
    UserWarning
        When a harmonic with more than :data:`UNCOVERED_WARNING` of a source's mean-square
        acceleration lies outside a path's table (transmitted as zero).
    """
    if not all(hasattr(frf, a) for a in _FRF_FIELDS):  # a FrequencyResponse (read by its fields: the
        # response class sits above this module and calls it from with_sound)
        raise TypeError(f"`frf` must be a FrequencyResponse (rattle.frequency_response), got {type(frf).__name__}")
    paths_t = check_sound_paths(paths, frf.model)
    system = frf.model.system()
    n = system.n
    P = len(frf)
    H = frf.harmonics
    Q = frf.coefficients.reshape(P, n, 2 * H + 1)
    period = np.asarray(frf.period, dtype=int)
    w = np.asarray(frf.omega, dtype=float) / period
    kw = w[:, None, None] * np.arange(1, H + 1)[None, None, :]
    Xdd = -(kw**2) * (Q[:, :, 1 : H + 1] - 1j * Q[:, :, H + 1 :])
    lin = None
    if linear and P:
        omega = np.asarray(frf.omega, dtype=float)
        lin = _pressure(frf.model, paths_t, _linear_harmonics(frf.model, omega, H), omega, np.ones(P, dtype=int),
                        omega, a_weighting, None).spl_db
    result = _pressure(frf.model, paths_t, Xdd, w, period, np.asarray(frf.omega, dtype=float), a_weighting, lin)
    _warn_uncovered(result)
    return result


def linear_sound_pressure(model: Any, omega: FloatArray, paths: SoundPath | Sequence[SoundPath], *,
                          a_weighting: bool = False) -> SoundPressure:
    """Sound pressure of the linear system (every element law replaced by f = δ, same excitation;
    :func:`rattle.results.linear_frequency_response`) at the forcing frequencies ``omega``
    (rad/s, shape (P,)), through ``paths`` (see :func:`sound_pressure`); exact, period 1, the
    harmonics of the excitation only."""
    check_analysable_model(model)
    omega = as_float_array(omega, "omega", "frequencies in rad/s (numbers)").ravel()
    if omega.size > 10**6 or not np.all(np.isfinite(omega) & (omega > 0)):
        raise ValueError(f"`omega` must hold at most 10⁶ finite frequencies > 0 rad/s, got {omega.size} values")
    paths_t = check_sound_paths(paths, model)
    K = max(model.system().forced_harmonics, 1)
    result = _pressure(model, paths_t, _linear_harmonics(model, omega, K), omega, np.ones(omega.size, dtype=int),
                       omega, a_weighting, None)
    _warn_uncovered(result)
    return result


# ---------------------------------------------------------------------------------------------
# Recorded motions (time-domain sweeps) and bare harmonic-balance solutions (response maps)
# ---------------------------------------------------------------------------------------------
#: A recorded motion is sampled at no fewer than this many points per forcing period …
RECORD_SAMPLES_PER_PERIOD = 4096
#: … and at no fewer than this many times the highest harmonic a path table reaches.
RECORD_OVERSAMPLING = 32
#: Most samples of one recorded window (a power of two; harmonics above half of it fold back).
MAX_RECORD_SAMPLES = 2**18


def record_samples(omega: float, window: int, paths: Sequence[SoundPath]) -> int:
    """Samples N of a recorded window of ``window`` forcing periods at Ω = ``omega``: the least
    power of two ≥ max(4096 · window, 32 · (K + 1)), K = the highest harmonic of ω = Ω/window
    that a path table reaches (f_max · 2π/ω), at most :data:`MAX_RECORD_SAMPLES`. The harmonics
    of a rattling δ'' fall as k⁻², so what folds onto harmonic k from k ± N is of relative order
    (k/N)²·|X''_1|/|X''_k|: with 512 samples per period it moved an A-weighted level (which
    lifts the upper harmonics by up to 60 dB over the fundamental) by 2e-3 dB, with 4096 by
    under 3e-5 dB (examples/clutch_with_paths.toml at 64 rad/s)."""
    f_max = max(p.frequency_range[1] for p in paths)
    k_cover = int(min(f_max * 2.0 * np.pi * window / omega, MAX_RECORD_SAMPLES))
    need = max(RECORD_SAMPLES_PER_PERIOD * int(window), RECORD_OVERSAMPLING * (k_cover + 1))
    return int(min(2 ** int(np.ceil(np.log2(need))), MAX_RECORD_SAMPLES))


def record_harmonics(trajectory: Any, omega: float, window: int, samples: int) -> ComplexArray:
    """Acceleration harmonics X''_k, k = 1 … N/2 − 1, (n, N/2 − 1), of the coordinates of a
    recorded motion: ``trajectory`` (an exact :class:`~rattle.timeint.Trajectory` or
    :class:`~rattle.timeint.SystemTrajectory` from t = 0) over its first ``window`` forcing periods
    T_w = window · 2π/Ω, base frequency ω = Ω/window, by the discrete Fourier transform of N =
    ``samples`` exact samples t_j = j T_w / N (rectangular window):

        X''_k = (2/N) Σ_j x''(t_j) e^{−2πi kj/N}      (x'' = Re Σ_k X''_k e^{ikωt}).

    For a periodic motion of period ``window`` this is its Fourier series up to aliasing: x'' is
    continuous and its slope jumps at the crossings, so |X''_k| falls as k⁻² and the folded
    content at harmonic k ≪ N is of relative order (k/N)². For a non-periodic motion it is the
    spectrum of the record's periodic extension: the forcing's harmonics fall on the bins
    k = h · window, the rest leaks into neighbouring bins — an estimate."""
    t = np.arange(samples) * (window * 2.0 * np.pi / omega / samples)
    acc = np.asarray(trajectory.derivatives(t, 2)[2], dtype=float).reshape(samples, -1)
    spectrum = np.fft.rfft(acc, axis=0)[1 : samples // 2] * (2.0 / samples)
    return spectrum.T


def motion_sound_pressure(model: Any, trajectory: Any, omega: float, window: int,
                          paths: SoundPath | Sequence[SoundPath], *, a_weighting: bool | Sequence[bool] = False,
                          warn: bool = True) -> Any:
    """Sound pressure at the receiver of a simulated motion (one row; module docstring, eq. 1).

    ``trajectory``: the exact motion at forcing frequency ``omega`` from t = 0 over at least
    ``window`` forcing periods — a steady state's orbit (``window`` its period p, base frequency
    ω = Ω/p) or, for a non-periodic motion, its record (``window`` the record's forcing periods,
    the spectrum an estimate: :func:`record_harmonics`). The source accelerations' harmonics
    k ω (k up to N/2 − 1, N = :func:`record_samples`) go through the paths harmonic by harmonic:
    P_k = Σ_j H_j(f_k) A_{s(j),k}, p_rms = sqrt(Σ_k |P_k|²/2) — the rms over the window of the
    time-domain pressure p(t) = Re Σ_k P_k e^{ikωt} (Parseval). The result's ``period`` is
    ``window``. ``a_weighting`` a sequence of flags gives a list, one SoundPressure per flag
    (the harmonics computed once)."""
    paths_t = check_sound_paths(paths, model)
    window = int(window)
    Xdd = record_harmonics(trajectory, float(omega), window, record_samples(float(omega), window, paths_t))[None]
    flags = [a_weighting] if isinstance(a_weighting, bool) else list(a_weighting)
    w = np.array([float(omega) / window])
    out = [_pressure(model, paths_t, Xdd, w, np.array([window]), np.array([float(omega)]), bool(f), None)
           for f in flags]
    if warn:
        _warn_uncovered(out[0])
    return out[0] if isinstance(a_weighting, bool) else out


def coefficient_sound_pressure(model: Any, q: FloatArray, omega: FloatArray, period: Any,
                               paths: SoundPath | Sequence[SoundPath], *, a_weighting: bool = False) -> SoundPressure:
    """Sound pressure of P harmonic-balance solutions given by their coefficients ``q``
    ((P, n·(2H+1)), coordinate-major blocks [a_0, a_1 … a_H, b_1 … b_H] of base frequency
    ω = Ω/period), at forcing frequencies ``omega`` (P,) with periods ``period`` (P,): as
    :func:`sound_pressure` for a frequency response (X''_k = −(kω)² (a_k − i b_k)), without
    the linear reference."""
    paths_t = check_sound_paths(paths, model)
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    period = np.broadcast_to(np.asarray(period, dtype=int), omega.shape).copy()
    n = model.system().n
    Q = np.asarray(q, dtype=float).reshape(omega.size, n, -1)
    H = (Q.shape[2] - 1) // 2
    w = omega / period
    Xdd = -((w[:, None, None] * np.arange(1, H + 1)) ** 2) * (Q[:, :, 1 : H + 1] - 1j * Q[:, :, H + 1 :])
    result = _pressure(model, paths_t, Xdd, w, period, omega, a_weighting, None)
    _warn_uncovered(result)
    return result
