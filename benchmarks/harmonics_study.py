"""How many harmonics each feature of the reference case needs to reach 0.1 % in rms.

Run:  python benchmarks/harmonics_study.py

For each feature — the primary resonance (upper branch near the upper fold, Ω = 0.87, and the
lower branch at 0.80), the 1/2, 1/3 and 1/4 super-harmonic resonances and the period-2
sub-harmonic at Ω = 1.41 (the paper's point "B") — the harmonic-balance solution at that Ω is
computed with H = 1 … 64 harmonics (Newton from the converged H = 64 orbit truncated to H) and its
rms compared with the exact periodic orbit (shooting on the exact piecewise-linear flow). The
smallest H whose error stays below 0.1 % for it and every larger H is reported.
"""

from __future__ import annotations

import numpy as np

import rattle
from rattle.hb import HarmonicBalance, HBOptions, NewtonOptions, solve_harmonic_balance
from rattle.timeint import ExactIntegrator, shoot_periodic_orbit

HS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64)


def truncate(q: np.ndarray, H: int, H_new: int) -> np.ndarray:
    out = np.zeros(2 * H_new + 1)
    m = min(H, H_new)
    out[: m + 1] = q[: m + 1]
    out[H_new + 1 : H_new + 1 + m] = q[H + 1 : H + 1 + m]
    return out


def state0(q: np.ndarray, H: int, w: float) -> np.ndarray:
    k = np.arange(1, H + 1)
    return np.array([q[0] + q[1 : H + 1].sum(), np.sum(k * w * q[H + 1 :])])


def main() -> int:
    model = rattle.reference_case()
    frf = rattle.frequency_response(model, harmonics=64, subharmonics=True)
    sup = {g.detail["order"]: g.omega_min for g in frf.regions if g.kind == "superharmonic"}
    features = [
        ("primary, upper branch", 0.87, 1, "max"),
        ("primary, lower branch", 0.80, 1, "min"),
        *[(f"1/{k} super-harmonic", w, 1, "any") for k, w in sorted(sup.items())],
        ("1/2 sub-harmonic (B)", 1.41, 2, "stable"),
    ]
    integ = ExactIntegrator(model)
    print(f"{'feature':24s} {'Ω':>7s} " + " ".join(f"{h:>8d}" for h in HS) + "   H for 0.1 %")
    for name, w, period, pick in features:
        rows = np.nonzero(frf.period == period)[0]
        near = rows[np.argsort(np.abs(frf.omega[rows] - w))[:12]]
        if pick == "max":
            i = near[np.argmax(frf.rms[near])]
        elif pick == "min":
            i = near[np.argmin(frf.rms[near])]
        elif pick == "stable":
            i = next((j for j in near if frf.stable[j]), near[0])
        else:
            i = near[0]
        w = float(frf.omega[i])
        H64 = frf.harmonics
        q64 = frf.coefficients[i]
        exact = shoot_periodic_orbit(model, w, state0(q64, H64, w / period), period=period, integrator=integ)
        errs = []
        for H in HS:
            if H < period:
                errs.append(np.nan)
                continue
            hb = HarmonicBalance(model, HBOptions(harmonics=H), period=period)
            r = solve_harmonic_balance(hb, truncate(q64, H64, H), w, NewtonOptions(max_iterations=60))
            if not r.converged:
                errs.append(np.nan)
                continue
            rms = np.sqrt(r.q[0] ** 2 + 0.5 * np.sum(r.q[1:] ** 2))
            errs.append(abs(rms / exact.rms - 1))
        errs = np.array(errs)
        ok = [H for j, H in enumerate(HS) if np.all(np.nan_to_num(errs[j:], nan=1.0) < 1e-3)]
        print(f"{name:24s} {w:7.4f} " + " ".join(f"{e:8.1e}" if np.isfinite(e) else f"{'—':>8s}" for e in errs)
              + f"   {ok[0] if ok else '> 64'}")
    print("(relative rms error against the exact orbit; — : Newton did not converge from the truncated orbit)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
