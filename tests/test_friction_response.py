"""The frequency response of a chain with Coulomb friction, every row checked by exact shooting.

A grounded chain of 3 inertias: a clutch (Clutch law: a soft first stage over a backlash, friction
levels per stage) between inertias 1 and 2, a gear with backlash between 2 and 3 (no friction).
:func:`rattle.analysis.friction_response` continues the regularised HB (ε = 0.01, H = 32) and
checks each row against the exact event-driven orbit (Filippov sticking, saltation monodromy):
- heavy friction (13 rows): the clutch sticks 8.6–17.5 % of every period; the HB at ε = 0.01 is
  0.9–2.8 % off (the regularisation: sticking becomes creeping), its ε → 0 estimate (ladder to
  ε = 1e-3, H ≤ 64, Richardson) within 0.5 % of the exact rms on every row (measured ≤ 0.25 %);
  the branch loses stability inside the range (a Neimark–Sacker and a period-doubling label),
  the exact and the HB orbit's stability agree on every row;
- light friction (30 rows): the clutch slips throughout; the HB at ε = 0.01 within 0.5 % directly
  (measured ≤ 0.018 %; max |μ| of the two agree to 3e-8);
- without friction the whole-law System's branch is the smooth chain's: the exact rms equal to
  :func:`rattle.timeint.shoot_system_orbit`'s to 1e-9 and the HB within 0.5 % (measured 1.2e-5).
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from rattle.analysis import RegularisationOptions, frequency_response
from rattle.analysis._friction_response import friction_response
from rattle.analysis._nonsmooth import nonsmooth_response
from rattle.analysis._friction_response import _start, friction_balance_factory
from rattle.analysis._regularisation import regularisation_limit
from rattle.continuation import ContinuationOptions
from rattle.model import Chain, System
from rattle.results import FrequencyResponse, FrictionCheck
from rattle.timeint import shoot_friction_orbit, shoot_system_orbit

from _cases import clutch_gear_chain, lockup_chain  # tests/ is on sys.path through its conftest

STICK = (0.02, 0.05, 0.02)  # friction levels per clutch stage (relative to its stiffness)
SLIP = (0.01, 0.03, 0.01)
WIDE = ContinuationOptions(max_step=0.3)


def _chain(levels: tuple[float, ...] | None, amplitude: float, speed_order: float | None = None) -> Chain:
    return clutch_gear_chain(levels, amplitude, speed_order)


@pytest.fixture(scope="module")
def sticking() -> FrictionCheck:
    fs = _chain(STICK, 0.1).friction_system()
    return friction_response(fs, (1.25, 1.35), RegularisationOptions(harmonics=32, limit_harmonics=64),
                             continuation=WIDE)


@pytest.fixture(scope="module")
def slipping() -> FrictionCheck:
    fs = _chain(SLIP, 0.2, speed_order=2.0).friction_system()
    return friction_response(fs, (1.28, 1.3), RegularisationOptions(harmonics=32), continuation=WIDE)


def test_sticking_rows_match_the_exact_orbit_at_the_regularisation_limit(sticking: FrictionCheck) -> None:
    r = sticking
    assert len(r) >= 5 and r.status.success
    assert np.all(r.matched)
    assert np.all(r.stick_fraction[:, 0] > 0.05)  # the clutch sticks on every row (measured 8.6–17.5 %)
    assert np.all(r.stick_fraction[:, 1] == 0.0)  # the gear has no friction
    # At ε = 0.01 the regularisation is visible (sticking is creeping): measured 0.9–2.8 %.
    assert np.max(np.abs(r.rms_error)) > 0.005
    # Every such row was refined; the HB's ε → 0 estimate is within 0.5 % of the exact rms.
    np.testing.assert_array_equal(r.limit_index, np.arange(len(r)))
    assert np.all(r.limit_eps == pytest.approx(1e-3))
    assert np.all(r.hb_error <= 0.005)
    # Exact stability (saltation monodromy of the exact orbit) agrees with the HB orbit's.
    np.testing.assert_array_equal(r.stable, r.stable_hb)
    np.testing.assert_array_equal(r.stable, r.stable_hb_limit)  # and the HB at ε = 1e-3
    assert r.limit_multipliers is not None and np.all(np.isfinite(r.limit_multipliers))
    assert np.any(~r.stable) and np.any(r.stable)  # a stability change inside the range
    assert set(r.bifurcation[r.bifurcation != ""]) <= {"fold", "period_doubling", "neimark_sacker"}
    assert np.any(r.bifurcation != "")


def test_slipping_rows_match_the_exact_orbit_at_eps(slipping: FrictionCheck) -> None:
    r = slipping
    assert len(r) >= 3 and np.all(r.matched)
    assert np.all(r.stick_fraction == 0.0)
    assert np.all(np.abs(r.element_rms_error) <= 0.005)
    assert r.limit_index.size == 0  # nothing to refine
    np.testing.assert_array_equal(r.stable, r.stable_hb)
    np.testing.assert_allclose(r.mu_abs, r.mu_hb_abs, atol=1e-4)  # measured 3e-8
    np.testing.assert_allclose(r.rpm, r.omega * 60.0 / (2.0 * math.pi * 2.0))


def test_without_friction_it_is_the_smooth_chains_exact_orbit() -> None:
    chain = _chain(None, 0.2)
    system = chain.system()
    fs = system.with_friction((0.0, 0.0))
    assert not fs.has_friction
    r = friction_response(fs, (1.28, 1.3), RegularisationOptions(harmonics=32), continuation=WIDE)
    assert np.all(r.matched) and np.all(r.stick_fraction == 0.0)
    for i in (0, len(r) - 1):
        pb = friction_balance_factory(fs)(0.01, 32)
        ref = shoot_system_orbit(system, float(r.omega[i]), _hb_state(fs, float(r.omega[i])))
        assert ref.converged
        np.testing.assert_allclose(r.rms[i], ref.measures.rms, rtol=1e-9)
        assert pb.size == 3 * 65
    assert np.all(np.abs(r.element_rms_error) <= 0.005)


def _hb_state(fs: System, omega: float) -> np.ndarray:
    """A start for the smooth shooting: the regularised HB orbit's state at t = 0."""
    make = friction_balance_factory(fs)
    lad = regularisation_limit(make, omega, make(0.1, 32).linear_solution(omega), eps_start=0.1, eps_min=0.01,
                               harmonics=32, max_harmonics=32, tail_tol=math.inf)
    return make(0.01, 32).state_at_zero(lad.last.q, omega)


