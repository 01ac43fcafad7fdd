"""The exact solution of a :class:`~rattle.model.System` on one stage combination.

On a stage combination s (every element e on one stage s_e of its law) the equations of motion
are linear; in first-order form z = (x, x'),

    z' = A_s z + g_s + Σ_h (c_h cos hΩt + s_h sin hΩt),

with A_s = [[0, I], [−K_s, −C]], g_s = (0, F_0 − Σ_e b_e o_e), c_h = (0, F_ch), s_h = (0, F_sh).

* The harmonics have the particular solution z_h(t) = Re Σ_h Z_h e^{ihΩt},
  Z_h = (ihΩ I − A_s)⁻¹ (c_h − i s_h); it exists unless ihΩ is an eigenvalue of A_s (an undamped
  stage in exact resonance), which is refused with a clear error.
* The rest, u = z − z_h, solves the autonomous u' = A_s u + g_s, i.e. w = (u, 1) solves
  w' = Ā w with the augmented matrix Ā = [[A_s, g_s], [0, 0]] (Van Loan): w(τ) = exp(Ā τ) w(0).
  This covers, without special cases, a singular A_s (a free sub-chain inside a backlash gap:
  ramp- and parabola-type solutions) and the constant part of the force.

exp(Ā τ) is evaluated exactly (to round-off) in a block-modal form. The eigenvalues of Ā are
grouped: those closer than 1e-4 ρ to one another (ρ the spectral radius of A_s) form a cluster —
the zero modes (the augmented eigenvalue 0 with any rigid-body-like mode of the stage, possibly
defective) or a critically damped pair — and keep one block each, on an orthonormal basis of
their invariant subspace (a sorted complex Schur form); every other eigenvalue is diagonalised:

    Ā = P diag(μ_1 I + N_1, …, μ_c I + N_c, Λ) P⁻¹,
    exp(Ā τ) = P diag(e^{μ_1 τ} exp(N_1 τ), …, e^{Λ τ}) P⁻¹,

exp(N_j τ) being the Taylor series of a nearly nilpotent block (a polynomial in τ for an exactly
nilpotent one: ramps and parabolas), summed until its terms are below round-off over the
segment's length. Where P is ill-conditioned anyway (cond > 1e6) the stage falls back to
``scipy.linalg.expm`` of Ā τ, slower but as exact.

A :class:`Segment` is the solution from a state z_s at t_s on one stage combination, written as
z(t_s + τ) = Re[Σ_j B_j e^{λ_j τ}] (modes λ: the diagonalised eigenvalues and
the harmonics ihΩ, whose phases at t_s are folded into B so that τ, not t, carries the round-off;
plus Re[e^{μ_j τ} Σ_k Q_jk τ^k] for every cluster block),
evaluated vectorised for the crossing search and at single points for the root refinement.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import scipy.linalg as sla

from .._typing import FloatArray
from ..model import System
from ._recent import Recent

_EPS = float(np.finfo(float).eps)
_TWO_PI = 2.0 * math.pi
_CLUSTER = 1e-4  # eigenvalues closer than this × spectral radius share a Taylor-summed block
_MAX_CONDITION = 1e6  # condition number of P beyond which the stage falls back to expm
_SEGMENT_SCALES = 64.0  # longest segment, in stage time scales (a new segment starts beyond it)
_MAX_TAYLOR = 200
#: exp(Ā τ) a fallback stage keeps by τ (:meth:`StageSolution.expm`)
EXPM_KEPT = 16


def _taylor_terms(T: np.ndarray, c: np.ndarray, tau_max: float) -> np.ndarray:
    """u_k = T^k c / k! for k = 0 … K−1, stopped when ‖u_k‖ τ_max^k is below round-off of the
    sum (shape (K, len(c)))."""
    terms = [c]
    if T.size == 0:
        return np.asarray(terms)
    total = float(np.max(np.abs(c))) if c.size else 0.0
    u = c
    scale = 1.0
    for k in range(1, _MAX_TAYLOR):
        u = (T @ u) / k
        scale *= tau_max
        size = float(np.max(np.abs(u))) * scale
        if size == 0.0 or not math.isfinite(size):
            break
        terms.append(u)
        total += size
        if size <= 1e-18 * total and k >= 2:
            break
    return np.asarray(terms)


def _taylor_expm(T: np.ndarray, tau: float) -> np.ndarray:
    """exp(T τ) by its Taylor series (T nearly nilpotent, small)."""
    k_dim = T.shape[0]
    out = np.eye(k_dim, dtype=complex)
    if k_dim == 0:
        return out
    term = np.eye(k_dim, dtype=complex)
    Tt = T * tau
    for k in range(1, _MAX_TAYLOR):
        term = (term @ Tt) / k
        size = float(np.max(np.abs(term)))
        if size == 0.0:
            break
        out = out + term
        if size <= 1e-18 * float(np.max(np.abs(out))) and k >= 2:
            break
    return out


#: What :meth:`StageSolution._block_modal_form` computes (Ω-independent; kept across Ω).
_MODAL_FIELDS = ("method", "clusters", "sdim", "lam", "P", "Pinv", "Pz", "Pd", "Pz_modal", "Pd_modal", "Pinv_z")


class SystemStages:
    """Forcing data of ``system`` at forcing frequency ``omega`` and the cache of its stage
    solutions (:meth:`solution`).

    ``samples_per_scale`` grid points per stage time scale bracket the crossings.
    """

    def __init__(self, system: System, omega: float, samples_per_scale: int = 40,
                 modal_cache: dict | None = None) -> None:
        self.system = system
        self.omega = float(omega)
        # The stage matrices and their (block-)modal forms do not depend on Ω: an integrator
        # keeps them across frequencies (``modal_cache``); only the harmonic particular
        # solutions are made anew for each Ω.
        self.modal_cache: dict = {} if modal_cache is None else modal_cache
        self.samples_per_scale = int(samples_per_scale)
        n, m = system.n, system.m
        self.n, self.m = n, m
        self.C = np.asarray(system.damping, dtype=float)
        self.mean = np.asarray(system.mean_at(self.omega), dtype=float).reshape(n)
        # The cached modal forms are those of Ā = [[A, g], [0, 0]], g holding the mean forcing: a
        # mean that changes with Ω (a drag by speed) makes it part of the cache key.
        self._cache_tag = None if system.load is None else self.mean.tobytes()
        cos = np.asarray(system.cos, dtype=float).reshape(-1, n)
        sin = np.asarray(system.sin, dtype=float).reshape(-1, n)
        keep = np.any(cos != 0.0, axis=1) | np.any(sin != 0.0, axis=1)
        self._orders, self._keep = np.arange(1, cos.shape[0] + 1, dtype=float), keep
        self.hw = (self._orders * self.omega)[keep]
        self.fc = cos[keep]
        self.fs = sin[keep]
        rows = system.element_rows.reshape(m, n)
        self.rows = rows
        G = np.zeros((2 * m, 2 * n))
        G[:m, :n] = rows
        G[m:, n:] = rows
        self.G = G
        self.lower = [np.concatenate(([-np.inf], np.asarray(e.breakpoints, dtype=float))) for e in system.elements]
        self.upper = [np.concatenate((np.asarray(e.breakpoints, dtype=float), [np.inf])) for e in system.elements]
        self._cache: dict[tuple[int, ...], StageSolution] = {}
        #: a solution per stage combination at any Ω, shared with the copies of :meth:`at_omega`
        #: (the Ω-independent parts of their solutions)
        self._bases: dict[tuple[int, ...], StageSolution] = {}

    def at_omega(self, omega: float) -> SystemStages:
        """The same system's stages at forcing frequency ``omega``, equal to ``SystemStages(system,
        omega, …)`` for a system whose mean forcing does not depend on Ω (no ``load``): its stage
        solutions are made from those of any frequency (:meth:`StageSolution.at_omega`: only the
        harmonic particular solutions and the time scales afresh)."""
        if self.system.load is not None:
            raise ValueError("at_omega needs a mean forcing independent of Ω (a system without `load`)")
        out = copy.copy(self)  # shares the stage data, the modal cache and the bases
        out.omega = float(omega)
        out.hw = (self._orders * out.omega)[self._keep]
        out._cache = {}
        return out

    def solution(self, stages: tuple[int, ...]) -> StageSolution:
        """The :class:`StageSolution` of the stage combination ``stages`` (cached; from the same
        stages' solution at another Ω where there is one)."""
        sol = self._cache.get(stages)
        if sol is None:
            base = self._bases.get(stages)
            sol = StageSolution(self, stages) if base is None else base.at_omega(self)
            self._cache[stages] = sol
            self._bases.setdefault(stages, sol)
        return sol

    def forcing(self, t: FloatArray | float, derivative: int = 0) -> FloatArray:
        """F(t) or its ``derivative``-th time derivative, shape t.shape + (n,)."""
        t = np.asarray(t, dtype=float)
        th = np.multiply.outer(t, self.hw)
        co, si = np.cos(th), np.sin(th)
        w = self.hw[:, None] ** derivative
        fc, fs = w * self.fc, w * self.fs
        r = derivative % 4
        if r == 0:
            out = co @ fc + si @ fs
        elif r == 1:
            out = -si @ fc + co @ fs
        elif r == 2:
            out = -(co @ fc + si @ fs)
        else:
            out = si @ fc - co @ fs
        return out + self.mean if derivative == 0 else out

    def stages_at(self, t: float, z: FloatArray) -> tuple[int, ...]:
        """The stage of every element at state ``z`` = (x, x') at time ``t``; exactly on a
        breakpoint the direction of motion decides (sign of δ', then of δ'', the upper stage if
        both vanish)."""
        n = self.n
        x, v = z[:n], z[n:]
        stages = []
        for e, elem in enumerate(self.system.elements):
            bp = np.asarray(elem.breakpoints, dtype=float)
            d = float(self.rows[e] @ x)
            j = int(np.searchsorted(bp, d, side="right"))
            stages.append(j)
        stages_t = tuple(stages)
        acc = None
        for e, elem in enumerate(self.system.elements):
            j = stages_t[e]
            bp = np.asarray(elem.breakpoints, dtype=float)
            d = float(self.rows[e] @ x)
            if j > 0 and d == bp[j - 1]:
                direction = float(self.rows[e] @ v)
                if direction == 0.0:
                    if acc is None:
                        Ks = self.system.stage_stiffness(stages_t)
                        acc = self.forcing(t) - self.C @ v - Ks @ x - self.system.stage_offset(stages_t)
                    direction = float(self.rows[e] @ acc)
                if direction < 0.0:
                    stages[e] = j - 1
        return tuple(stages)


class StageSolution:
    """The exact solution data of one stage combination (see the module docstring).

    Attributes: ``stages``; ``A`` (2n, 2n) the stage matrix; ``g`` (2n,) its constant forcing;
    ``Zh`` (H, 2n) complex harmonic particular amplitudes; ``eigenvalues`` of A; ``time_scale``
    the fastest time scale (highest forcing harmonic, highest natural frequency, fastest decay);
    ``grid_step`` the crossing-search step; ``max_segment`` the longest segment; ``method``
    ``"modal"`` (block-modal form: ``clusters`` (start, stop, μ, N) and the diagonalised
    eigenvalues ``lam``) or ``"expm"`` (ill-conditioned fallback).
    """

    def __init__(self, flow: SystemStages, stages: tuple[int, ...]) -> None:
        system = flow.system
        n = flow.n
        self.flow = flow
        self.stages = stages
        self.Ks = np.asarray(system.stage_stiffness(stages), dtype=float)
        self.offset = np.asarray(system.stage_offset(stages), dtype=float)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -self.Ks
        A[n:, n:] = -flow.C
        self.A = A
        g = np.zeros(2 * n)
        g[n:] = flow.mean - self.offset
        self.g = g
        k = 2 * n + 1
        Abar = np.zeros((k, k))
        Abar[: 2 * n, : 2 * n] = A
        Abar[: 2 * n, 2 * n] = g
        self.Abar = Abar
        self._expm_kept = Recent(EXPM_KEPT)  # (τ, batch) → exp(Ā τ); shared with the at_omega copies
        key = stages if flow._cache_tag is None else (stages, flow._cache_tag)
        cached = flow.modal_cache.get(key)
        lam = np.linalg.eigvals(A) if cached is None else cached["eigenvalues"]
        self.eigenvalues = lam
        rho = float(np.max(np.abs(lam))) if lam.size else 0.0
        self._rho = rho
        self._set_omega(flow)  # the harmonic particular solutions and the time scales

        # Block-modal form of exp(Ā τ).
        if cached is None:
            self.method = "modal"
            try:
                self._block_modal_form(Abar, rho)
            except (np.linalg.LinAlgError, ValueError):
                self.method = "expm"
            cached = {"eigenvalues": lam, "method": self.method}
            if self.method == "modal":
                cached.update({k: getattr(self, k) for k in _MODAL_FIELDS})
            flow.modal_cache[key] = cached
        else:
            for k, v in cached.items():
                if k != "eigenvalues":
                    setattr(self, k, v)
        if self.method == "modal":
            self.Pinv_1 = self.Pinv[:, -1]
        self._set_bases()
        self.lo = np.array([flow.lower[e][j] for e, j in enumerate(stages)])
        self.hi = np.array([flow.upper[e][j] for e, j in enumerate(stages)])
        self.bounded = bool(np.any(np.isfinite(self.lo)) or np.any(np.isfinite(self.hi)))

    def at_omega(self, flow: SystemStages) -> StageSolution:
        """The same stage combination's solution in ``flow`` (the same system at another Ω, a mean
        forcing independent of Ω): the stage matrices and their modal form shared, the harmonic
        particular solutions, time scales and mode amplitudes' bases made afresh — equal to
        ``StageSolution(flow, stages)``."""
        out = copy.copy(self)
        out.flow = flow
        out.__dict__.pop("_omega_xy", None)
        out._set_omega(flow)
        out._set_bases()
        return out

    def _set_omega(self, flow: SystemStages) -> None:
        """The parts that depend on Ω: the harmonic particular amplitudes Z_h (refused at an exact
        resonance of an undamped stage), the time scales, the grid step and the longest segment."""
        n = flow.n
        A, lam, rho, stages = self.A, self.eigenvalues, self._rho, self.stages
        hw = flow.hw
        if hw.size:
            dist = np.abs(lam[None, :] - 1j * hw[:, None])
            bad = dist <= 1e-10 * np.maximum(hw[:, None], rho)
            if np.any(bad):
                h_i, l_i = np.argwhere(bad)[0]
                raise ValueError(
                    f"the stage combination {stages} has the eigenvalue {lam[l_i]!r}: it is undamped and in "
                    f"exact resonance with the forcing harmonic at {hw[h_i]!r} rad/s (`omega` = {flow.omega!r}); "
                    "the response grows without bound: add damping or change `omega`"
                )
            rhs = np.zeros((hw.size, 2 * n), dtype=complex)
            rhs[:, n:] = flow.fc - 1j * flow.fs
            M = 1j * hw[:, None, None] * np.eye(2 * n)[None] - A[None]
            self.Zh = np.linalg.solve(M, rhs[..., None])[..., 0]
        else:
            self.Zh = np.zeros((0, 2 * n), dtype=complex)

        # Time scales: the highest harmonic's and the stage's own (its fastest oscillation and decay).
        own = getattr(self, "_own_scale", None)
        if own is None:
            own = math.inf
            im = float(np.max(np.abs(lam.imag))) if lam.size else 0.0
            re = float(np.max(np.abs(lam.real))) if lam.size else 0.0
            if im > 0.0:
                own = min(own, _TWO_PI / im)
            if re > 0.0:
                own = min(own, 0.5 / re)
            self._own_scale = own
        scale = min(_TWO_PI / float(np.max(hw)), own) if hw.size else own
        self.time_scale = scale
        self.grid_step = scale / flow.samples_per_scale
        self.max_segment = _SEGMENT_SCALES * scale

    def _set_bases(self) -> None:
        """The modes (the diagonalised eigenvalues, then the harmonics ihΩ) and a segment's mode
        amplitudes' bases: coef[:, None] * base (coef: modal coordinates, then the harmonics'
        phase factors at its start)."""
        flow = self.flow
        hw = flow.hw
        self.Zh_d = self.Zh @ flow.G.T  # (H, 2m)
        if self.method == "modal":
            self.modes = np.concatenate((self.lam, 1j * hw))
            self.base_d = np.concatenate((self.Pd_modal.T, self.Zh_d), axis=0)  # (K, 2m)
            self.base_z = np.concatenate((self.Pz_modal.T, self.Zh), axis=0)  # (K, 2n)
        else:
            self.modes = 1j * hw
            self.base_d, self.base_z = self.Zh_d, self.Zh
        self.modes_l = self.modes.tolist()

    def _block_modal_form(self, Abar: np.ndarray, rho: float) -> None:
        """Ā = P diag(μ_1 I + N_1, …, μ_c I + N_c, Λ) P⁻¹: clusters of eigenvalues closer than
        1e-4 ρ to each other (zero modes, critical damping; possibly defective) keep a block each
        (an orthonormal basis of their invariant subspace from a sorted Schur form), the others
        are diagonalised. Sets ``method`` to "expm" when P is ill-conditioned."""
        n2 = Abar.shape[0] - 1
        k = n2 + 1
        lam, V = np.linalg.eig(Abar)
        ctol = _CLUSTER * rho if rho > 0.0 else math.inf
        # single-linkage clusters
        label = list(range(k))
        for i in range(k):
            for j in range(i + 1, k):
                if abs(lam[i] - lam[j]) <= ctol and label[i] != label[j]:
                    old, new = label[j], label[i]
                    label = [new if x == old else x for x in label]
        groups: dict[int, list[int]] = {}
        for i, g in enumerate(label):
            groups.setdefault(g, []).append(i)
        blocks, singles = [], []
        for members in groups.values():
            (blocks if len(members) > 1 else singles).append(members)
        cols, clusters = [], []
        start = 0
        for members in blocks:
            mu = complex(np.mean(lam[members]))
            if abs(mu) <= ctol:
                mu = 0j
            elif abs(mu.imag) <= ctol:
                mu = complex(mu.real, 0.0)
            radius = max(abs(lam[i] - mu) for i in members) + 0.5 * ctol  # the other eigenvalues are farther
            def inside(x: complex, mu: complex = mu, radius: float = radius) -> bool:
                return abs(x - mu) <= radius

            _, Z, sdim = sla.schur(Abar.astype(complex), output="complex", sort=inside)
            if sdim != len(members):
                raise ValueError("cluster basis")
            cols.append(Z[:, :sdim])
            clusters.append((start, start + sdim, mu))
            start += sdim
        single = [i for members in singles for i in members]
        cols.append(V[:, single])
        P = np.concatenate(cols, axis=1) if cols else np.zeros((k, 0), dtype=complex)
        Pinv = np.linalg.inv(P)
        cond = float(np.linalg.norm(P, 2) * np.linalg.norm(Pinv, 2))
        if not (math.isfinite(cond) and cond <= _MAX_CONDITION):
            self.method = "expm"
            return
        self.clusters = []
        for a, b, mu in clusters:
            T = Pinv[a:b] @ Abar @ P[:, a:b]
            self.clusters.append((a, b, mu, T - mu * np.eye(b - a)))
        sdim = start
        self.sdim = sdim
        self.lam = lam[single]
        self.P, self.Pinv = P, Pinv
        self.Pz = P[:n2]
        self.Pd = self.flow.G @ self.Pz
        self.Pz_modal, self.Pd_modal = self.Pz[:, sdim:], self.Pd[:, sdim:]
        self.Pinv_z = Pinv[:, :n2]

    # --- pieces ---------------------------------------------------------------------------------
    def omega_particular(self, t: float) -> FloatArray:
        """A particular solution p(t) (2n,) of s' = A_s s + ∂F/∂Ω(t), the equation of the
        sensitivity s = ∂z/∂Ω to the forcing frequency (times fixed):

            ∂F/∂Ω = Re Σ_h i h t (c_h − i s_h) e^{ihΩt},   p(t) = Re Σ_h (X_h t + Y_h) e^{ihΩt},

        with X_h = i h Z_h and Y_h = −(ihΩ I − A_s)⁻¹ X_h."""
        hw = self.flow.hw
        if not hw.size:
            return np.zeros(self.A.shape[0])
        XY = getattr(self, "_omega_xy", None)
        if XY is None:
            h = hw / self.flow.omega
            X = 1j * h[:, None] * self.Zh
            n2 = self.A.shape[0]
            M = 1j * hw[:, None, None] * np.eye(n2)[None] - self.A[None]
            Y = -np.linalg.solve(M, X[..., None])[..., 0]
            XY = self._omega_xy = (X, Y)
        X, Y = XY
        ph = np.exp(1j * hw * t)
        return ((X * t + Y) * ph[:, None]).sum(axis=0).real

    def expm(self, tau: float, batch: bool = False) -> FloatArray:
        """exp(Ā τ) (2n+1, 2n+1) by ``scipy.linalg.expm`` (of Ā τ, or with ``batch`` of the stack
        of one Ā τ, as a vector of times gives it), the last :data:`EXPM_KEPT` kept by their exact τ
        (Ā does not depend on Ω: kept across :meth:`at_omega`)."""
        kept = self._expm_kept
        key = (tau, batch)
        E = kept.get(key)
        if E is None:
            E = sla.expm(self.Abar[None] * np.array([tau])[:, None, None])[0] if batch else sla.expm(self.Abar * tau)
            kept.put(key, E)
        return E

    def transition(self, tau: float) -> FloatArray:
        """exp(A_s τ) (2n, 2n), exact to round-off."""
        if self.method == "expm":
            return sla.expm(self.A * tau)
        M = (self.Pz_modal * np.exp(self.lam * tau)) @ self.Pinv_z[self.sdim:]
        for a, b, mu, N in self.clusters:
            M = M + self.Pz[:, a:b] @ ((np.exp(mu * tau) * _taylor_expm(N, tau)) @ self.Pinv_z[a:b])
        return M.real.copy()

    def segment(self, ts: float, z: FloatArray, tau_max: float) -> Segment:
        """The solution from state ``z`` at ``ts`` for local times 0 ≤ τ ≤ ``tau_max``."""
        return Segment(self, ts, z, tau_max)


def _horner(Q: np.ndarray, tau: np.ndarray | float) -> np.ndarray | complex:
    """Σ_k Q[k] τ^k (Q (K, …); τ broadcast against Q[0] with a trailing axis for arrays)."""
    acc = Q[-1]
    for k in range(Q.shape[0] - 2, -1, -1):
        acc = acc * tau + Q[k]
    return acc


class Segment:
    """The exact solution on one stage combination from (t_s, z_s) (module docstring).

    ``state(tau)`` gives z = (x, x') and z' = (x', x'') at local times τ = t − t_s (vector or
    scalar); ``scan(taus)`` the element deflections δ and δ' (N, m) at once; ``element_point``
    (δ_e, δ_e', δ_e'') of one element at one τ (the root finder's hot call); ``end_state`` z at
    one τ.
    """

    __slots__ = ("sol", "ts", "z0", "tau_max", "mu", "c", "coef", "Bd", "w0", "poly", "_Bz", "_Qz",
                 "_floors", "_mu_l", "_bd_l", "_qd_l", "_ef")

    def __init__(self, sol: StageSolution, ts: float, z: FloatArray, tau_max: float) -> None:
        flow = sol.flow
        self.sol, self.ts, self.z0 = sol, float(ts), z
        self.tau_max = tau_max = float(tau_max) if math.isfinite(tau_max) else 1.0
        self.mu = sol.modes
        self._mu_l = sol.modes_l
        self._Bz = self._Qz = self._floors = None
        self._bd_l = self._qd_l = None
        self.poly: list[tuple[complex, np.ndarray, np.ndarray, int, int]] = []  # (μ, U, Qd, a, b)
        if flow.hw.size:
            ph = np.exp((1j * self.ts) * flow.hw)
            u = z - (ph @ sol.Zh).real  # the state less the harmonics' particular solution
        else:
            ph = np.zeros(0, dtype=complex)
            u = z
        if sol.method == "modal":
            self.c = c = sol.Pinv_z @ u + sol.Pinv_1
            self.coef = coef = np.concatenate((c[sol.sdim:], ph))
            for a, b, mu, N in sol.clusters:
                U = _taylor_terms(N, c[a:b], tau_max)  # (Kp, d)
                self.poly.append((mu, U, U @ sol.Pd[:, a:b].T, a, b))
            self.w0 = None
        else:
            self.w0 = np.concatenate((u, [1.0]))
            self.coef = coef = ph
        self.Bd = coef[:, None] * sol.base_d  # (K, 2m)

    # --- lazily built pieces ------------------------------------------------------------------
    @property
    def Bz(self) -> np.ndarray:
        """Mode amplitudes of z (K, 2n)."""
        if self._Bz is None:
            self._Bz = self.coef[:, None] * self.sol.base_z
        return self._Bz

    @property
    def Qz(self) -> list[tuple[complex, np.ndarray]]:
        """Per cluster block: (μ, polynomial coefficients of z (Kp, 2n))."""
        if self._Qz is None:
            self._Qz = [(mu, U @ self.sol.Pz[:, a:b].T) for mu, U, _, a, b in self.poly]
        return self._Qz

    def floors(self) -> tuple[FloatArray, FloatArray]:
        """Round-off floors of δ and δ' of every element over the segment, (m,) each: 8 ε times
        the sum of the magnitudes of the terms (mode amplitudes, polynomial terms at the
        segment's end) that make them up."""
        if self._floors is None:
            m = self.sol.flow.m
            dmag = np.abs(self.Bd[:, :m]).sum(axis=0)
            vmag = np.abs(self.Bd[:, m:]).sum(axis=0)
            for mu, _, Qd, _, _ in self.poly:
                powers = self.tau_max ** np.arange(Qd.shape[0]) * max(1.0, math.exp(min(mu.real * self.tau_max, 700.0)))
                q = np.abs(Qd).T @ powers
                dmag, vmag = dmag + q[:m], vmag + q[m:]
            if self.w0 is not None:
                G = self.sol.flow.G
                dmag, vmag = dmag + np.abs(G[:m] @ self.z0), vmag + np.abs(G[m:] @ self.z0)
            self._floors = (8.0 * _EPS * dmag, 8.0 * _EPS * vmag)
        return self._floors

    @property
    def d_floor(self) -> FloatArray:
        return self.floors()[0]

    @property
    def v_floor(self) -> FloatArray:
        return self.floors()[1]

    def element_floors(self, e: int) -> tuple[float, float]:
        """Round-off floors (δ_e, δ_e') of one element (as :meth:`floors`, in Python floats)."""
        if self.w0 is not None:
            d, v = self.floors()
            return float(d[e]), float(v[e])
        self._element_terms(e)
        return self._ef[e]

    # --- evaluation -----------------------------------------------------------------------------
    def _expm_w(self, taus: FloatArray) -> np.ndarray:
        """w(τ) = exp(Ā τ) w0 (fallback stages), shape (N, 2n+1): scipy's expm, stepped by one
        expm of the grid step where ``taus`` is an equally spaced grid; every exp(Ā τ) is kept by
        its exact τ (:meth:`StageSolution.expm`: a grid's step and ends recur)."""
        sol = self.sol
        if taus.size > 3:
            h = taus[1] - taus[0]
            inner = taus[1:-1] - taus[0]
            if h > 0.0 and np.allclose(np.diff(inner), h, rtol=1e-12, atol=0.0):
                E = sol.expm(float(h))
                out = np.empty((taus.size, self.w0.size))
                w = sol.expm(float(taus[0])) @ self.w0
                out[0] = w
                for i in range(1, taus.size - 1):
                    w = E @ w
                    out[i] = w
                out[-1] = sol.expm(float(taus[-1])) @ self.w0
                return out
        if taus.size == 1:
            return sol.expm(float(taus[0]), batch=True)[None] @ self.w0
        E = sla.expm(sol.Abar[None] * taus[:, None, None])
        return E @ self.w0

    def scan(self, taus: FloatArray) -> tuple[FloatArray, FloatArray]:
        """δ and δ' of every element at local times ``taus`` (N,): two (N, m) arrays."""
        m = self.sol.flow.m
        if self.mu.size:
            y = (np.exp(np.multiply.outer(taus, self.mu)) @ self.Bd).real
        else:
            y = np.zeros((taus.size, 2 * m))
        for mu, _, Qd, _, _ in self.poly:
            p = Qd[0] if Qd.shape[0] == 1 else _horner(Qd, taus[:, None])
            y += (np.exp(mu * taus)[:, None] * p).real if mu != 0 else np.real(p)
        if self.w0 is not None:
            w = self._expm_w(taus)
            y = y + w[:, :-1] @ self.sol.flow.G.T
        return y[:, :m], y[:, m:]

    def state(self, taus: FloatArray | float) -> tuple[FloatArray, FloatArray]:
        """z = (x, x') and z' = (x', x'') at local times ``taus``: shapes taus.shape + (2n,)."""
        taus = np.asarray(taus, dtype=float)
        shape = taus.shape
        t = taus.reshape(-1)
        Bz = self.Bz
        n2 = Bz.shape[1]
        if self.mu.size:
            E = np.exp(np.multiply.outer(t, self.mu))
            z = (E @ Bz).real
            zd = ((E * self.mu) @ Bz).real
        else:
            z = np.zeros((t.size, n2))
            zd = np.zeros((t.size, n2))
        tt = t[:, None]
        for mu, Q in self.Qz:
            acc = np.broadcast_to(Q[-1], (t.size, n2)).astype(complex)
            dacc = np.zeros((t.size, n2), dtype=complex)
            for k in range(Q.shape[0] - 2, -1, -1):
                dacc = dacc * tt + acc
                acc = acc * tt + Q[k]
            if mu != 0:
                e = np.exp(mu * t)[:, None]
                acc, dacc = e * acc, e * (mu * acc + dacc)
            z = z + acc.real
            zd = zd + dacc.real
        if self.w0 is not None:
            w = self._expm_w(t)
            z = z + w[:, :-1]
            zd = zd + w @ self.sol.Abar[:-1].T
        return z.reshape(shape + (n2,)), zd.reshape(shape + (n2,))

    def end_state(self, tau: float) -> FloatArray:
        """z = (x, x') at one local time ``tau`` (2n,)."""
        if self.w0 is not None:  # as state() computes z (not z')
            t = np.array([tau])
            z = (np.exp(np.multiply.outer(t, self.mu)) @ self.Bz).real if self.mu.size else np.zeros((1, self.z0.size))
            return (z + self._expm_w(t)[:, :-1])[0]
        sol = self.sol
        z = (np.exp(self.mu * tau) * self.coef) @ sol.base_z
        z = z.real.copy()
        for mu, U, _, a, b in self.poly:
            u = U[0] if U.shape[0] == 1 else _horner(U, tau)
            if mu != 0:
                u = u * complex(np.exp(mu * tau))
            z += (sol.Pz[:, a:b] @ u).real
        return z

    def _element_terms(self, e: int) -> list[tuple[complex, complex, complex]]:
        """Python numbers of element ``e``'s terms (μ, its δ and δ' amplitudes; the polynomial
        blocks' in ``_qd_l``) and its round-off floors (``_ef``), built on first use."""
        if self._bd_l is None:
            self._bd_l, self._qd_l, self._ef = {}, {}, {}
        terms = self._bd_l.get(e)
        if terms is None:
            m = self.sol.flow.m
            terms = self._bd_l[e] = list(zip(self._mu_l, self.Bd[:, e].tolist(), self.Bd[:, m + e].tolist()))
            poly = self._qd_l[e] = [(complex(mu), Qd[:, e].tolist(), Qd[:, m + e].tolist())
                                    for mu, _, Qd, _, _ in self.poly]
            dmag = sum(abs(b0) for _, b0, _ in terms)
            vmag = sum(abs(b1) for _, _, b1 in terms)
            T = self.tau_max
            for mu, qd, qv in poly:
                grow = max(1.0, math.exp(min(mu.real * T, 700.0)))
                dmag += grow * sum(abs(q) * T**k for k, q in enumerate(qd))
                vmag += grow * sum(abs(q) * T**k for k, q in enumerate(qv))
            self._ef[e] = (8.0 * _EPS * dmag, 8.0 * _EPS * vmag)
        return terms

    def element_point(self, tau: float, e: int) -> tuple[float, float, float]:
        """(δ_e, δ_e', δ_e'') at local time ``tau`` (a scalar)."""
        if self.w0 is not None:
            z, zd = self.state(np.array([tau]))
            a = self.sol.flow.rows[e]
            n = self.sol.flow.n
            return float(a @ z[0, :n]), float(a @ z[0, n:]), float(a @ zd[0, n:])
        terms = self._element_terms(e)
        d = v = a = 0.0
        exp, cos, sin = math.exp, math.cos, math.sin
        for mu, b0, b1 in terms:
            r = exp(mu.real * tau)
            ph = mu.imag * tau
            ez = complex(r * cos(ph), r * sin(ph))
            b1e = b1 * ez
            d += (b0 * ez).real
            v += b1e.real
            a += (mu * b1e).real
        for mu, qd, qv in self._qd_l[e]:
            pd, pv, dpv = qd[-1], qv[-1], 0j
            for k in range(len(qd) - 2, -1, -1):
                dpv = dpv * tau + pv
                pd = pd * tau + qd[k]
                pv = pv * tau + qv[k]
            if mu != 0:
                r = exp(mu.real * tau)
                ph = mu.imag * tau
                ez = complex(r * cos(ph), r * sin(ph))
                pd, pv, dpv = pd * ez, pv * ez, (mu * pv + dpv) * ez
            d += pd.real
            v += pv.real
            a += dpv.real
        return d, v, a


__all__ = ["SystemStages", "StageSolution", "Segment"]
