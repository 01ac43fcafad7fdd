"""Response measures of periodic solutions (SPEC §1), batched over many solutions.

For an element's deflection δ(t) = a_0 + Σ (a_k cos kωt + b_k sin kωt) of period T_p = 2π/ω:

    mean = a_0,  rms² = a_0² + ½ Σ (a_k² + b_k²),  rms_ac² = ½ Σ (a_k² + b_k²)   (Parseval),
    p2p = max δ − min δ,  acc_p2p = max δ'' − min δ'',

with δ'' taken from the equation of motion (exact for the orbit, and continuous, unlike the
truncated series of δ''): for the system x'' + C x' + K x + Σ_j b_j f_j(a_j·x) = F(t) and an
element δ = a·x,

    δ'' = a · (F(t) − C x' − K x − Σ_j b_j f_j(a_j·x))

(δ'' = F − c δ' − k f(δ) for the single equation). Extremes are located on the N samples and
polished: those of δ by Newton on δ' = 0 (δ is smooth there), those of δ'' on two nested local
grids (resolution T_p / (64 N); δ'' has kinks at breakpoint crossings).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ._typing import FloatArray
from .model import Model, System

REGIMES = ("no_impact", "single_sided", "double_sided")


@dataclass(frozen=True, slots=True)
class Measures:
    """SPEC §1 measures, one entry per solution (arrays of shape (P,))."""

    mean: FloatArray
    rms: FloatArray
    rms_ac: FloatArray
    p2p: FloatArray
    acc_p2p: FloatArray
    delta_min: FloatArray
    delta_max: FloatArray
    regime: np.ndarray  # str


def synthesize_batch(Q: FloatArray, samples: int) -> FloatArray:
    """Samples (P, N) of the series rows Q (P, 2H+1) at t_j = j T_p / N."""
    H = (Q.shape[1] - 1) // 2
    spec = np.zeros((Q.shape[0], samples // 2 + 1), dtype=complex)
    spec[:, 0] = Q[:, 0]
    spec[:, 1 : H + 1] = 0.5 * (Q[:, 1 : H + 1] - 1j * Q[:, H + 1 :])
    return np.fft.irfft(spec * samples, n=samples, axis=1)


def evaluate_batch(Q: FloatArray, omega: FloatArray, t: FloatArray, derivative: int = 0) -> FloatArray:
    """δ^(derivative)(t) for rows Q (P, 2H+1), base frequencies ω (P,), times t (P, m)."""
    H = (Q.shape[1] - 1) // 2
    kw = np.arange(1, H + 1)[None, None, :] * omega[:, None, None]
    ph = kw * t[:, :, None]
    a = Q[:, None, 1 : H + 1]
    b = Q[:, None, H + 1 :]
    c, s = np.cos(ph), np.sin(ph)
    scale = kw**derivative
    m = derivative % 4
    if m == 0:
        out = np.sum(scale * (c * a + s * b), axis=2)
        return out + (Q[:, None, 0] if derivative == 0 else 0.0)
    if m == 1:
        return np.sum(scale * (c * b - s * a), axis=2)
    if m == 2:
        return np.sum(scale * (-c * a - s * b), axis=2)
    return np.sum(scale * (-c * b + s * a), axis=2)


def _phasors(omega: FloatArray, t: FloatArray, H: int) -> np.ndarray:
    """e^{ikωt}, k = 1 … H, for base frequencies ω (P,) and times t (P, m): (P, m, H) complex, the
    powers of e^{iωt} by a running product (one cos and one sin per time instead of H; the error
    grows like k ε, as the rounding of the phase kωt does in a direct evaluation)."""
    th = omega[:, None] * t
    z = np.empty((H,) + th.shape, dtype=complex)  # one contiguous slab per k: the products vectorise
    np.cos(th, out=z[0].real)
    np.sin(th, out=z[0].imag)
    for k in range(1, H):
        np.multiply(z[k - 1], z[0], out=z[k])
    return z.transpose(1, 2, 0)


def _series_at(Z: np.ndarray, coef: np.ndarray) -> FloatArray:
    """Re Σ_k coef_k Z_k for phasors Z (P, m, H) and complex coefficients coef (P, H): (P, m)."""
    return np.matmul(Z, coef[:, :, None])[..., 0].real


def _position_velocity(Q: FloatArray, omega: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray]:
    """δ(t) and δ'(t) from one table of phasors, times t (P, m):
    δ = a_0 + Re Σ (a_k − i b_k) e^{ikωt},  δ' = Re Σ kω (b_k + i a_k) e^{ikωt}."""
    H = (Q.shape[1] - 1) // 2
    Z = _phasors(omega, t, H)
    a, b = Q[:, 1 : H + 1], Q[:, H + 1 :]
    kw = np.arange(1, H + 1)[None, :] * omega[:, None]  # (P, H)
    delta = Q[:, :1] + _series_at(Z, a - 1j * b)
    vel = _series_at(Z, kw * (b + 1j * a))
    return delta, vel