def test_chain_ladder_records_every_element() -> None:
    fs = _chain(STICK, 0.1).friction_system()
    make = friction_balance_factory(fs)
    w = 1.3
    q = _start(make, w, 0.01, 32, None)
    lad = regularisation_limit(make, w, q, eps_start=0.01, eps_min=2.5e-3, harmonics=32, max_harmonics=32)
    assert [s.eps for s in lad.steps] == pytest.approx([0.01, 0.005, 2.5e-3])
    for s in lad.steps:
        assert s.element_rms is not None and s.element_rms.shape == (2,)
        assert s.rms == pytest.approx(float(np.max(s.element_rms)))
    ext = lad.extrapolated_element_rms
    a, b = lad.steps[-2].element_rms, lad.steps[-1].element_rms
    np.testing.assert_allclose(ext, b - 2.5e-3 * (b - a) / (2.5e-3 - 5e-3))


def test_columns_csv_and_json(sticking: FrictionCheck, slipping: FrictionCheck, tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = FrequencyResponse.from_check(sticking, model=None, settings={}, timings={}).to_csv(tmp_path / "friction.csv")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    header = rows[0]
    assert header[:5] == ["branch", "period", "omega", "clutch_rms", "clutch_rms_hb"]
    for name in ("clutch", "gear"):
        for col in ("rms", "rms_hb", "mean", "stick", "rms_error", "rms_hb_limit", "rms_hb_extrapolated"):
            assert f"{name}_{col}" in header
    for col in ("matched", "stable", "stable_hb", "stable_hb_limit", "mu_abs", "mu_hb_abs", "rms_error", "bifurcation"):
        assert col in header
    assert "speed_rpm" not in header and len(rows) == len(sticking) + 1
    i = header.index("clutch_rms")
    np.testing.assert_allclose([float(x[i]) for x in rows[1:]], sticking.rms[:, 0], rtol=1e-12)
    assert slipping.column_names()[:4] == ["branch", "period", "omega", "speed_rpm"]
    doc = json.loads(json.dumps(sticking.to_dict()))
    assert doc["metadata"]["rows"] == len(sticking) and doc["metadata"]["matched"] == len(sticking)
    assert doc["metadata"]["elements"] == ["clutch", "gear"]
    text = sticking.summary()
    assert "clutch sticks" in text and "matched on" in text


def test_plot(sticking: FrictionCheck) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rattle.plotting import friction_response_plot

    fig, axes = friction_response_plot(sticking)
    assert len(axes["rms"].lines) >= 4 and axes["rms"].patches  # the stick range is shaded
    plt.close(fig)


def test_nonsmooth_response_dispatches_a_friction_system(slipping: FrictionCheck) -> None:
    fs = _chain(SLIP, 0.2, speed_order=2.0).friction_system()
    r = frequency_response(fs, (1.28, 1.3), options=RegularisationOptions(harmonics=32), continuation=WIDE)
    assert isinstance(r, FrequencyResponse) and isinstance(r.check, FrictionCheck)
    np.testing.assert_allclose(r.check.rms, slipping.rms, rtol=1e-12)
    np.testing.assert_allclose(r.rms, slipping.rms[:, 0], rtol=1e-12)  # the SPEC columns: the first element's
    assert r.column_names == slipping.column_names() and len(r) == len(slipping)


def test_regularised_stability_reads_the_hb_orbit(slipping: FrictionCheck) -> None:
    """``stability="regularised"``: the HB multipliers are the regularised chain's monodromy along
    the HB orbit (not the exact flow). On the slipping branch (friction reverses twice a period) the
    largest moduli agree with the exact orbit's to 1e-5 (measured 9e-7: the regularisation's and the
    midpoint rule's error); the exact columns are unchanged."""
    fs = _chain(SLIP, 0.2, speed_order=2.0).friction_system()
    r = friction_response(fs, (1.28, 1.3), RegularisationOptions(harmonics=32, stability="regularised"),
                          continuation=WIDE)
    assert len(r) == len(slipping) and np.all(r.matched)
    np.testing.assert_array_equal(r.rms, slipping.rms)
    np.testing.assert_array_equal(r.multipliers, slipping.multipliers)
    gap = np.abs(np.abs(r.multipliers_hb).max(axis=1) - np.abs(r.multipliers).max(axis=1))
    assert np.max(gap) <= 1e-5
    assert not np.array_equal(r.multipliers_hb, slipping.multipliers_hb)  # another method, another number


def test_bad_arguments_are_refused() -> None:
    fs = _chain(SLIP, 0.2).friction_system()
    with pytest.raises(TypeError, match="`system`"):
        friction_response(_chain(SLIP, 0.2), (1.28, 1.3))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="whole laws"):
        nonsmooth_response("chain", (1.28, 1.3))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="`options`"):
        friction_response(fs, (1.28, 1.3), {"harmonics": 32})  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        friction_response(fs, (1.7, 1.6), RegularisationOptions(harmonics=32))
    with pytest.raises(TypeError, match="`continuation`"):
        friction_response(fs, (1.28, 1.3), RegularisationOptions(harmonics=32), continuation=0.1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="`harmonics`"):
        RegularisationOptions(harmonics=0)


