"""Random cross-validation: every fold and period doubling of the period-1 branch, at default settings.

Issue 7, item 1: on random continuous piecewise-linear cases (backlash, clutch, asymmetric
multi-stage laws; clearances 0.05–1 rad; several harmonics with random phases) the special points
that ``rattle.frequency_response`` reports on branch 0 at its defaults (H = 32) are compared with
the exact reference of ``_exact_branch.py`` (pseudo-arclength continuation of the shooting
problem on the exact flow; see its docstring for why it can be trusted):

* every exact fold and period doubling is matched by an HB point of the same kind within
  1e-4 in Ω (the issue's bound);
* no HB special point lacks an exact counterpart within 1e-4 (none spurious).

Two fixed cases come first: the reference clutch (whose exact points are also checked against
their published values) and examples/gear_backlash.toml (period-doubling pair 0.64016/0.65668).
A failure prints the case, both lists and the HB continuation rows around every miss.

Then three backlash cases on which the continuation before issue 7 (fda89e3) stepped over a
period-doubling pair (screened from 80 gear-like cases), and the first ``N_RANDOM`` accepted
random cases of seed ``SEED`` — the stream of benchmarks/bench_bifurcations.py, whose figure covers
40 cases — with a step budget per reference (rejections are printed with their reason). A
reference costs ~5–15 s of CPU (steps ≤ 2e-3 in scaled arclength), HB ~1–3 s: the file takes
~2 min.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rattle
from _exact_branch import (
    ExactBranch,
    RandomCase,
    accepted_cases,
    branch_points_at,
    check_g_omega,
    diagnose,
    exact_special_points,
    guard_and_locate,
    hb_special_points,
    match,
)

TOL = 1e-4  # the bound on the located Ω
SEED = 2026
N_RANDOM = 4
#: Step budget of a random case's reference (~10 s): a longer branch (light damping, large
#: resonance amplitudes) rejects the case here; the benchmark has no such budget.
MAX_STEPS = 12_000
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

#: H-independent exact special points of the reference clutch over Ω 0.1…3.0.
REFERENCE_EXACT = [
    ("fold", 0.18618), ("fold", 0.18772), ("fold", 0.23784), ("fold", 0.24237), ("fold", 0.75385),
    ("fold", 0.87437), ("period_doubling", 0.40823), ("period_doubling", 0.46323),
    ("period_doubling", 1.24258), ("period_doubling", 1.95908),
]


#: Backlash cases (K = I = 1, one harmonic, Ω 0.2…2.5) on which the continuation before issue 7
#: (fda89e3) stepped over a period-doubling pair (ψ_pd > 0 at both ends of one step) — cases 13,
#: 26 and 54 of ``gear_like_case`` with seed 7 (``bench_bifurcations.py --family gear --seed 7``),
#: found by screening 80 of them, old against new continuation — with the pair's exact Ω:
#: (b, c, F_m, F_p1, (Ω_pd1, Ω_pd2)).
HARD_CASES = {
    "hard-13": (0.443334661767277, 0.05648858953353816, 0.18232961690673818, 0.10717270785305268,
                (0.650354416927, 0.656142109891)),
    "hard-26": (0.4451845367382262, 0.04646584599627554, 0.13689389578873534, 0.07921044833621778,
                (0.655027173479, 0.658671870484)),
    "hard-54": (0.42936128007871377, 0.061084632362127286, 0.10567071030219373, 0.09185075538172113,
                (0.384150539213, 0.390279216368)),
}


@pytest.fixture(scope="module")
def random_cases():
    cases, rejected = accepted_cases(SEED, N_RANDOM, max_steps=MAX_STEPS)
    print(f"\n{len(cases)} random cases accepted, {len(rejected)} rejected:")
    for i, label, why in rejected:
        print(f"  #{i}: {why} [{label}]")
    return cases


def _report(label: str, exact, states, hb, m, frf) -> str:
    lines = [f"case: {label}", "exact (kind, Ω):"]
    lines += [f"  {k:<16} {w:.8f}" for k, w in sorted(exact, key=lambda p: p[1])]
    lines.append("HB branch 0 (kind, Ω):")
    lines += [f"  {k:<16} {w:.8f}" for k, w in sorted(hb, key=lambda p: p[1])]
    lines.append(f"matched {len(m.pairs)}/{len(exact)}, worst |ΔΩ| = {max(m.errors, default=0.0):.2e}")
    lines.append("missed: " + ", ".join(f"{k} {w:.6f}" for k, w in m.missed))
    lines.append("spurious: " + ", ".join(f"{k} {w:.6f}" for k, w in m.spurious))
    for p in m.missed + m.spurious:
        lines.append(diagnose(frf, p, exact, states))
    return "\n".join(lines)


def _check(case: RandomCase, ref: ExactBranch) -> None:
    frf = rattle.frequency_response(case.model, omega=case.omega)
    hb = hb_special_points(frf)
    m = match(ref.special, hb, TOL)
    assert not m.missed and not m.spurious, _report(case.label, ref.special, ref.states, hb, m, frf)


def test_g_omega_finite_difference_step():
    # The central-difference ∂G/∂Ω of the reference (Jacobian column only) is in its O(h²) range.
    assert check_g_omega(rattle.reference_case(), 0.5) < 1e-6


def test_guard_recovers_hidden_pair():
    # The reference's hidden-pair guard on its own, on a hand-made coarse branch of the gear
    # example: Ω = 0.62, 0.635, 0.665, 0.68. The step 0.635 -> 0.665 holds the period-doubling pair
    # (ψ_pd > 0 at both ends, the situation of the HB step that missed it); without the guard no
    # point is found, with it both, at the Ω of the fine continuation.
    model = rattle.Model.from_toml(EXAMPLES / "gear_backlash.toml")
    corr, pts = branch_points_at(model, [0.62, 0.635, 0.665, 0.68])
    assert pts[1].psi[1] > 0.0 and pts[2].psi[1] > 0.0
    assert guard_and_locate(corr, pts, (0.62, 0.68), min_split=1.0)[0] == []  # guard off
    special, _, _, splits, failures = guard_and_locate(corr, pts, (0.62, 0.68))
    pds = sorted(w for k, w in special if k == "period_doubling")
    assert len(pds) == 2 and splits > 0 and not failures, special
    assert abs(pds[0] - 0.6401643474) < 1e-8 and abs(pds[1] - 0.6566801262) < 1e-8, pds


@pytest.mark.slow
def test_reference_clutch():
    model = rattle.reference_case()
    ref = exact_special_points(model, (0.1, 3.0))
    assert not ref.stats["guard_failures"], ref.stats
    got = sorted(ref.special, key=lambda p: (p[0], p[1]))
    want = sorted(REFERENCE_EXACT)
    assert [k for k, _ in got] == [k for k, _ in want], got
    assert np.allclose([w for _, w in got], [w for _, w in want], atol=1e-5), got
    _check(RandomCase(model, (0.1, 3.0), "reference clutch (rattle.reference_case())"), ref)


@pytest.mark.slow
def test_gear_example():
    model = rattle.Model.from_toml(EXAMPLES / "gear_backlash.toml")
    ref = exact_special_points(model, (0.1, 3.0))
    assert not ref.stats["guard_failures"], ref.stats
    pds = sorted(w for k, w in ref.special if k == "period_doubling")
    assert any(abs(w - 0.64016) < 1e-5 for w in pds) and any(abs(w - 0.65668) < 1e-5 for w in pds), ref.special
    _check(RandomCase(model, (0.1, 3.0), "examples/gear_backlash.toml"), ref)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(HARD_CASES))
def test_hard_case(name):
    b, c, mean, amp, pair = HARD_CASES[name]
    model = rattle.Model(inertia=1.0, damping=c, stiffness=1.0, elastic=rattle.Backlash(b=b),
                         excitation=rattle.Excitation(mean=mean, amplitudes=(amp,)))
    ref = exact_special_points(model, (0.2, 2.5))
    assert not ref.stats["guard_failures"], ref.stats
    pds = [w for k, w in ref.special if k == "period_doubling"]
    assert all(min(abs(w - x) for x in pds) < 1e-9 for w in pair), (pair, ref.special)
    label = f"{name}: backlash b={b} c={c} Fm={mean} Fp=({amp},) omega=(0.2, 2.5)"
    _check(RandomCase(model, (0.2, 2.5), label), ref)


@pytest.mark.slow
@pytest.mark.parametrize("i", range(N_RANDOM))
def test_random_case(random_cases, i):
    acc = random_cases[i]
    _check(acc.case, acc.reference)