def acceleration_batch(model: Model, Q: FloatArray, omega: FloatArray, forcing_omega: FloatArray, t: FloatArray) -> FloatArray:
    """δ''(t) = F(t) − c δ' − k f(δ) along single-coordinate orbits Q (P, 2H+1) (base
    frequencies ω, forcing Ω), times t (P, m): :func:`element_accelerations` of the first element."""
    return element_accelerations(_system_of(model), Q[:, None, :], omega, forcing_omega, t)[:, 0]


def _refine_grid(func, t_best: FloatArray, half_width: FloatArray, sign: float, levels: int = 2, points: int = 17) -> FloatArray:
    """Maximum of sign·func near t_best by nested uniform grids over ±half_width (a kink-safe
    search: δ'' has kinks where δ crosses a breakpoint). Returns the extreme values."""
    u = np.linspace(-1.0, 1.0, points)
    t, w = t_best, half_width
    rows = np.arange(t.size)
    val = np.full(t.shape, -np.inf)
    for _ in range(levels):
        grid = t[:, None] + w[:, None] * u[None, :]
        v = sign * func(grid)
        i = np.argmax(v, axis=1)
        t, val = grid[rows, i], np.maximum(val, v[rows, i])
        w = w * (2.0 / (points - 1))
    return sign * val


