"""Systems built by hand for the System integrator tests:
M θ'' + C_θ θ' + K_θ θ + Σ w_eᵀ K_e f_e(w_e·θ) = T, reduced as in rattle.model._system."""

from __future__ import annotations

import math

import numpy as np

from rattle.model import Backlash, Clutch, ReducedElement, System

INERTIAS = (1.0, 2.0, 1.5)


def _assemble(links, n_inertias: int = 3):
    Kt = np.zeros((n_inertias, n_inertias))
    Ct = np.zeros((n_inertias, n_inertias))
    for i, j, k, c in links:  # j = -1: ground
        w = np.zeros(n_inertias)
        w[i] = 1.0
        if j >= 0:
            w[j] = -1.0
        Kt += k * np.outer(w, w)
        Ct += c * np.outer(w, w)
    return Kt, Ct


def _harmonics(amps, phases, torque_dir):
    cos = np.array([a * math.cos(p) * torque_dir for a, p in zip(amps, phases)])
    sin = np.array([-a * math.sin(p) * torque_dir for a, p in zip(amps, phases)])
    return cos, sin


def grounded_chain(amps=(0.1, 0.04), phases=(0.3, -1.0), mean=0.05) -> System:
    """Three inertias M = diag(1, 2, 1.5) grounded at both ends; a clutch (K = 1, α = 0.25,
    b = 0.1) between 1 and 2, a gear backlash (K = 2, b = 0.05) between 2 and 3; two forcing
    harmonics with phases and a mean torque on inertia 1."""
    Mi = np.diag(1.0 / np.array(INERTIAS))
    Kt, Ct = _assemble([(0, -1, 0.5, 0.03), (0, 1, 0.0, 0.05), (1, 2, 0.0, 0.04), (2, -1, 0.3, 0.02)])
    w12, w23 = np.array([1.0, -1.0, 0.0]), np.array([0.0, 1.0, -1.0])
    elements = (ReducedElement("clutch", w12, Mi @ w12 * 1.0, Clutch(alpha=0.25, b=0.1)),
                ReducedElement("gear", w23, Mi @ w23 * 2.0, Backlash(b=0.05)))
    T = np.array([1.0, 0.0, 0.0])
    cos, sin = _harmonics(amps, phases, Mi @ T)
    return System(damping=Mi @ Ct, stiffness=Mi @ Kt, elements=elements, mean=Mi @ (mean * T), cos=cos, sin=sin,
                  coordinates=("theta1", "theta2", "theta3"), angles=np.eye(3), free=False)


def free_chain(amps=(0.08, 0.03), phases=(0.0, 0.7), mean=0.05, gear_damping=0.0) -> System:
    """Three free inertias M = diag(1, 2, 1.5) in the relative coordinates x_k = θ_k − θ_{k+1}: a
    clutch (K = 1, α = 0.25, b = 0.1) with a damper (0.05) between 1 and 2, a gear backlash
    (K = 2, b = 0.05) between 2 and 3 with damper ``gear_damping`` (0: inside the gap the relative
    motion of {1, 2} and 3 is an undamped rigid mode, a defective zero eigenvalue); torques
    (mean, −mean) on inertias 1 and 3, harmonics on inertia 1."""
    Mi = np.diag(1.0 / np.array(INERTIAS))
    Kt, Ct = _assemble([(0, 1, 0.0, 0.05), (1, 2, 0.0, gear_damping)])
    D = np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0]])
    Z = np.array([[1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    w12, w23 = np.array([1.0, -1.0, 0.0]), np.array([0.0, 1.0, -1.0])
    elements = (ReducedElement("clutch", w12 @ Z, D @ Mi @ w12 * 1.0, Clutch(alpha=0.25, b=0.1)),
                ReducedElement("gear", w23 @ Z, D @ Mi @ w23 * 2.0, Backlash(b=0.05)))
    cos, sin = _harmonics(amps, phases, D @ Mi @ np.array([1.0, 0.0, 0.0]))
    return System(damping=D @ Mi @ Ct @ Z, stiffness=D @ Mi @ Kt @ Z, elements=elements,
                  mean=D @ Mi @ np.array([mean, 0.0, -mean]), cos=cos, sin=sin, coordinates=("x12", "x23"),
                  angles=Z, free=True)


def free_pair(damping: float, b: float = 0.5, mean: float = 0.05, amp: float = 0.03) -> System:
    """Two free inertias (1 and 2) joined by a backlash element (K = 1, half-gap ``b``) and a
    damper ``damping``: x = θ1 − θ2, x'' + 1.5 c x' + 1.5 f(x) = 1.5 mean + amp cos Ωt."""
    return System(damping=np.array([[1.5 * damping]]), stiffness=np.zeros((1, 1)),
                  elements=(ReducedElement("gap", np.array([1.0]), np.array([1.5]), Backlash(b=b)),),
                  mean=np.array([1.5 * mean]), cos=np.array([[amp]]), sin=np.zeros((1, 1)), coordinates=("x",),
                  angles=np.array([[1.0], [0.0]]), free=True)


def rhs(system: System, omega: float):
    """The right-hand side of z' for scipy's solve_ivp (the laws evaluated directly)."""
    n = system.n

    def f(t, z):
        x, v = z[:n], z[n:]
        return np.concatenate((v, system.forcing(t, omega) - system.damping @ v - system.restoring(x)))

    return f
