"""One orbit of a preload / friction law: the exact orbit started from the regularised HB, its stick
and lock phases, its table and its plot (issue 11: "the plots show stick phases")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rattle.analysis import RegularisationOptions, nonsmooth_orbit
from rattle.errors import Status
from rattle.files import read_csv
from rattle.model import Excitation, Friction, NonsmoothLaw, Preload, System
from rattle.results import (
    NONSMOOTH_ORBIT_COLUMNS,
    NonsmoothOrbitResult,
    NonsmoothCheck,
)
from rattle.timeint import ExactIntegrator, shoot_nonsmooth_orbit

OPTS = RegularisationOptions(harmonics=64, regularisation=0.01)


def _system(tp: float, r: float, fp: float = 0.3) -> System:
    law = NonsmoothLaw(elastic=Preload(preload=tp), friction=Friction(levels=r) if r else None)
    return System.single(damping=0.05, stiffness=1.0, law=law,
                           excitation=Excitation(mean=0.01, amplitudes=(fp,), phases=(0.3,)))


def _span(patch) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """The t- (or Ω-) range of an ``axvspan``: a Rectangle (matplotlib ≥ 3.9) or a Polygon."""
    if hasattr(patch, "get_width"):
        return patch.get_x(), patch.get_x() + patch.get_width()
    xy = np.asarray(patch.get_xy())
    return float(xy[:, 0].min()), float(xy[:, 0].max())


@pytest.fixture(scope="module")
def sticking() -> NonsmoothOrbitResult:
    """T_p = 0.2, r = 0.05, Ω = 0.6: three stick phases, 1.97 s of the 10.5 s period."""
    return nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)


@pytest.fixture(scope="module")
def locking() -> NonsmoothOrbitResult:
    """T_p = 0.25, r = 0.02, Ω = 0.3: two stick phases and a lock at the jump δ = 0."""
    return nonsmooth_orbit(_system(0.25, 0.02), 0.3, OPTS, every=False)


def test_the_stick_phases_are_the_trajectory_s(sticking: NonsmoothOrbitResult) -> None:
    res = sticking
    assert res.converged and res.start == "hb" and res.hb_start == "rest" and res.message == ""
    tr = res.orbit.trajectory
    spans = res.stick_intervals
    assert len(spans) == 3 and {k for *_, k in spans} == {"stick"}
    assert sum(b - a for a, b, _ in spans) == pytest.approx(tr.stick_time, rel=1e-13, abs=0)
    assert tr.stick_time == pytest.approx(1.97, abs=0.01)
    # every span runs from a "stick" event to an "unstick" event (merged, maximal)
    events = dict(zip(tr.event_time.tolist(), tr.event_kind))
    for a, b, _ in spans:
        assert events[a] == "stick" and events[b] == "unstick"
        t = np.linspace(a, b, 41)
        d, v, acc = res.sample(t)  # at t = b the slip that starts there: δ' = 0 to round-off
        assert np.max(np.abs(v)) <= 1e-12 and np.all(v[:-1] == 0.0) and np.all(acc[:-1] == 0.0)
        assert np.ptp(d[:-1]) == 0.0 and abs(d[-1] - d[0]) <= 1e-15
        # the friction holds: |F(t) − k f(δ_s)| ≤ k r over the span
        F = 0.01 + 0.3 * np.cos(0.6 * t + 0.3)
        assert np.max(np.abs(F - (d + 0.2 * np.sign(d)))) <= 0.05 * (1 + 1e-9)
    # outside the spans it slips: δ' vanishes only at isolated points
    t = np.linspace(0.0, res.period, 2001)
    held = np.zeros(t.size, dtype=bool)
    for a, b, _ in spans:
        held |= (t >= a) & (t <= b)
    assert np.count_nonzero(np.abs(res.sample(t)[1][~held]) <= 1e-12) <= 2
    # a stick phase forgets the velocity: one exact zero multiplier
    assert abs(res.multipliers[1]) < 1e-12 and res.stable and res.regime == "single_sided"


def test_rms_is_an_independent_shooting_s_and_the_hb_is_kept(sticking: NonsmoothOrbitResult) -> None:
    res = sticking
    exact = shoot_nonsmooth_orbit(_system(0.2, 0.05), 0.6, (0.05, 0.0))  # from elsewhere
    assert exact.converged
    assert res.rms == pytest.approx(exact.rms, rel=1e-9)
    assert res.mean == pytest.approx(exact.mean, rel=1e-9)
    np.testing.assert_allclose(np.abs(res.multipliers), np.abs(exact.multipliers), atol=1e-9)
    # δ_HB: the series itself (rms by the sampled mean square, exact for N > 2H), its state at t = 0
    t = np.arange(1024) * res.period / 1024
    assert res.rms_hb == pytest.approx(math.sqrt(np.mean(res.sample_hb(t) ** 2)), rel=1e-12)
    assert res.sample_hb(0.0) == pytest.approx(res.hb_state[0], rel=1e-12)
    assert res.sample_hb(0.0, derivative=1) == pytest.approx(res.hb_state[1], rel=1e-9)
    assert res.rms_error == pytest.approx(res.rms_hb / res.rms - 1.0, rel=1e-15)
    # the stick creeps under regularisation: ε = 0.01 is off by about 10 % (docs/nonsmooth.md: 9.3e-2)
    assert 0.03 < abs(res.rms_error) < 0.2 and res.matched and res.hb_distance < 0.1
    assert res.regularisation == 0.01 and res.harmonics == 64 and res.coefficients.size == 129
    # started from the orbit's own state, the shooting stays there
    summary = res.summary()
    assert summary["rms"] == res.rms and summary["mu2_abs"] < 1e-12 and summary["stable"] is True
    assert summary["phases"] == [[a, b, k] for a, b, k in res.stick_intervals] and summary["start"] == "hb"
    import json

    assert json.loads(json.dumps(summary))["regime"] == "single_sided"
    again = nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, x0=res.orbit.state0, every=False)
    assert again.start == "x0" and again.rms == pytest.approx(res.rms, rel=1e-12)


def test_csv_holds_one_period_with_every_event_and_the_modes(sticking: NonsmoothOrbitResult, tmp_path) -> None:
    res = sticking
    path = res.to_csv(tmp_path / "orbit.csv")
    cols = read_csv(path)
    assert list(cols) == list(NONSMOOTH_ORBIT_COLUMNS) == ["t", "delta", "velocity", "acceleration", "mode", "delta_hb"]
    t = cols["t"]
    tr = res.orbit.trajectory
    assert t[0] == 0.0 and t[-1] == pytest.approx(res.period, rel=1e-15) and np.all(np.diff(t) > 0)
    assert t.size >= 513 + tr.event_time.size - 1
    assert set(tr.event_time.tolist()) <= set(t.tolist())
    d, v, a = tr.sample(t)
    np.testing.assert_array_equal(cols["delta"], d)
    np.testing.assert_array_equal(cols["velocity"], v)
    np.testing.assert_array_equal(cols["acceleration"], a)
    np.testing.assert_array_equal(cols["delta_hb"], res.sample_hb(t))
    # the mode of each row from the merged spans (a span owns its start, not its end)
    expect = np.full(t.size, "slip", dtype=object)
    for lo, hi, kind in res.stick_intervals:
        expect[(t >= lo) & (t < hi)] = kind
    assert list(cols["mode"]) == list(expect)
    assert set(cols["mode"]) == {"slip", "stick"}
    assert np.all(cols["velocity"][cols["mode"] == "stick"] == 0.0)
    assert (tmp_path / "orbit.csv").read_text().startswith("t,delta,velocity,acceleration,mode,delta_hb\n")


def test_plot_shades_every_stick_phase_and_saves(sticking: NonsmoothOrbitResult, tmp_path) -> None:
    fig, ax = sticking.plot()
    assert list(ax) == ["delta", "velocity", "phase"]
    n = len(sticking.stick_intervals)
    assert len(ax["delta"].patches) == n == len(ax["velocity"].patches) == 3
    spans = sorted(_span(p) for p in ax["delta"].patches)
    np.testing.assert_allclose(spans, [(a, b) for a, b, _ in sticking.stick_intervals], rtol=1e-14)
    labels = [ln.get_label() for ln in ax["delta"].get_lines()]
    assert labels[:2] == ["exact orbit", "regularised HB (ε = 0.01, H = 64)"] and "jump at δ = 0" in labels
    hb = ax["delta"].get_lines()[1]
    assert hb.get_linestyle() == "--"
    assert ax["delta"].get_legend() is None  # one legend, below the panels (over no data)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "stick (friction holds)" in legend
    fig.savefig(tmp_path / "orbit.png")
    assert (tmp_path / "orbit.png").read_bytes()[:4] == b"\x89PNG"


def test_a_lock_at_the_jump_is_shaded_in_its_own_colour(locking: NonsmoothOrbitResult) -> None:
    from matplotlib.colors import to_rgb

    from rattle.plotting._nonsmooth import LOCK_COLOUR, STICK_COLOUR

    res = locking
    kinds = [k for *_, k in res.stick_intervals]
    assert kinds.count("lock") == 1 and kinds.count("stick") == 2
    assert sum(b - a for a, b, _ in res.stick_intervals) == pytest.approx(res.stick_time, rel=1e-13)
    (a, b, _), = [s for s in res.stick_intervals if s[2] == "lock"]
    d, v, _ = res.sample(np.linspace(a, b, 21)[:-1])  # [a, b): at b the slip starts
    assert np.all(d == 0.0) and np.all(v == 0.0)  # held at the jump δ = 0
    # in the lock band: |F| ≤ k (T_p + r)
    F = 0.01 + 0.3 * np.cos(0.3 * np.linspace(a, b, 21) + 0.3)
    assert np.max(np.abs(F)) <= 0.27 * (1 + 1e-12)
    assert np.max(np.abs(res.multipliers)) < 1e-12  # a lock forgets everything: super-stable
    fig, ax = res.plot()
    colours = [to_rgb(p.get_facecolor()[:3]) for p in ax["delta"].patches]
    assert len(colours) == 3
    assert colours.count(to_rgb(LOCK_COLOUR)) == 1 and colours.count(to_rgb(STICK_COLOUR)) == 2
    legend = [t.get_text() for t in fig.legends[0].get_texts()]  # the one legend, below the panels
    assert "lock (held at a jump)" in legend and "stick (friction holds)" in legend


def test_a_failed_shooting_is_retried_after_settling(sticking: NonsmoothOrbitResult, monkeypatch) -> None:
    """The first shooting (from the HB state) is made to fail: the flow settles for 100 periods
    and the shooting from there finds the same stable orbit."""
    import rattle.analysis._nonsmooth_orbit as mod

    calls: list[np.ndarray] = []
    real = mod.shoot_nonsmooth_orbit

    def flaky(system, omega, x0, **kw):  # type: ignore[no-untyped-def]
        calls.append(np.asarray(x0, dtype=float))
        if len(calls) == 1:
            raise mod.ConvergenceError("made to fail")
        return real(system, omega, x0, **kw)

    monkeypatch.setattr(mod, "shoot_nonsmooth_orbit", flaky)
    res = nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)
    assert len(calls) == 2 and np.array_equal(calls[0], res.hb_state)
    x100 = ExactIntegrator(_system(0.2, 0.05)).propagate(res.hb_state, 0.0, 100 * res.period, 0.6).state1
    np.testing.assert_array_equal(calls[1], x100)
    assert res.start == "settled" and "made to fail" in res.message and "settled for 100 periods" in res.message
    assert res.rms == pytest.approx(sticking.rms, rel=1e-9) and res.hb_start == "rest"


def test_a_failed_hb_ladder_is_replaced_by_settling_and_the_exact_spectrum(sticking: NonsmoothOrbitResult,
                                                                          monkeypatch) -> None:
    """The ladder from rest is made to fail: the exact orbit comes from rest by settling, and the
    HB is solved at ε from its spectrum — the same HB orbit as the ladder's."""
    import rattle.analysis._nonsmooth_orbit as mod

    real = mod.regularisation_limit
    starts: list[float] = []

    def flaky(make, omega, q0, **kw):  # type: ignore[no-untyped-def]
        starts.append(kw["eps_start"])
        if len(starts) == 1:
            raise mod.ConvergenceError("ladder made to fail")
        return real(make, omega, q0, **kw)

    monkeypatch.setattr(mod, "regularisation_limit", flaky)
    res = nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)
    assert starts == [0.1, 0.01]
    assert res.start == "settled" and res.hb_start == "exact" and "ladder made to fail" in res.message
    assert res.rms == pytest.approx(sticking.rms, rel=1e-9)
    assert res.rms_hb == pytest.approx(sticking.rms_hb, rel=1e-6) and res.matched

    def fails(make, omega, q0, **kw):  # type: ignore[no-untyped-def]
        raise mod.ConvergenceError("no HB")

    monkeypatch.setattr(mod, "regularisation_limit", fails)
    res = nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)  # the exact orbit alone: HB columns nan
    assert res.converged and res.hb_start == "" and np.all(np.isnan(res.coefficients))
    assert math.isnan(res.rms_hb) and math.isnan(res.hb_distance) and not res.matched
    cols = res.columns(64)
    assert np.all(np.isnan(cols["delta_hb"])) and np.all(np.isfinite(cols["delta"]))
    monkeypatch.setattr(mod, "shoot_nonsmooth_orbit", lambda *a, **k: (_ for _ in ()).throw(mod.ConvergenceError("x")))
    with pytest.raises(mod.ConvergenceError, match="`omega`"):
        nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)