def test_bifurcation_labels_follow_stability_and_switching_pattern(sticking: FrictionCheck) -> None:
    """Every change of stability between matched rows carries its kind; every change of an
    element's stick phases or crossings without one is a grazing label; nothing else is labelled."""
    r = sticking
    m = np.flatnonzero(r.matched)
    assert r.pattern is not None and np.all(r.pattern[m] >= 0)
    k = len(r.element_names)
    want: dict[int, set[str]] = {}
    for i, j in zip(m, m[1:]):
        if r.stable[i] != r.stable[j]:
            want[int(j)] = {"fold", "period_doubling", "neimark_sacker"}
        elif np.any(r.pattern[i, :k] != r.pattern[j, :k]):
            want[int(j)] = {"grazing_sliding"}
        elif np.any(r.pattern[i, k:] != r.pattern[j, k:]):
            want[int(j)] = {"grazing"}
    labels = r.bifurcation
    assert {int(i) for i in np.flatnonzero(labels != "")} == set(want)
    assert all(labels[i] in kinds for i, kinds in want.items())


def test_a_start_where_newton_fails_from_the_linear_solution_uses_the_exact_orbit() -> None:
    """At Ω_min = 1.52232 neither plain nor damped Newton converges from the linearised chain's
    solution (ε = 0.1 and 0.3); the start then takes the spectrum of the exact orbit (simulated
    and shot) and narrows ε from there: the branch starts, and its first row matches."""
    fs = _chain(STICK, 0.1).friction_system()
    res = friction_response(fs, (1.52232, 1.53), RegularisationOptions(harmonics=64, refine=None))
    assert len(res) >= 2 and res.omega[0] == pytest.approx(1.52232) and res.matched[0]
    assert np.abs(res.element_rms_error[0]).max() < 0.03


def test_without_options_a_chain_is_solved_at_its_own_default_regularisation() -> None:
    """options None: ε = 0.001 (a chain's velocity width is ~10× the single equation's at equal
    ε); the slipping branch is then within 0.5 % at ε on every row."""
    from rattle.analysis._friction_response import CHAIN_REGULARISATION

    r = friction_response(_chain(SLIP, 0.2).friction_system(), (1.28, 1.281), continuation=WIDE)
    assert r.regularisation == CHAIN_REGULARISATION == 0.001
    assert np.all(r.matched) and np.abs(r.element_rms_error).max() <= 0.005


