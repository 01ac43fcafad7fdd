"""Chains of inertias (SPEC §5) and their reduction to the equations the numerics see."""

import numpy as np
import pytest

import rattle
from rattle.model import Backlash, Chain, Clutch, Element, Link, Piecewise, Torque


def _two_inertia(I1, I2, c=0.05, alpha=0.25, b=rattle.model.library.REFERENCE_B, Fm=0.05, Fp=(0.03,), phases=None):
    """The free two-inertia chain whose relative angle obeys the reference single equation
    δ'' + c δ' + f(δ) = F_m + F_p cos(Ωt) (K = I = 1 after the reduction)."""
    I = I1 * I2 / (I1 + I2)
    Tm = Fm / (1 / I1 + 1 / I2)
    return Chain(
        inertias=(I1, I2),
        links=(Link(between=(1, 2), damping=c * I),),
        elements=(Element(name="clutch", between=(1, 2), stiffness=I, law=Clutch(alpha=alpha, b=b)),),
        torques=(Torque(inertia=1, mean=Tm, amplitudes=tuple(a * I1 for a in Fp), phases=phases),
                 Torque(inertia=2, mean=-Tm)),
    )


@pytest.mark.parametrize("I1, I2", [(2.0, 2.0), (3.0, 1.5), (0.1, 40.0)])
def test_two_inertia_free_chain_is_the_single_equation(I1, I2):
    ref = rattle.reference_case().system()
    s = _two_inertia(I1, I2).system()
    assert s.n == 1 and s.m == 1 and s.free
    for name in ("damping", "stiffness", "mean", "cos", "sin"):
        np.testing.assert_allclose(getattr(s, name), getattr(ref, name), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(s.elements[0].a, ref.elements[0].a, rtol=1e-13)
    np.testing.assert_allclose(s.elements[0].b, ref.elements[0].b, rtol=1e-13)
    np.testing.assert_allclose(s.static_equilibrium(), ref.static_equilibrium(), rtol=1e-12)


def _three_chain(ground: bool):
    links = [Link(between=(1, 2), damping=0.03, stiffness=0.5), Link(between=(2, 3), damping=0.02)]
    if ground:
        links.append(Link(between=(3, 0), stiffness=2.0, damping=0.01))
    torques = [Torque(inertia=1, mean=0.05, amplitudes=(0.03, 0.01), phases=(0.2, -1.0))]
    if not ground:
        torques.append(Torque(inertia=3, mean=-0.05))
    return Chain(
        inertias=(1.0, 2.0, 1.5),
        links=tuple(links),
        elements=(
            Element(name="clutch", between=(1, 2), stiffness=1.0, law=Clutch(alpha=0.25, b=0.17)),
            Element(name="gear", between=(2, 3), stiffness=4.0,
                    law=Piecewise(breakpoints=(-0.05, 0.04), slopes=(1.0, 0.0, 1.0))),
        ),
        torques=tuple(torques),
    )


@pytest.mark.parametrize("ground", [False, True])
def test_reduced_equations_equal_the_absolute_ones(ground):
    """x'' from the reduced System equals D θ'' from M θ'' = T − C θ' − K θ − Σ w K f(w θ)."""
    chain = _three_chain(ground)
    s = chain.system()
    M, Ct, Kt = chain.matrices()
    Tm, Th = chain.torque_vectors()
    rng = np.random.default_rng(3)
    N = chain.n_inertias
    D = np.eye(N) if ground else (np.eye(N) - np.eye(N, k=1))[: N - 1]
    for _ in range(20):
        th, dth = rng.normal(scale=0.2, size=N), rng.normal(scale=0.3, size=N)
        t, Om = rng.uniform(0, 10), rng.uniform(0.3, 3)
        T = Tm + sum((Th[h] * np.exp(1j * (h + 1) * Om * t)).real for h in range(Th.shape[0]))
        f = sum(np.outer(chain._w(e.between), 1)[:, 0] * e.stiffness * e.law.force(chain._w(e.between) @ th)
                for e in chain.elements)
        ddth = np.linalg.solve(M, T - Ct @ dth - Kt @ th - f)
        x, dx = D @ th, D @ dth
        ddx = s.forcing(t, Om) - s.damping @ dx - s.restoring(x)
        np.testing.assert_allclose(ddx, D @ ddth, rtol=1e-12, atol=1e-13)
        if not ground:  # θ − θ_N 1 = Z x
            np.testing.assert_allclose(s.angles @ x, th - th[-1], atol=1e-14)


def test_static_equilibrium_solves_the_mean_balance():
    for ground in (False, True):
        s = _three_chain(ground).system()
        xs = s.static_equilibrium()
        np.testing.assert_allclose(s.restoring(xs), s.mean, atol=1e-14)


def test_static_equilibrium_centres_a_balanced_gap():
    chain = Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 2), damping=0.1),),
                  elements=(Element(name="gear", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1)),),
                  torques=(Torque(inertia=1, amplitudes=(0.1,)),))
    assert chain.system().static_equilibrium() == pytest.approx([0.0], abs=1e-15)


