"""The time domain on chains: steady state with period detection on the System integrator, time
sweeps with per-element columns, periodic orbits and the time-domain confirmation of the
Neimark–Sacker intervals (one core, the single equation as its special case)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from rattle.analysis import frequency_response, periodic_orbit, time_sweep
from rattle.analysis._tori import confirm_tori, section_curve
from rattle.model import Chain, Clutch, reference_case
from rattle.model._stage_matrix import stage_transition
from rattle.analysis import SteadyStateOptions, steady_state
from rattle.timeint import ExactIntegrator

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def two_inertia() -> Chain:
    return Chain.from_toml(EXAMPLES / "chain_two_inertia.toml")


@pytest.fixture(scope="module")
def grounded() -> Chain:
    return Chain.from_toml(EXAMPLES / "grounded_two_inertia.toml")


@pytest.fixture(scope="module")
def driveline() -> Chain:
    return Chain.from_toml(EXAMPLES / "driveline_three_inertia.toml")


# --- steady state ----------------------------------------------------------------------------
@pytest.mark.parametrize("omega", [0.6, 1.1])
def test_two_inertia_chain_settles_like_the_single_equation(two_inertia: Chain, omega: float) -> None:
    """The free two-inertia chain is the reference case: the System path (ExactIntegrator,
    state (x, x')) settles on the orbit the single-equation path (ExactIntegrator) finds."""
    chain = steady_state(two_inertia, omega)
    # the example's b = 0.174533 (10° to six digits)
    model = dataclasses.replace(reference_case(), elastic=Clutch(alpha=0.25, b=0.174533))
    single = steady_state(model, omega)
    assert chain.period == single.period == 1
    assert chain.element_names == ("clutch",)
    for name in ("mean", "rms", "rms_ac", "p2p", "acc_p2p"):
        assert getattr(chain, name) == pytest.approx(getattr(single, name), rel=1e-8, abs=1e-12)
    np.testing.assert_allclose(np.abs(chain.multipliers), np.abs(single.multipliers), rtol=1e-7)
    assert chain.regime == single.regime
    assert chain.element("clutch")["rms"] == chain.rms


def test_chain_steady_state_measures_every_element(driveline: Chain) -> None:
    s = steady_state(driveline, 1.0)
    n = driveline.system().n
    assert s.period == 1 and s.settled
    assert s.state0.shape == (2 * n,) and s.multipliers.shape == (2 * n,)
    em = s.element_measures
    assert em.names == ("clutch", "gear")
    assert s.rms == em.rms[0] and s.p2p == em.p2p[0]
    assert len(s.regimes()) == 2
    # the orbit closes: one more forcing period from state0 returns to it
    z1, _ = ExactIntegrator(driveline.system()).advance(s.state0, 0.0, 2 * math.pi, 1.0)
    assert np.max(np.abs(z1 - s.state0)) < 1e-8


def test_chain_period_two_and_quasi_periodic(grounded: Chain) -> None:
    """Inside the period-doubling bubble of the grounded chain the motion is of period 2; in the
    Neimark–Sacker interval no period ≤ 8 settles (period 0, Poincaré points kept)."""
    p2 = steady_state(grounded, 0.765)
    assert p2.period == 2 and p2.cycle.shape == (2, 4)
    assert np.max(np.abs(p2.multipliers)) < 1.0
    qp = steady_state(grounded, 0.834, options=SteadyStateOptions(max_periods=300, record_periods=40,
                                                                   section_points=40))
    assert qp.period == 0 and qp.multipliers is None
    assert qp.poincare.shape == (40, 4)


def test_chain_steady_state_refuses_a_wrong_state(grounded: Chain) -> None:
    with pytest.raises(ValueError, match="`x0`"):
        steady_state(grounded, 0.6, (0.0, 0.0))


# --- sweeps -------------------------------------------------------------------------------------
def test_chain_sweep_has_element_columns(driveline: Chain, tmp_path: Path) -> None:
    r = time_sweep(driveline, (0.9, 1.3), 3, "both")
    assert r.element_names == ("clutch", "gear")
    cols = r.columns()
    assert list(cols)[:8] == ["direction", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "period"]
    assert [k for k in cols if k.startswith("gear_")] == [
        "gear_mean", "gear_rms", "gear_rms_ac", "gear_p2p", "gear_acc_p2p", "gear_regime"]
    np.testing.assert_array_equal(r.rms, r.element_columns["clutch_rms"])
    # one regime per element, each that of its own deflection: the first element's is `regime`
    assert list(r.element_columns["clutch_regime"]) == list(r.regime)
    for i, w in enumerate(r.omega[:3]):
        s = steady_state(driveline, float(w), r.state0[i])  # the row's own steady motion
        assert (r.element_columns["clutch_regime"][i], r.element_columns["gear_regime"][i]) == s.regimes()
    assert np.all(r.element_columns["gear_rms"] > 0)
    assert r.state0.shape == (6, 2 * driveline.system().n)
    up = r.select("up")
    assert len(up.element_columns["gear_rms"]) == 3
    path = r.to_csv(tmp_path / "sweep.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header[:8] == list(cols)[:8] and header[-1] == "gear_regime"
    assert header.index("clutch_regime") == header.index("clutch_acc_p2p") + 1


def test_single_equation_sweep_has_no_element_columns() -> None:
    r = time_sweep(reference_case(), (1.0, 1.2), 2, "up")
    assert r.element_columns == {} and list(r.columns()) == [
        "direction", "omega", "mean", "rms", "rms_ac", "p2p", "acc_p2p", "period", "regime"]


# --- orbits ---------------------------------------------------------------------------------------
def test_chain_periodic_orbit_finds_the_simulated_period_two(grounded: Chain, tmp_path: Path) -> None:
    po = periodic_orbit(grounded, 0.765, harmonics=8, search_range=(0.74, 0.79))
    assert po.simulated_period == 2
    p2 = po.of_period(2)
    assert p2 and p2[0].stable and p2[0].simulated
    assert set(p2[0].elements) == {"clutch"}
    assert p2[0].rms == pytest.approx(po.simulated_rms, rel=1e-3)  # H = 8 against the exact orbit
    path = po.to_csv(tmp_path / "orbit.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header == ["t", "delta", "velocity", "acceleration", "clutch_delta", "clutch_acceleration"]
    hist = po.simulated_history()
    assert hist is not None and "clutch_delta" in hist


# --- Neimark–Sacker confirmation ------------------------------------------------------------------
def test_section_curve_tells_a_closed_curve_from_a_cloud() -> None:
    k = np.arange(300)
    rho = 0.3137
    theta = 2 * np.pi * rho * k
    r = 1.0 + 0.2 * np.cos(theta)
    pts = np.column_stack((r * np.cos(theta), r * np.sin(theta), 0.1 * np.sin(2 * theta)))
    plane = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    curve = section_curve(pts, np.zeros(3), plane)
    assert curve["closed_curve"] and curve["rotation"] == pytest.approx(rho, abs=1e-12)
    cloud = np.random.default_rng(0).normal(size=(300, 3))
    assert not section_curve(cloud, np.zeros(3), plane)["closed_curve"]


def test_torus_region_is_confirmed_quasi_periodic(grounded: Chain) -> None:
    """The grounded chain's second Neimark–Sacker interval: the simulation from the perturbed
    unstable orbit settles on a torus (period 0, Poincaré points on a closed curve) whose
    rotation number is near the critical multipliers' θ/2π."""
    frf = frequency_response(grounded, (0.79, 0.88), 16, confirm_tori=False)
    tori = [r for r in frf.regions if r.kind == "torus"]
    assert len(tori) == 1
    (region,) = [r for r in confirm_tori(frf) if r.kind == "torus"]
    sim = region.detail["simulation"]
    assert region.detail["simulated_periods"] == [0]
    assert sim["closed_curve"] and sim["winds"]
    assert sim["rotation"] == pytest.approx(np.mean(region.detail["torus_ratio"]), abs=0.03)
    assert "quasi-periodic" in region.label and "rotation number" in region.label


def test_frequency_response_confirms_tori_by_default_only_where_there_are_some() -> None:
    frf = frequency_response(reference_case(), (1.0, 1.3), 8)
    assert "torus_simulations" not in frf.timings


# --- the one closed form ---------------------------------------------------------------------------
@pytest.mark.parametrize("damping", [0.0, 0.05, 2.0, 20.0])
def test_stage_transition_is_the_matrix_exponential(damping: float) -> None:
    from scipy.linalg import expm

    kappa = np.array([0.0, 1e-6, 0.25, 1.0, damping**2 / 4, 50.0])
    tau = np.linspace(0.3, 7.0, kappa.size)
    ref = np.array([expm(np.array([[0.0, 1.0], [-k, -damping]]) * t) for k, t in zip(kappa, tau)])
    np.testing.assert_allclose(stage_transition(kappa, damping, tau), ref, rtol=1e-9, atol=1e-12)