def test_a_clutch_locked_part_of_the_period_is_matched_at_the_regularisations_limit() -> None:
    """At 0.76–0.78 ω_n the lock-up clutch is held ~45 % of the period (locked at its jump or
    stuck beside it) with an exact rms ~6e-4 rad; the HB at ε = 0.01 gives it a deflection of the
    jump's regularised width (ε_δ artanh(τ/T_p): rms ~2.7e-3, ~4× the exact one) and departs from
    the exact δ(t) by more than `match` of its own peak-to-peak, so the row is matched at the
    limit: the flow shot from the HB at the ladder's end (ε = 1e-3) against that HB, the held
    element measured on the chain's scale. The gear, moving freely, is within 1 % at ε."""
    fs = lockup_chain().friction_system()
    wn = fs.frequency_scale()
    opts = RegularisationOptions(harmonics=32, regularisation=0.01, refine=None, limit=0, limit_harmonics=32)
    r = friction_response(fs, (0.76 * wn, 0.78 * wn), opts, continuation=WIDE)
    assert len(r) >= 3 and np.all(r.matched)
    assert np.all(r.match_distance <= opts.match)
    held = r.stick_fraction[:, 0]
    assert np.all((held > 0.4) & (held < 0.5)), held
    assert np.all(r.stick_fraction[:, 1] == 0.0)  # the gear has no friction
    assert np.all(r.rms[:, 0] < 1e-3) and np.all(r.rms_hb[:, 0] > 3.0 * r.rms[:, 0])
    assert np.max(np.abs(r.element_rms_error[:, 1])) < 0.01
    # what the summary and frf.json say: the held clutch apart, the moving gear within 1 %
    np.testing.assert_allclose(r.moving_rms_error, np.abs(r.element_rms_error[:, 1]))
    md = r.metadata()
    assert md["held_rows"] == len(r) and md["within_0_5_percent"] == 0
    assert md["within_0_5_percent_moving"] == int(np.sum(np.abs(r.element_rms_error[:, 1]) <= 0.005))
    assert "resolves that element only to their width (`held` narrows its own steps)" in r.summary()
    # the plain check (departure relative to the element's own HB peak-to-peak at ε) fails here:
    make = friction_balance_factory(fs)
    pb, w = make(0.01, 32), float(r.omega[0])
    q = _start(make, w, 0.01, 32, None)
    orbit = shoot_friction_orbit(fs, w, pb.state_at_zero(q, w), max_iterations=30)
    assert orbit.converged and orbit.stick_fraction[0] > 0.4
    t = np.arange(64) * (2.0 * math.pi / w / 64)
    d_hb = pb.basis.evaluate(pb.element_series(q)[0], w, t)
    gap = np.max(np.abs(orbit.trajectory.element_samples(t)[0][:, 0] - d_hb)) / np.ptp(d_hb)
    assert gap > opts.match
    # both stability verdicts agree (the period-1 orbit with the gear rattling is unstable here)
    np.testing.assert_array_equal(r.stable, r.stable_hb)


def test_a_row_whose_own_shooting_fails_is_matched_from_its_neighbours_exact_orbit(slipping, monkeypatch):
    """Where the shooting from a row's HB state fails (near a fold the HB's error at ε moves that
    state out of Newton's reach), the row is shot again from the exact orbit of its nearest matched
    neighbour: with every shooting at one row's Ω forced to fail unless it starts on a known exact
    orbit, that row is still matched, on the same exact orbit (rms to 1e-9)."""
    import rattle.analysis._friction_response as module
    from rattle.errors import ConvergenceError

    k = len(slipping) // 2
    target, known = float(slipping.omega[k]), slipping.states[slipping.matched]
    real = module.shoot_friction_orbit

    def failing(system, omega, z0, **kwargs):  # type: ignore[no-untyped-def]
        if omega == target and not np.any(np.all(np.abs(known - np.asarray(z0)) <= 1e-13, axis=1)):
            raise ConvergenceError("forced to fail from the HB state")
        return real(system, omega, z0, **kwargs)

    monkeypatch.setattr(module, "shoot_friction_orbit", failing)
    fs = _chain(SLIP, 0.2, speed_order=2.0).friction_system()
    r = friction_response(fs, (1.28, 1.3), RegularisationOptions(harmonics=32), continuation=WIDE)
    assert len(r) == len(slipping) and r.omega[k] == target
    assert r.matched[k] and np.all(r.matched == slipping.matched)
    np.testing.assert_allclose(r.rms[k], slipping.rms[k], rtol=1e-9)
    assert r.match_distance[k] <= 0.1