def test_chain_refusals():
    el = (Element(name="e", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1)),)
    with pytest.raises(ValueError, match="summing to zero"):
        Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 2), damping=0.1),), elements=el,
              torques=(Torque(inertia=1, mean=0.1),))
    with pytest.raises(ValueError, match="separate chains"):
        Chain(inertias=(1.0, 1.0, 1.0), elements=el)
    with pytest.raises(ValueError, match="reach ground"):
        Chain(inertias=(1.0, 1.0, 1.0), links=(Link(between=(1, 0), stiffness=1.0),), elements=el)
    with pytest.raises(ValueError, match="unique"):
        Chain(inertias=(1.0, 1.0), elements=el + el)
    with pytest.raises(ValueError, match=r"inertia number 1 … 2"):
        Chain(inertias=(1.0, 1.0), elements=(Element(name="e", between=(1, 3), stiffness=1.0, law=Backlash(b=0.1)),))
    with pytest.raises(ValueError, match="inertias\\[1\\]"):
        Chain(inertias=(1.0, -1.0), elements=el)
    with pytest.raises(ValueError, match="at least one clearance element"):
        Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 2), stiffness=1.0),), elements=())
    with pytest.raises(ValueError, match="identifier"):
        Element(name="my clutch", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1))
    with pytest.raises(ValueError, match="damping"):
        rattle.model.check_analysable_model(Chain(inertias=(1.0, 1.0), elements=el))


def test_parts_refuse_malformed_arguments_naming_them():
    el = (Element(name="e", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1)),)
    with pytest.raises(TypeError, match="`links` must be a list or tuple of Link"):
        Chain(inertias=(1.0, 1.0), links=Link(between=(1, 2), damping=0.1), elements=el)
    with pytest.raises(TypeError, match="`elements` must be a list or tuple of Element"):
        Chain(inertias=(1.0, 1.0), elements=el[0])
    with pytest.raises(TypeError, match=r"`between` must be a pair"):
        Link(between=(1, 2, 3))
    with pytest.raises(TypeError, match=r"`between\[1\]` must be an integer"):
        Element(name="e", between=(1, "2"), stiffness=1.0, law=Backlash(b=0.1))
    with pytest.raises(TypeError, match=r"`between\[0\]` must be an integer"):
        Link(between=(True, 2))
    with pytest.raises(TypeError, match="`law` must be an elastic law"):
        Element(name="e", between=(1, 2), stiffness=1.0, law="clutch")
    with pytest.raises(ValueError, match=r"`inertias\[1\]` must be finite"):
        Chain(inertias=(1.0, float("nan")), elements=el)


def test_grounded_chain_whose_mean_torque_nothing_can_hold_is_refused():
    """Tied to ground by a damper only: the mean torque turns it without end (no equilibrium)."""
    with pytest.raises(ValueError, match="`torques`: the mean torques cannot be balanced"):
        Chain(inertias=(1.0, 1.0), links=(Link(between=(1, 0), damping=0.1),),
              elements=(Element(name="e", between=(1, 2), stiffness=1.0, law=Backlash(b=0.1)),),
              torques=(Torque(inertia=1, mean=0.1),))
