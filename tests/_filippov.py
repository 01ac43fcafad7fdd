"""Independent references for the non-smooth laws, shared by the tests: the Filippov systems
integrated by scipy (DOP853, rtol 1e-12) with terminal events and the mode logic written out again
(not the project's integrators).

- :func:`single_reference`: the single equation with a discontinuous law (jumps, friction per
  stage), mode by mode;
- :func:`chain_reference`: a chain with constant friction levels on its elements, stick/slip by an
  explicit active set.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rattle.model import System


def _surface(d):
    def event(t, x):
        return x[0] - d

    return event


def _velocity_zero():
    def event(t, x):
        return x[1]

    return event


def single_reference(system: System, x0, t1: float, omega: float, max_step: float = np.inf):
    """Mode by mode with DOP853 (rtol 1e-12, atol 1e-14) and terminal events; returns the final
    state and the solver's (t, δ, δ') samples. ``max_step``: the solver's largest step — events are
    found from sign changes between steps, so a velocity that dips below zero and back within one
    step (next to a grazing of the stick surface) is seen only with steps shorter than the dip."""
    st, r = system.law.stages, system.law.friction_levels
    bp, s, e = st.breakpoints, st.slopes, st.offsets
    k, c = system.k, system.c

    def F(t):
        return system.excitation(t, omega)

    t, (d, v) = 0.0, x0
    j = int(np.searchsorted(bp, d, side="right"))
    sg = 0 if r[j] == 0 else int(np.sign(v))
    stick = False
    ts, xs = [], []
    while True:
        if stick:
            fd = k * (s[j] * d + e[j])
            lo, hi = fd - k * r[j], fd + k * r[j]
            grid = np.linspace(t, t1, max(2, int((t1 - t) * 400)))
            out = np.flatnonzero((F(grid[1:]) > hi) | (F(grid[1:]) < lo))
            if not out.size:
                return np.array([d, 0.0]), np.concatenate(ts), np.hstack(xs)
            i = out[0]
            up = F(grid[i + 1]) > hi
            t = brentq(lambda q, hi=hi, lo=lo, up=up: (F(q) - hi) if up else (lo - F(q)), grid[i], grid[i + 1],
                       xtol=1e-15, rtol=1e-15)
            v, sg, stick = 0.0, (1 if up else -1), False
            continue
        jj, ss = j, sg

        def rhs(tt, x, jj=jj, ss=ss):
            return [x[1], F(tt) - c * x[1] - k * (s[jj] * x[0] + e[jj] + r[jj] * ss)]

        events = []
        for bound, direction, comp in ((jj - 1, -1, 0), (jj, 1, 0)):
            if 0 <= bound < len(bp):
                ev = _surface(bp[bound])
                ev.terminal, ev.direction = True, direction
                events.append((ev, "up" if direction > 0 else "down"))
        if ss != 0:
            ev = _velocity_zero()
            ev.terminal, ev.direction = True, -ss
            events.append((ev, "stop"))
        sol = solve_ivp(rhs, (t, t1), [d, v], method="DOP853", rtol=1e-12, atol=1e-14, max_step=max_step,
                        events=[ev for ev, _ in events], dense_output=True)
        ts.append(sol.t)
        xs.append(sol.y)
        if sol.status == 0:
            return sol.y[:, -1], np.concatenate(ts), np.hstack(xs)
        t, n = min((te[0], n) for n, te in enumerate(sol.t_events) if len(te))
        d, v = sol.sol(t)
        what = events[n][1]
        if what == "stop":
            v = 0.0
            R = F(t) - k * (s[jj] * d + e[jj])
            if abs(R) <= k * r[jj]:
                stick = True
            else:
                sg = 1 if R > 0 else -1
        else:
            d = bp[jj] if what == "up" else bp[jj - 1]
            j = jj + 1 if what == "up" else jj - 1
            sg = 0 if r[j] == 0 else (1 if v > 0 else -1)


def chain_reference(fs: System, z0, t1, omega, max_step: float = np.inf):
    """An independent integration of the Filippov system by scipy (DOP853, rtol 1e-12) with
    terminal events at every breakpoint, velocity zero and stick band edge; only constant friction
    levels (the mode logic written out again, one element at a time)."""
    sysm = fs.continuous()
    n, m = sysm.n, sysm.m
    A = sysm.element_rows
    B = sysm.element_columns
    r = np.array([fs.friction_levels(e)[0] for e in range(m)])
    assert all(np.all(fs.friction_levels(e) == r[e]) for e in range(m))

    def y_of(t, z, sigma):
        x, v = z[:n], z[n:]
        d = A @ x
        f = np.array([el.law.force(d[e]) for e, el in enumerate(sysm.elements)])
        g = f + np.where(sigma != 0, sigma * r, 0.0)
        return sysm.forcing(t, omega) - sysm.damping @ v - sysm.stiffness @ x - B @ g

    def lam(S, y):
        AS, BS = A[S], B[:, S]
        return np.linalg.solve(AS @ BS, AS @ y)

    def rhs(t, z, S, sigma):
        y = y_of(t, z, sigma)
        if S:
            y = y - B[:, S] @ lam(S, y)
        return np.concatenate((z[n:], y))

    def settle(t, z, S, sigma):
        S = sorted(S)
        for e in S:
            sigma[e] = 0  # a stuck element's torque is λ, not σ r
        while S:
            lm = lam(S, y_of(t, z, sigma))
            worst = np.argmax(np.abs(lm) - r[S])
            if abs(lm[worst]) - r[S][worst] <= 1e-12 * r[S][worst]:
                break
            e = S.pop(int(worst))
            sigma[e] = 1 if lm[worst] > 0 else -1
        for e in S:
            sigma[e] = 0
        return S, sigma

    t, z = 0.0, np.asarray(z0, float).copy()
    sigma = np.zeros(m)
    for e in range(m):
        if r[e] > 0:
            sigma[e] = np.sign(A[e] @ z[n:])
    S: list[int] = []
    while t < t1:
        evs = []
        for e, el in enumerate(sysm.elements):
            for dbp in el.breakpoints:
                ev = (lambda tt, zz, *_, e=e, dbp=dbp: A[e] @ zz[:n] - dbp)
                ev.terminal = True
                evs.append(("bp", e, ev))
            if r[e] > 0 and e not in S:
                ev = (lambda tt, zz, *_, e=e: A[e] @ zz[n:])
                ev.terminal = True
                ev.direction = -sigma[e]  # leaving σ's side only (it starts at rest after a release)
                evs.append(("v0", e, ev))
        for j, e in enumerate(S):
            def band(tt, zz, *_, j=j, e=e, S=tuple(S), sg=sigma.copy()):  # noqa: B008 - bound now
                return abs(lam(list(S), y_of(tt, zz, sg))[j]) - r[e]
            band.terminal = True
            band.direction = 1
            evs.append(("band", e, band))
        sol = solve_ivp(rhs, (t, t1), z, method="DOP853", rtol=1e-12, atol=1e-15, args=(list(S), sigma.copy()),
                        events=[e[2] for e in evs], max_step=min(max_step, 2 * math.pi / omega / 64))  # a held state's torque
        # still changes with F(t): steps no longer than the forcing allows, or a band exit is stepped over
        t, z = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status != 1:
            break
        hit = min((abs(float(te[-1]) - t), i) for i, te in enumerate(sol.t_events) if te.size)
        kind, e, _ = evs[hit[1]]
        if kind == "v0":
            z[n:] -= A[e] * (A[e] @ z[n:]) / (A[e] @ A[e])
            S, sigma = settle(t, z, S + [e], sigma)
        elif kind == "band":
            lm = lam(S, y_of(t, z, sigma))[S.index(e)]
            S = [k for k in S if k != e]
            sigma[e] = 1 if lm > 0 else -1
        # a breakpoint: nothing changes in the mode (constant friction levels); restart past the kink
        t_next = t + 1e-13 * max(1.0, t)
        if t_next < t1:
            z = z + (t_next - t) * rhs(t, z, S, sigma)
            t = t_next
    return z


__all__ = ["chain_reference", "single_reference"]
