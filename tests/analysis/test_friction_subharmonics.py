"""The period-2 branches of a chain with friction on its elements
(:func:`rattle.analysis.friction_subharmonics`, ``nonsmooth_response(..., subharmonics=True)`` on a
``rattle frf --subharmonics`` on such a chain).

The chain is tests/test_friction_response.py's sticking chain (a clutch with friction
0.02/0.05/0.02 per stage and a gear with backlash; the clutch sticks 12–17 % of the period). Its
period-1 branch doubles its period between Ω = 1.3177 and 1.3193 (ε = 0.001); the period-2 branch
born there is subcritical (a fold at Ω ≈ 1.316), and regains stability near 1.363.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from _cases import clutch_gear_chain
from _cli_helpers import invoke, write_config
from rattle.analysis import RegularisationOptions
from rattle.analysis._friction_subharmonics import friction_subharmonics
from rattle.analysis._nonsmooth import nonsmooth_response
from rattle.analysis._friction_response import period_gap
from rattle.continuation import ContinuationOptions
from rattle.io import read_csv
from rattle.model import Chain
from rattle.timeint import ExactIntegrator, shoot_friction_orbit

#: The period-2 branches of a chain with friction: the second tier (python3 -m pytest -m slow).
pytestmark = pytest.mark.slow

RANGE = (1.30, 1.38)
WIDE = ContinuationOptions(max_step=0.3)


def _chain() -> Chain:
    return clutch_gear_chain()  # the clutch sticks 12–17 % of the period near Ω = 1.3


@pytest.fixture(scope="module")
def response():
    opts = RegularisationOptions(harmonics=32, regularisation=0.001, limit_harmonics=64)
    return nonsmooth_response(_chain().friction_system(), RANGE, opts, continuation=WIDE, subharmonics=True)


@pytest.fixture(scope="module")
def wide_steps():
    """The same at ε = 0.01: the regularised creep moves the period doubling, and the HB of
    period 2 has no orbit next to the exact one."""
    opts = RegularisationOptions(harmonics=32, regularisation=0.01, limit_harmonics=64)
    return nonsmooth_response(_chain().friction_system(), (1.315, RANGE[1]), opts, continuation=WIDE,
                              subharmonics=True)


def test_one_period_two_branch_is_born_at_the_period_doubling(response):
    assert "period_doubling" in set(response.bifurcation.tolist())
    (br,) = response.branches
    assert (br.branch, br.period, br.followed) == (1, 2, "harmonic balance")
    assert br.origin.startswith("period doubling of the period-1 branch between")
    assert br.states is not None and br.matched.sum() >= 0.8 * len(br)
    # the branch is subcritical: it starts unstable, turns at a fold below the doubling and
    # regains stability further up (a period doubling of its own)
    assert np.min(br.omega) < 1.3177 and not br.stable[br.matched][0] and br.stable[br.matched][-1]


def test_every_matched_row_is_an_exact_orbit_of_period_two(response):
    """From each matched row's z(0), one exact shooting over two periods returns the same orbit
    (rms to 1e-9), and that orbit does not repeat after one period."""
    (br,) = response.branches
    system = _chain().friction_system()
    integ = ExactIntegrator(system)
    rows = np.flatnonzero(br.matched)
    for i in rows[:: max(1, rows.size // 6)]:
        w = float(br.omega[i])
        orbit = shoot_friction_orbit(system, w, br.states[i], period=2, integrator=integ)
        assert orbit.converged
        np.testing.assert_allclose(orbit.rms, br.rms[i], rtol=1e-9)
        assert period_gap(orbit.trajectory, w) > 1e-3


def test_the_hb_of_period_two_meets_the_exact_orbit_away_from_the_fold(response):
    """The period-2 HB (2H = 64 harmonics of Ω/2, ε = 0.001) against the exact orbits: the clutch
    sticks 12–17 % of the period, so the HB is off by the creep of its stick (as the period-1
    branch's at this ε). Measured: 60 rows, 50 matched, median error 0.69 %; at most 0.74 % on
    the 27 matched rows more than 0.005 above the fold (1.95 % next to it); its stability agrees
    on every matched row."""
    (br,) = response.branches
    m = br.matched
    fold = float(np.min(br.omega))
    away = m & (br.omega > fold + 0.005)
    assert away.sum() >= 20
    err = np.abs(br.rms_error[away])
    assert np.all(err < 0.01), float(np.max(err))
    assert np.all(br.stable[m] == br.stable_hb[m])


def test_a_long_simulation_settles_on_the_stable_period_two_orbit(response):
    """At Ω = 1.375 the period-1 orbit is unstable (beyond the doubling) and the branch is stable:
    300 forcing periods of the exact flow from the period-1 orbit's state, nudged, end on the
    branch's orbit (element rms over the last two periods within 1e-6)."""
    (br,) = response.branches
    i = int(np.argmin(np.abs(br.omega - 1.375)))
    assert br.matched[i] and br.stable[i]
    w = float(br.omega[i])
    system = _chain().friction_system()
    integ = ExactIntegrator(system)
    j = int(np.argmin(np.abs(response.omega - w)))
    one = shoot_friction_orbit(system, w, response.states[j], integrator=integ)
    assert one.converged and np.abs(one.multipliers).max() > 1.0
    z = one.state0 + 1e-4 * system.length_scale() * np.ones(2 * system.n)
    T = 2.0 * math.pi / w
    for _ in range(300):
        z = integ.advance(z, 0.0, T, w)[0]
    traj = integ.propagate(z, 0.0, 2.0 * T, w)
    _, rms = traj.element_mean_and_rms()
    np.testing.assert_allclose(rms, br.rms[i], rtol=1e-6)


def test_without_a_regularised_period_two_orbit_the_branch_is_followed_exactly(response, wide_steps):
    """At ε = 0.01 the HB of period 2 has none next to the exact seed: the branch is followed by
    exact shooting alone, no HB values, and its exact orbits are those the HB route at ε = 0.001
    found (the exact flow does not depend on ε): the rms at a common Ω agrees to 1e-8."""
    (br,) = wide_steps.branches
    assert br.followed == "exact shooting" and np.all(np.isnan(br.rms_hb)) and np.all(br.matched)
    assert "followed by exact shooting alone" in br.message
    (hb,) = response.branches
    system = _chain().friction_system()
    w = float(br.omega[-1])
    k = int(np.argmin(np.abs(hb.omega - w)))
    orbit = shoot_friction_orbit(system, w, hb.states[k], period=2)
    assert orbit.converged
    np.testing.assert_allclose(orbit.rms, br.rms[-1], rtol=1e-8)


def test_arguments_are_checked():
    system = _chain().friction_system()
    with pytest.raises(TypeError, match="`primary` must be the FrictionCheck"):
        friction_subharmonics(system, None, RANGE)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="`system` must be a rattle.model.System with its elements' whole laws"):
        friction_subharmonics(None, None, RANGE)  # type: ignore[arg-type]