def test_without_an_exact_orbit_the_hb_stands_alone(monkeypatch, tmp_path) -> None:
    import rattle.analysis._nonsmooth_orbit as mod

    monkeypatch.setattr(mod, "shoot_nonsmooth_orbit", lambda *a, **k: (_ for _ in ()).throw(mod.ConvergenceError("x")))
    res = nonsmooth_orbit(_system(0.2, 0.05), 0.6, OPTS, every=False)
    assert not res.converged and res.orbit is None and res.start == "" and "no exact orbit" in res.message
    assert math.isnan(res.rms) and math.isnan(res.stick_time) and res.stable is None and res.regime == ""
    assert res.stick_intervals == [] and np.all(np.isnan(res.multipliers)) and res.rms_hb > 0
    cols = read_csv(res.to_csv(tmp_path / "orbit.csv"))
    assert np.all(np.isnan(cols["delta"])) and set(cols["mode"]) == {""} and np.all(np.isfinite(cols["delta_hb"]))
    _fig, ax = res.plot()
    assert len(ax["delta"].patches) == 0
    assert ax["delta"].get_lines()[0].get_label().startswith("regularised HB")


def test_the_branch_plot_shades_where_the_exact_orbit_sticks() -> None:
    """A hand-made response: rows 1–2 and 4 stick (two runs), row 3 slips, row 5 is not matched."""
    w = np.array([0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
    nan = np.full(6, np.nan)
    stick = np.array([0.0, 1.0, 2.0, 0.0, 0.5, np.nan])
    matched = np.array([True, True, True, True, True, False])
    mu = np.tile([0.5 + 0j, 0.0 + 0j], (6, 1))
    res = NonsmoothCheck(
        omega=w, rms_hb=np.linspace(0.1, 0.2, 6), mean=np.zeros(6), rms=np.linspace(0.1, 0.2, 6), rms_ac=nan,
        p2p=nan, acc_p2p=nan, regime=np.full(6, "single_sided", dtype=object), stable=np.ones(6, dtype=bool),
        multipliers=mu, multipliers_hb=mu, stick_time=stick, matched=matched, status=Status.SUCCESS, message="",
        regularisation=0.01, harmonics=64, limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0),
        limit_rms=np.zeros(0), limit_richardson=np.zeros(0), limit_linear=np.zeros(0, dtype=bool))
    from rattle.plotting import nonsmooth_response_plot

    _fig, ax = nonsmooth_response_plot(res)
    spans = sorted(_span(p) for p in ax["rms"].patches)
    np.testing.assert_allclose(spans, [(0.6, 0.7), (0.9, 0.9)])
    np.testing.assert_allclose(ax["stick"].get_lines()[0].get_ydata(), np.where(matched, stick / (2 * np.pi / w), np.nan))
    assert len(ax["stick"].collections) == 1  # the stick fraction filled


@pytest.mark.parametrize("args, kwargs, error, message", [
    ((0.0,), {}, ValueError, "`omega`"), ((-0.6,), {}, ValueError, "`omega`"), ((math.nan,), {}, ValueError, "`omega`"),
    (("0.6",), {}, TypeError, "`omega`"), ((0.6, {"harmonics": 8}), {}, TypeError, "`options`"),
    ((0.6,), {"x0": (0.0,)}, ValueError, "`x0`"),
])
def test_bad_arguments_are_refused_by_name(args: tuple, kwargs: dict, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        nonsmooth_orbit(_system(0.2, 0.05), *args, **kwargs, every=False)


def test_a_system_that_is_not_nonsmooth_is_refused() -> None:
    with pytest.raises(TypeError, match="`system`"):
        nonsmooth_orbit("clutch", 0.6, every=False)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="`system`"):
        nonsmooth_orbit(_system(0.2, 0.05).law, 0.6, every=False)  # type: ignore[arg-type]


@pytest.fixture(autouse=True)
def _close_figures():  # type: ignore[no-untyped-def]
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def test_every_orbit_at_the_speed_is_listed_beside_the_one_asked_for():
    """The torque converter (examples/torque_converter_preload.toml) at Ω = 0.9: the orbit door
    used to give the period-1 orbit alone, while a stable period-3 orbit coexists there (the map's
    search finds it; an exact simulation from next to it stays on it). ``every`` (the default)
    lists both, and the unstable period-3 orbit between their basins; each listed orbit is exact:
    the period-1 one is the orbit asked for (rms to 1e-9), and the stable period-3 one is a fixed
    point of the exact period map over three forcing periods (shooting from its own state
    converges in at most one step to the same rms) that does not repeat after one period."""
    from pathlib import Path

    from rattle.io import load_config

    system = load_config(Path(__file__).resolve().parents[2] / "examples" / "torque_converter_preload.toml").model
    res = nonsmooth_orbit(system, 0.9)
    periods = sorted((o.period, o.stable) for o in res.solutions)
    assert (1, True) in periods and (3, True) in periods and (3, False) in periods
    one = next(o for o in res.solutions if o.period == 1)
    assert abs(one.rms - res.rms) <= 1e-9 and one.source == "continuation"
    three = next(o for o in res.solutions if o.period == 3 and o.stable)
    assert np.max(np.abs(three.multipliers)) < 1.0 and abs(three.rms - one.rms) > 1e-3
    # the series of the exact period-3 orbit: its state at t = 0 shot again over three periods
    H = three.harmonics
    q = three.coefficients
    k = np.arange(1, H + 1)
    x0 = np.array([q[0] + q[1:H + 1].sum(), np.sum(k * (0.9 / 3) * q[H + 1:])])
    again = shoot_nonsmooth_orbit(system, 0.9, x0, period=3)
    assert again.converged and again.rms == pytest.approx(three.rms, rel=1e-6)
    summary = res.summary()
    assert len(summary["orbits"]) == len(res.solutions)
    # every=False: the one orbit (what the map and the tests of a single orbit ask for)
    assert nonsmooth_orbit(system, 0.9, every=False).solutions == ()


def test_a_simulated_periodic_attractor_no_branch_accounts_for_is_listed(monkeypatch):
    """A periodic attractor the census saw only by simulation (its branch not continued: the
    search's budget spent, or the continuation failed) is an orbit at the speed too: the orbit
    door solves it exactly from the settled state (Newton on the period map) and lists it with
    ``source`` "simulation"; a settled state that Newton cannot bring to an exact orbit stays in
    ``nonperiodic`` with its period. Shown on the torque converter at Ω = 0.9 with the census
    replaced by one that holds the stable period-3 orbit as such an attractor (the state where an
    exact simulation settles), the period-1 orbit seen as a period-2 motion (counted once, as the
    period-1 orbit) and no branch solution."""
    from pathlib import Path

    import rattle.analysis._census as census_module
    from rattle.analysis import steady_state
    from rattle.analysis._attractors import Census, SimulatedAttractor
    from rattle.io import load_config

    system = load_config(Path(__file__).resolve().parents[2] / "examples" / "torque_converter_preload.toml").model
    reference = nonsmooth_orbit(system, 0.9)
    three = next(o for o in reference.solutions if o.period == 3 and o.stable)
    H = three.harmonics
    q, k = three.coefficients, np.arange(1, H + 1)
    x0 = np.array([q[0] + q[1:H + 1].sum(), np.sum(k * (0.9 / 3) * q[H + 1:])])
    settled = steady_state(system, 0.9, x0=x0 + 1e-4 * np.array([1.0, -1.0]))
    assert settled.period == 3
    one_state = steady_state(system, 0.9).state0  # from rest: the period-1 orbit

    real = census_module.attractor_census

    def census_without_branches(model, grid, run, search=None, **kw):  # type: ignore[no-untyped-def]
        cell = real(model, grid, run, search, **kw)
        j = len(grid) // 2
        seen = [SimulatedAttractor(j, float(grid[j]), 3, settled.rms, settled.rms_ac, "impact", True, "test",
                                   np.asarray(settled.state0, dtype=float)),
                # Newton on the two-period map from the period-1 orbit's state: that orbit, once
                SimulatedAttractor(j, float(grid[j]), 2, reference.rms, reference.rms, "impact", True, "test",
                                   np.asarray(one_state, dtype=float)),
                SimulatedAttractor(j, float(grid[j]), 2, 0.5, 0.5, "impact", True, "test",
                                   np.array([np.nan, 0.0]))]  # no state to start from: Newton fails
        cell.census = Census(solutions=[], simulated=seen)
        return cell

    monkeypatch.setattr(census_module, "attractor_census", census_without_branches)
    found = census_module.exact_orbits_at(system, 0.9)
    assert [(o.period, o.stable, o.source) for o in found.solutions] == [(3, True, "simulation"),
                                                                           (1, True, "simulation")]
    assert found.solutions[0].rms == pytest.approx(three.rms, rel=1e-9)
    assert found.solutions[1].rms == pytest.approx(reference.rms, rel=1e-9)  # counted once, as period 1
    assert [(a.period, a.rms) for a in found.nonperiodic] == [(2, 0.5)]


def test_periodic_orbit_is_the_door_for_every_law(monkeypatch) -> None:
    """``rattle.periodic_orbit`` answers a law with jumps or friction as ``frequency_response``
    does (before: TypeError "`model` must be a rattle Model or Chain"): the exact orbits of
    ``nonsmooth_orbit`` with its options, x0 and period; a chain with friction on its
    ``friction_system()``; the harmonic-balance arguments refused by name; ``options`` refused for
    a continuous law."""
    import rattle
    from rattle.analysis import _nonsmooth_orbit

    calls = []
    monkeypatch.setattr(_nonsmooth_orbit, "nonsmooth_orbit",
                        lambda system, omega, options=None, **kw: calls.append((system, omega, options, kw)) or "exact")
    system = _system(0.2, 0.05)
    assert rattle.periodic_orbit(system, 0.6, options=OPTS, x0=(0.1, 0.0), period=2) == "exact"
    assert calls[-1] == (system, 0.6, OPTS, {"x0": (0.1, 0.0), "period": 2})
    chain = rattle.Chain.from_toml(Path(__file__).resolve().parents[2] / "examples" / "chain_clutch_friction.toml")
    assert isinstance(chain, rattle.Chain) and chain.discontinuous
    assert rattle.periodic_orbit(chain, 0.9) == "exact"
    solved = calls[-1][0]
    assert isinstance(solved, System) and np.array_equal(solved.damping, chain.friction_system().damping)
    with pytest.raises(TypeError, match="`harmonics`, `stability` must be left at the default"):
        rattle.periodic_orbit(system, 0.6, harmonics=16, stability="hill")
    with pytest.raises(TypeError, match="leave `options` None"):
        rattle.periodic_orbit(rattle.reference_case(), 0.6, options=OPTS)