def _refine_smooth_extreme(Q: FloatArray, omega: FloatArray, t: FloatArray, dt: FloatArray) -> FloatArray:
    """δ at the root of δ' near the sampled extreme t (within ±dt): Newton on δ' = 0 with
    δ'' from the series (δ is C², its extremes are smooth), kept inside the bracket:
    δ' = Re Σ kω (b_k + i a_k) e^{ikωt}, δ'' = −Re Σ (kω)² (a_k − i b_k) e^{ikωt}."""
    lo, hi = t - dt, t + dt
    H = (Q.shape[1] - 1) // 2
    kw = np.arange(1, H + 1)[None, :] * omega[:, None]
    a, b = Q[:, 1 : H + 1], Q[:, H + 1 :]
    c_vel = kw * (b + 1j * a)
    c_acc = -(kw**2) * (a - 1j * b)
    for _ in range(6):
        Z = _phasors(omega, t[:, None], H)
        v = _series_at(Z, c_vel)[:, 0]
        acc = _series_at(Z, c_acc)[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t_new = t - v / acc
        t = np.where(np.isfinite(t_new) & (t_new > lo) & (t_new < hi), t_new, t)
    return Q[:, 0] + _series_at(_phasors(omega, t[:, None], H), a - 1j * b)[:, 0]


def regime_of(model: Model, delta_min: FloatArray, delta_max: FloatArray) -> np.ndarray:
    """``no_impact`` (one stage), ``single_sided`` (breakpoints crossed on one side of δ = 0
    only) or ``double_sided``, for each (delta_min, delta_max) of the model's (first) element."""
    return regime_of_breakpoints(_system_of(model).elements[0].breakpoints, delta_min, delta_max)


def regime_of_breakpoints(d: FloatArray, delta_min: FloatArray, delta_max: FloatArray) -> np.ndarray:
    """:func:`regime_of` for an element with breakpoints ``d``."""
    out = np.full(delta_min.shape, "no_impact", dtype=object)
    if d.size == 0:
        return out
    crossed = (d[None, :] > delta_min[:, None]) & (d[None, :] < delta_max[:, None])
    pos = np.any(crossed & (d[None, :] >= 0), axis=1)
    neg = np.any(crossed & (d[None, :] < 0), axis=1)
    out[pos ^ neg] = "single_sided"
    out[pos & neg] = "double_sided"
    return out


def measures_batch(model: Model, Q: FloatArray, omega: FloatArray, forcing_omega: FloatArray, samples: FloatArray) -> Measures:
    """Measures of P single-coordinate solutions: rows Q (P, 2H+1), base frequencies ω (P,),
    forcing frequencies Ω (P,), on N = samples.shape[1] points per period (the first element of
    :func:`system_measures_batch`)."""
    return system_measures_batch(model, Q[:, None, :], omega, forcing_omega, samples.shape[1])[0]


# ---------------------------------------------------------------------------------------------
# Systems: every coordinate and element
# ---------------------------------------------------------------------------------------------
def _system_of(model: object) -> System:
    return model if isinstance(model, System) else model.system()  # type: ignore[attr-defined]


def coordinate_accelerations(
    system: System, X: FloatArray, V: FloatArray, t: FloatArray, forcing_omega: FloatArray, F: FloatArray | None = None,
) -> FloatArray:
    """x'' = F(t) − C x' − K x − Σ_j b_j f_j(a_j·x) from positions X and velocities V
    (P, n, m) at times t (P, m), forcing frequencies Ω (P,). Returns (P, n, m). ``F`` the
    forcing at those times (P or 1, m, n) if already at hand."""
    F = system.forcing(t, forcing_omega[:, None]) if F is None else F  # (P, m, n)
    acc = np.moveaxis(F, -1, 1) - np.einsum("ij,pjm->pim", system.damping, V) - np.einsum("ij,pjm->pim", system.stiffness, X)
    for e in system.elements:
        d = np.einsum("j,pjm->pm", e.a, X)
        acc -= e.b[None, :, None] * e.law.force(d)[:, None, :]
    return acc


def _series_position_velocity(Qx: FloatArray, omega: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray]:
    """x(t), x'(t) of coefficient blocks Qx (P, n, 2H+1) at times t (P, m): (P, n, m) each."""
    P, n, L = Qx.shape
    Qr = Qx.reshape(P * n, L)
    w = np.repeat(omega, n)
    tr = np.repeat(t, n, axis=0)
    x, v = _position_velocity(Qr, w, tr)
    return x.reshape(P, n, -1), v.reshape(P, n, -1)


def element_accelerations(system: System, Qx: FloatArray, omega: FloatArray, forcing_omega: FloatArray, t: FloatArray) -> FloatArray:
    """δ_e''(t) of every element (P, m_el, m) along orbits with coefficient blocks Qx (P, n, 2H+1)."""
    X, V = _series_position_velocity(Qx, omega, t)
    acc = coordinate_accelerations(system, X, V, t, forcing_omega)
    return np.einsum("ej,pjm->pem", system.element_rows, acc)


def _sample_forcing(system: System, omega: FloatArray, forcing_omega: FloatArray, N: int) -> FloatArray | None:
    """F at the N samples t_j = j T_p / N of every orbit, (1, N, n), when all orbits have the same
    period multiple p = Ω/ω: then Ω t_j = 2π p j / N whatever Ω, so one row serves all (instead
    of P·N evaluations of every forcing harmonic). None when the multiples differ."""
    if omega.size == 0 or system.load is not None:  # a mean by speed differs from orbit to orbit
        return None
    ratio = forcing_omega / omega
    p = float(np.rint(ratio[0]))
    if p < 1 or not np.allclose(ratio, p, rtol=1e-12, atol=0.0):
        return None
    return system.forcing(np.arange(N) * (2 * np.pi / N), p)[None]


#: Orbits measured together: the tables of one chunk (samples, phasors) stay in the cache; the rows
#: are independent, so the chunking changes no number.
CHUNK = 128


def system_measures_batch(model: object, Qx: FloatArray, omega: FloatArray, forcing_omega: FloatArray, samples: int) -> tuple[Measures, ...]:
    """SPEC §1 measures of every element's deflection, one :class:`Measures` per element, for P
    orbits with coefficient blocks Qx (P, n, 2H+1) (coordinate-major), base frequencies ω (P,),
    forcing frequencies Ω (P,), evaluated on ``samples`` points per period (``CHUNK`` orbits at a
    time)."""
    P = Qx.shape[0]
    if P <= CHUNK:
        return _measures_of_rows(_system_of(model), Qx, omega, forcing_omega, samples)
    system = _system_of(model)
    parts = [_measures_of_rows(system, Qx[i : i + CHUNK], omega[i : i + CHUNK], forcing_omega[i : i + CHUNK], samples)
             for i in range(0, P, CHUNK)]
    names = [f.name for f in fields(Measures)]
    return tuple(Measures(**{name: np.concatenate([getattr(part[e], name) for part in parts]) for name in names})
                 for e in range(len(parts[0])))


def _measures_of_rows(system: System, Qx: FloatArray, omega: FloatArray, forcing_omega: FloatArray, samples: int) -> tuple[Measures, ...]:
    """:func:`system_measures_batch` of one chunk of orbits."""
    P, n, L = Qx.shape
    H = (L - 1) // 2
    N = samples
    A = system.element_rows
    Qe = np.einsum("ej,pjl->pel", A, Qx)  # element deflection series (P, m, 2H+1)
    X = synthesize_batch(Qx.reshape(P * n, L), N).reshape(P, n, N)
    k = np.arange(1, H + 1)[None, :] * np.repeat(omega, n)[:, None]
    dQ = np.zeros((P * n, L))
    Qr = Qx.reshape(P * n, L)
    dQ[:, 1 : H + 1] = k * Qr[:, H + 1 :]
    dQ[:, H + 1 :] = -k * Qr[:, 1 : H + 1]
    V = synthesize_batch(dQ, N).reshape(P, n, N)
    T = 2 * np.pi / omega
    dt = T / N
    rows = np.arange(P)
    times = np.arange(N)[None, :] * dt[:, None]
    acc_all = np.einsum("ej,pjm->pem", A, coordinate_accelerations(system, X, V, times, forcing_omega,
                                                                   _sample_forcing(system, omega, forcing_omega, N)))
    out = []
    for e_idx, e in enumerate(system.elements):
        Q = Qe[:, e_idx]
        d = np.einsum("j,pjm->pm", e.a, X)
        mean = Q[:, 0].copy()
        ac2 = 0.5 * np.sum(Q[:, 1:] ** 2, axis=1)
        # Both extremes polished in one batch (rows 0…P−1 the maxima, P…2P−1 the minima).
        polished = _refine_smooth_extreme(np.concatenate([Q, Q]), np.concatenate([omega, omega]), np.concatenate(
            [times[rows, np.argmax(d, axis=1)], times[rows, np.argmin(d, axis=1)]]), np.concatenate([dt, dt]))
        dmax = np.maximum(d.max(axis=1), polished[:P])
        dmin = np.minimum(d.min(axis=1), polished[P:])
        acc = acc_all[:, e_idx]

        def acc_f(t: FloatArray, e_idx: int = e_idx) -> FloatArray:
            return element_accelerations(system, Qx, omega, forcing_omega, t)[:, e_idx]

        amax = np.maximum(acc.max(axis=1), _refine_grid(acc_f, times[rows, np.argmax(acc, axis=1)], dt, +1.0))
        amin = np.minimum(acc.min(axis=1), _refine_grid(acc_f, times[rows, np.argmin(acc, axis=1)], dt, -1.0))
        out.append(Measures(mean=mean, rms=np.sqrt(mean**2 + ac2), rms_ac=np.sqrt(ac2), p2p=dmax - dmin,
                            acc_p2p=amax - amin, delta_min=dmin, delta_max=dmax,
                            regime=regime_of_breakpoints(e.breakpoints, dmin, dmax)))
    return tuple(out)

__all__ = ["system_measures_batch", "element_accelerations", "coordinate_accelerations", "regime_of_breakpoints", "Measures", "measures_batch", "synthesize_batch", "evaluate_batch", "acceleration_batch", "regime_of", "REGIMES"]