CHAIN_TOML = """\
[model]
inertias = [1.0, 0.5, 2.0]

[[model.links]]
between = [1, 0]
stiffness = 0.5
damping = 0.05

[[model.links]]
between = [2, 3]
damping = 0.05

[[model.links]]
between = [3, 0]
stiffness = 1.0
damping = 0.1

[[model.elements]]
name = "clutch"
between = [1, 2]
stiffness = 1.0
type = "clutch"
alpha = 0.2
b = 0.1
friction = [0.02, 0.05, 0.02]

[[model.elements]]
name = "gear"
between = [2, 3]
stiffness = 3.0
type = "backlash"
b = 0.02

[[excitation.torques]]
inertia = 1
mean = 0.05
amplitudes = [0.1]

[analysis]
omega = [1.315, 1.34]
harmonics = 32
regularisation = 0.01
method = "hb"
"""


def test_cli_frf_subharmonics_on_a_chain_writes_every_branch(tmp_path):
    config = write_config(tmp_path, CHAIN_TOML)
    result = invoke(["frf", str(config), "--subharmonics", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    table = read_csv(tmp_path / "out" / "frf.csv")
    branch, period = np.asarray(table["branch"]), np.asarray(table["period"])
    assert set(branch.tolist()) == {0, 1} and np.all(period[branch == 1] == 2) and np.all(period[branch == 0] == 1)
    meta = json.loads((tmp_path / "out" / "frf.json").read_text())
    (b,) = meta["branches"]
    assert (b["branch"], b["period"], b["followed"]) == (1, 2, "exact shooting")
    assert b["points"] == int(np.sum(branch == 1))
    assert "branch 1 (period 2, period doubling of the period-1 branch" in result.stdout


def test_friction_orbit_of_period_two_is_the_branchs_orbit(response):
    """``friction_orbit(..., period=2)`` at Ω = 1.375 (the period-1 orbit unstable by a multiplier
    beyond −1): the exact orbit is branch 1's (every element rms to 1e-8), over two forcing
    periods, and the HB of period 2 beside it (64 harmonics of Ω/2) within 1 %."""
    from rattle.analysis import friction_orbit

    (br,) = response.branches
    i = int(np.argmin(np.abs(br.omega - 1.375)))
    w = float(br.omega[i])
    res = friction_orbit(_chain().friction_system(), w, RegularisationOptions(harmonics=32, regularisation=0.001),
                         period=2, every=False)
    assert res.converged and res.periods == 2 and res.harmonics == 64
    np.testing.assert_allclose(res.rms, br.rms[i], rtol=1e-8)
    assert res.t[-1] == pytest.approx(2 * 2 * math.pi / w) and res.period == pytest.approx(2 * 2 * math.pi / w)
    assert np.all(np.abs(res.element_rms_error) < 0.01) and res.matched
    assert res.metadata()["periods"] == 2 and "2 forcing periods" in res.summary()


def test_friction_orbit_of_period_two_where_the_motion_has_period_one():
    """At Ω = 1.312 the period-1 orbit is stable (between the Neimark–Sacker point and the period
    doubling) and the motion settles on it: no orbit of period 2."""
    from rattle.analysis import friction_orbit
    from rattle.errors import ConvergenceError

    with pytest.raises(ConvergenceError, match="no periodic orbit of period 2 at `omega` = 1.312: .*repeats after one"):
        friction_orbit(_chain().friction_system(), 1.312, RegularisationOptions(harmonics=32, regularisation=0.001),
                       period=2, every=False)
    with pytest.raises(ValueError, match="`period` must be 1 or 2"):
        friction_orbit(_chain().friction_system(), 1.3, period=3, every=False)


def test_cli_orbit_period_two_on_a_chain(tmp_path):
    """``rattle orbit --period 2`` at Ω = 1.375: the exact period-2 orbit over two forcing periods
    (at the file's ε = 0.01 the HB of period 2 has none next to it, and the summary says so); at
    Ω = 1.312, where the motion has period 1, exit 1 and nothing written."""
    config = write_config(tmp_path, CHAIN_TOML)
    result = invoke(["orbit", str(config), "--omega", "1.375", "--period", "2", "--single", "-o", "out"], tmp_path)
    assert result.exit_code == 0, (result.stdout, result.stderr)
    meta = json.loads((tmp_path / "out" / "orbit.json").read_text())
    assert meta["orbit"]["periods"] == 2 and meta["settings"]["period"] == 2 and meta["orbit"]["converged"]
    table = read_csv(tmp_path / "out" / "orbit.csv")
    assert float(table["t"][-1]) == pytest.approx(2 * 2 * math.pi / 1.375)
    assert "2 forcing periods" in result.stdout and "only the exact orbit is given" in result.stdout
    result = invoke(["orbit", str(config), "--omega", "1.312", "--period", "2", "-o", "out2"], tmp_path)
    assert result.exit_code == 1 and "no periodic orbit of period 2" in result.stderr
    assert not (tmp_path / "out2").exists()
