"""Labels that are true: an interval where the computed branches are unstable is called "no
stable periodic solution" only when sub-harmonics were computed and a simulation found no
period there; otherwise the label says what is known. ``periodic_orbit`` lists every orbit it
found, of every period, the simulation's included."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import rattle
from rattle.analysis import confirm_with_sweep
from rattle.analysis._regimes import UNSTABLE_KINDS
from rattle.results import Region

FALSE_CLAIM = "no stable periodic solution"
GEAR = Path(__file__).parents[1] / "examples" / "gear_backlash.toml"


def _gaps(frf):
    return [r for r in frf.regions if r.kind in UNSTABLE_KINDS]


def test_reference_case_at_defaults_says_period_two_is_likely(reference_frf):
    """Without sub-harmonics, Ω 0.408–0.463 and 1.243–1.959 (bounded by period doublings, where a
    stable period-2 orbit exists) are labelled as such, never "no stable periodic solution"."""
    gaps = _gaps(reference_frf)
    spans = [(round(r.omega_min, 3), round(r.omega_max, 3)) for r in gaps]
    assert spans == [(0.408, 0.463), (1.243, 1.959)], spans
    for r in gaps:
        assert r.kind == "unstable_period_doubling"
        assert "period-2 motion likely" in r.label and "--subharmonics" in r.label
        assert FALSE_CLAIM not in r.label and not r.detail["subharmonics_computed"]
    assert FALSE_CLAIM not in reference_frf.summary()
    assert FALSE_CLAIM not in json.dumps(reference_frf.metadata()["regions"])


def test_the_figure_legend_says_what_is_known(reference_frf):
    import matplotlib.pyplot as plt

    fig, ax = reference_frf.plot()
    try:
        texts = [t.get_text() for t in ax.get_legend().get_texts()] + [t.get_text() for t in ax.texts]
    finally:
        plt.close(fig)
    assert any("period doubling" in t for t in texts)
    assert any("period 2\nlikely" == t for t in texts)
    assert not any(FALSE_CLAIM in t for t in texts)


def test_with_subharmonics_the_gap_is_covered_or_says_none_computed_is_stable(reference_model):
    # A sweep given to frequency_response labels the regions with what it saw (here a stand-in
    # that saw period 2 everywhere: it seeds nothing new, the branches explain it).
    grid = np.linspace(0.40, 0.47, 15)
    sweep = SimpleNamespace(omega=grid, period=np.full(grid.size, 2), rms=np.full(grid.size, 0.15),
                            state0=np.zeros((grid.size, 2)))
    frf = rattle.frequency_response(reference_model, omega=(0.40, 0.47), harmonics=16, subharmonics=True,
                                    sweep=sweep)
    assert any(r.kind == "subharmonic" and r.omega_min < 0.44 < r.omega_max for r in frf.regions)
    assert all("sweep_periods" in r.detail for r in frf.regions)
    for r in _gaps(frf):  # slivers between a period doubling and a fold of the period-2 branch
        assert r.kind == "no_stable_computed" and r.detail["subharmonics_computed"]
        assert FALSE_CLAIM not in r.label


def _sweep(omegas, periods):
    return SimpleNamespace(omega=np.asarray(omegas, dtype=float), period=np.asarray(periods))


def test_no_stable_periodic_only_with_subharmonics_computed_and_the_simulation_agreeing():
    computed = Region("no_stable_computed", 1.0, 2.0, "no stable orbit of period ≤ 4 computed",
                      {"subharmonics_computed": True, "max_period": 4})
    guessed = Region("unstable_period_doubling", 1.0, 2.0, "period-1 unstable (period doubling): …",
                     {"subharmonics_computed": False, "period": 1})
    chaotic = _sweep([1.2, 1.5, 1.8], [0, 0, 0])
    (a, b) = confirm_with_sweep((computed, guessed), chaotic)
    assert a.kind == "no_stable_periodic" and a.label.startswith(FALSE_CLAIM)
    assert b.kind == "unstable_period_doubling" and FALSE_CLAIM not in b.label  # sub-harmonics not computed
    (c,) = confirm_with_sweep((guessed,), _sweep([1.2, 1.5], [2, 2]))
    assert "simulation: period 2" in c.label and c.detail["sweep_periods"] == [2]
    (d,) = confirm_with_sweep((computed,), _sweep([1.2, 1.5], [0, 4]))
    assert d.kind == "no_stable_computed" and "period 4" in d.label


def test_a_failed_sweep_frequency_adds_no_period_to_a_label():
    """A sweep row whose steady state failed (period −1) saw nothing: it is counted, never said."""
    guessed = Region("unstable_period_doubling", 1.0, 2.0, "period-1 unstable (period doubling): …",
                     {"subharmonics_computed": False, "period": 1})
    computed = Region("no_stable_computed", 1.0, 2.0, "no stable orbit of period ≤ 4 computed",
                      {"subharmonics_computed": True, "max_period": 4})
    (a,) = confirm_with_sweep((guessed,), _sweep([1.2, 1.5, 1.8], [-1, 2, -1]))
    assert "simulation: period 2 " in a.label and "period -1" not in a.label
    assert a.detail["sweep_periods"] == [2] and a.detail["sweep_failed"] == 2
    (b,) = confirm_with_sweep((computed,), _sweep([1.2, 1.5], [-1, -1]))  # nothing seen: nothing said
    assert b.kind == "no_stable_computed" and b.label == computed.label
    assert b.detail["sweep_periods"] == [] and b.detail["sweep_failed"] == 2
    (c,) = confirm_with_sweep((computed,), _sweep([1.2, 1.5, 3.0], [0, 0, -1]))  # the failure lies outside
    assert c.kind == "no_stable_periodic" and "sweep_failed" not in c.detail


def test_cli_frf_prints_no_false_label(tmp_path):

    from _cli_helpers import invoke, write_config
    config = write_config(tmp_path)
    out = tmp_path / "out"
    result = invoke(["frf", str(config), "--omega-min", "0.38", "--omega-max", "0.5", "--harmonics", "16",
                     "-o", str(out)], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert FALSE_CLAIM not in result.stdout and "period-2 motion likely" in result.stdout
    regions = json.loads((out / "frf.json").read_text())["regions"]
    assert [r["kind"] for r in regions if r["kind"] in UNSTABLE_KINDS] == ["unstable_period_doubling"]


@pytest.fixture(scope="module")
def gear_orbit():
    case = rattle.load_case(GEAR)
    return rattle.periodic_orbit(case.model, 0.6538, harmonics=case.analysis.harmonics, search_range=(0.6, 0.7))


def test_gear_orbit_at_0_6538_lists_the_stable_period_two_orbit(gear_orbit):
    """Between the period doublings at 0.64016 and 0.65668 the small single-sided period-1 orbit
    is unstable (multiplier < −1); started next to it the simulation settles on a stable period-2
    orbit, which must be listed, polished by HB of period 2 and marked as found by simulation."""
    p2 = gear_orbit.of_period(2)
    assert len(p2) == 1 and p2[0].stable and p2[0].source == "simulation" and p2[0].simulated
    assert p2[0].residual < 1e-8
    # The exact period-2 orbit through the HB orbit's state at t = 0.
    h = gear_orbit.time_history(gear_orbit.solutions.index(p2[0]), samples=64)
    exact = rattle.shoot_periodic_orbit(gear_orbit.model, 0.6538, (h["delta"][0], h["velocity"][0]), period=2)
    assert exact.converged and exact.stable and p2[0].rms == pytest.approx(exact.rms, rel=1e-4)
    # The orbit the simulation from rest settles on is marked too.
    sim_rms = gear_orbit.simulated_rms
    assert any(s.simulated and abs(s.rms - sim_rms) < 1e-6 for s in gear_orbit.solutions)
    assert any(not s.stable and s.multipliers[0].real < -1 for s in gear_orbit.of_period(1))  # its parent
    assert "period 2" in gear_orbit.summary()
    assert {s["simulated"] for s in gear_orbit.metadata()["solutions"]} == {True, False}


def test_compare_labels_the_interval_with_what_the_sweep_saw(reference_model):
    cmp = rattle.compare(reference_model, omega=(0.40, 0.47), harmonics=16, points=5, at=[0.44])
    (gap,) = _gaps(cmp.frf)
    assert gap.kind == "unstable_period_doubling" and 2 in gap.detail["sweep_periods"]
    assert "simulation: period 2" in gap.label and FALSE_CLAIM not in gap.label
    assert FALSE_CLAIM not in cmp.summary()
    assert 2 in {s.period for s in cmp.orbits[0].solutions}


def test_cli_orbit_on_the_gear_example_lists_the_period_two_orbit(tmp_path):

    from _cli_helpers import invoke
    out = tmp_path / "out"
    result = invoke(["orbit", str(GEAR), "--omega", "0.6538", "--omega-min", "0.6", "--omega-max", "0.7",
                     "-o", str(out)], tmp_path)
    assert result.exit_code == 0, result.stderr
    assert "period 2, rms 0.2274" in result.stdout and "from simulation" in result.stdout
    sols = json.loads((out / "orbit.json").read_text())["solutions"]
    assert any(s["period"] == 2 and s["stable"] and s["simulated"] for s in sols)
