"""Cases shared by the tests: the reference clutch and the torque converter's preloaded spring as
TOML, the chain with a lock-up clutch, the clutch-and-gear chain with friction per stage; and the
state at t = 0 of a harmonic-balance row, the start of exact shooting from it."""

from __future__ import annotations

import numpy as np

from rattle.hb import FourierBasis
from rattle.model import (
    Backlash, Chain, Clutch, Element, Excitation, Friction, Link, NonsmoothLaw, Preload, System, Torque,
)


def lockup_chain() -> Chain:
    """A grounded 3-inertia chain with a torque-converter lock-up clutch (a torque jump ±0.03 K_e
    at δ = 0, friction 0.01) between inertias 1 and 2 and a gear with backlash (b = 0.02) between
    2 and 3, forced by 0.05 + 0.1 cos Ωt on inertia 1 (benchmarks/bench_friction_chain.py
    ``--case preload``, examples/chain_lockup_clutch.toml)."""
    return Chain(inertias=(1.0, 0.5, 2.0),
                 links=(Link(between=(1, 0), stiffness=0.5, damping=0.05), Link(between=(2, 3), damping=0.05),
                        Link(between=(3, 0), stiffness=1.0, damping=0.1)),
                 elements=(Element(name="tcc", between=(1, 2), stiffness=1.0, law=Preload(preload=0.03),
                                   friction=Friction(levels=0.01)),
                           Element(name="gear", between=(2, 3), stiffness=3.0, law=Backlash(b=0.02))),
                 torques=(Torque(inertia=1, mean=0.05, amplitudes=(0.1,)),))


def clutch_gear_chain(levels: tuple[float, ...] | None = (0.02, 0.05, 0.02), amplitude: float = 0.1,
                      speed_order: float | None = None) -> Chain:
    """The grounded 3-inertia chain of the friction benchmarks (benchmarks/bench_friction_chain.py):
    a clutch (α = 0.2, b = 0.1) with friction ``levels`` per stage (None: none) between inertias 1
    and 2 and a gear with backlash (b = 0.02) between 2 and 3, forced by 0.05 + ``amplitude`` cos Ωt
    on inertia 1 (``speed_order``: an engine order for the rpm column). With the default levels
    the clutch sticks part of every period near Ω = 1.3."""
    return Chain(inertias=(1.0, 0.5, 2.0),
                 links=(Link(between=(1, 0), stiffness=0.5, damping=0.05), Link(between=(2, 3), damping=0.05),
                        Link(between=(3, 0), stiffness=1.0, damping=0.1)),
                 elements=(Element(name="clutch", between=(1, 2), stiffness=1.0, law=Clutch(alpha=0.2, b=0.1),
                                   friction=None if levels is None else Friction(levels=levels)),
                           Element(name="gear", between=(2, 3), stiffness=3.0, law=Backlash(b=0.02))),
                 torques=(Torque(inertia=1, mean=0.05, amplitudes=(amplitude,)),), speed_order=speed_order)


def clutch_toml(omega: tuple[float, float] = (0.1, 3.0), harmonics: int = 32) -> str:
    """The paper's reference clutch as a configuration file, over ``omega`` with ``harmonics``."""
    return f"""\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "clutch"
alpha = 0.25
b = 0.174533

[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
omega = [{omega[0]!r}, {omega[1]!r}]
harmonics = {harmonics}
"""


def preload_spring_toml(omega: tuple[float, float], harmonics: int | None = None, friction: float | None = 0.02) -> str:
    """The torque converter's preloaded spring (T_p = 0.03) with friction r = ``friction`` (None:
    none), K = I = 1, C = 0.05, F = 0.05 + 0.03 cos Ωt, as a configuration file over ``omega``
    (with ``harmonics`` when given): with r = 0.02 it sticks part of every period at Ω = 0.5 … 0.7;
    without friction it is examples/torque_converter_preload.toml."""
    lines = f"omega = [{omega[0]!r}, {omega[1]!r}]\n" + ("" if harmonics is None else f"harmonics = {harmonics}\n")
    rub = "" if friction is None else f"friction = {friction!r}\n"
    return f"""\
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0

[model.elastic]
type = "preload"
preload = 0.03
{rub}
[excitation]
mean = 0.05
amplitudes = [0.03]

[analysis]
{lines}"""


def hb_state0(frf, i):
    """(δ(0), δ'(0)) of row i of a single equation's frequency response: a start for exact shooting."""
    q = frf.coefficients[i]
    H = frf.harmonics
    w = frf.omega[i] / frf.period[i]
    k = np.arange(1, H + 1)
    return np.array([q[0] + q[1: H + 1].sum(), np.sum(k * w * q[H + 1:])])


def hb_chain_state0(frf, i):
    """(x(0), x'(0)) of row i of a chain's frequency response: a start for exact shooting."""
    n = frf.model.system().n
    H = frf.harmonics
    Q = frf.coefficients[i].reshape(n, 2 * H + 1)
    basis = FourierBasis(H, 4 * (2 * H + 1))
    w = float(frf.omega[i] / frf.period[i])
    return np.array([basis.evaluate(r, w, 0.0, derivative=k) for k in (0, 1) for r in Q], dtype=float)


def random_preload(seed: int, omega: tuple[float, float] = (0.4, 1.6), span: float = 1.1, offset: int = 0
                   ) -> tuple[System, tuple[float, float]]:
    """A random preload law (a clearance on odd seeds, friction per stage on two of three seeds),
    forcing with a second harmonic, and the range (Ω₀, ``span`` Ω₀) for Ω₀ drawn from ``omega``;
    the numbers from the generator of ``offset + seed``: the random cases of the exact-shooting
    tests (offset 0) and of benchmarks/crossval_shooting_stability.py (offset 1000)."""
    rng = np.random.default_rng(offset + seed)
    b = [0.0, 0.05][seed % 2]
    fr = None if seed % 3 == 0 else Friction(levels=tuple(rng.uniform(0.0, 0.01, 3 if b else 2)))
    law = NonsmoothLaw(elastic=Preload(preload=rng.uniform(0.005, 0.03), clearance=b, slope=rng.uniform(0.6, 1.4)),
                       friction=fr)
    system = System.single(damping=rng.uniform(0.03, 0.1), stiffness=1.0, law=law,
                             excitation=Excitation(mean=rng.uniform(-0.02, 0.05),
                                                   amplitudes=(rng.uniform(0.03, 0.1), rng.uniform(0.0, 0.02)),
                                                   phases=(0.0, rng.uniform(0.0, 6.0))))
    w = rng.uniform(*omega)
    return system, (w, span * w)


def friction_chain() -> System:
    """Three inertias, a clutch with Coulomb friction and a gear backlash: the friction chain of the
    exact-shooting tests and of benchmarks/crossval_shooting_stability.py."""
    chain = Chain(
        inertias=(1.0, 0.5, 2.0),
        links=(Link(between=(2, 3), stiffness=0.6, damping=0.03), Link(between=(3, 0), stiffness=0.4, damping=0.04)),
        elements=(
            Element(name="clutch", between=(1, 2), stiffness=1.5, law=Clutch(alpha=0.2, b=0.05),
                    friction=Friction(levels=0.02)),
            Element(name="gear", between=(2, 3), stiffness=2.0, law=Backlash(b=0.02)),
        ),
        torques=(Torque(inertia=1, mean=0.02, amplitudes=(0.25,), phases=(0.0,)),),
    )
    return chain.friction_system()
