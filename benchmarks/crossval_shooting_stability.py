"""Cross-validation: the stability of exact shooting branches (laws with jumps or friction) and the
location of their stability changes, against an independent integration (issue 25).

Run:  python benchmarks/crossval_shooting_stability.py  [--cases 6] [--seed 0] [--rows 6] [--delta 1e-4]

For random single-equation cases (a preload, with a clearance on odd cases, Coulomb friction per stage
on two of three, forcing with a second harmonic, Ω from a random Ω_0 in 0.3–1 to 2 Ω_0) and the two-element
friction chain of the tests, ``rattle.frequency_response`` at default settings (exact shooting
continuation) is checked against the independent reference of the tests (``tests/_filippov.py``:
scipy DOP853 at rtol 1e-12 with terminal events and the Filippov stick/slip/lock logic written out
again — not rattle's integrators — with steps of at most a thousandth of the period):

* **stability away from special points**: at ``--rows`` rows spread over each branch (farther than
  2e-3 in Ω from a labelled point and with no multiplier within 1e-3 of the unit circle), the
  monodromy matrix by central differences of the reference's period map (step 1e-7 of the length
  scale) — its multipliers, and the verdict stable / unstable, against the row's (exact monodromy
  with saltation matrices);
* **every located stability change**: on each side of a labelled point Ω* (fold, period doubling,
  Neimark–Sacker, grazing) along the branch, the orbit within δ of Ω* — the neighbouring row itself
  when it is that close, else the point of the segment towards it whose Ω is δ/2 from Ω*, solved on
  the reference (Newton on its period map, Jacobian by central differences, from the interpolated
  state) — has the reference's verdict; where rattle's stability changes at the point the two
  verdicts must differ (the change lies within δ of Ω*), where it does not ("no change": a grazing
  that keeps the stability) they must agree. A fold's two arms both lie on one side in Ω, a
  grazing's may be a hop apart: both are covered by taking the arms, not Ω* ± δ.

Prints a line per case and the totals; exits 1 when a verdict or a location disagrees.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from _cases import friction_chain, random_preload  # noqa: E402  (the tests' random cases)
from _filippov import chain_reference, single_reference  # noqa: E402  (the tests' independent reference)

import rattle  # noqa: E402
from rattle.model import System  # noqa: E402


def single_case(seed: int) -> tuple[System, tuple[float, float]]:
    """The tests' random preload (tests/_cases.py), its numbers from seed 1000 + ``seed``, Ω from Ω₀ in
    0.3–1 to 2 Ω₀."""
    return random_preload(seed, omega=(0.3, 1.0), span=2.0, offset=1000)


def chain_case():  # the friction chain of the exact-shooting tests (tests/_cases.py)
    return friction_chain(), (0.6, 0.72)


#: The reference's largest step, per forcing period: its events are sign changes between steps, so
#: a velocity that dips below zero and back within one step (next to a grazing of the stick
#: surface) would be missed — measured: with unbounded steps the reference missed such a dip 1e-4
#: in Ω before a grazing-sliding point (its period map 2.6e-4 L off rattle's orbit, a stable verdict
#: where the orbit is unstable with |μ| = 36); with T/1000 it agrees (periodic to 1e-11, |μ| 35.95).
STEPS_PER_PERIOD = 1000
#: ... and where that reference does not find a row periodic (its defect above 1e-8 of the scales:
#: a dip shorter than a thousandth of the period, next to a grazing), the row is integrated again
#: with steps of T/20000 (measured: a row 4e-6 in Ω from a grazing, |μ| 10.42, defect 2.2e-4 with
#: T/1000 and 2.9e-11 with T/50000, |μ| 10.422 as rattle's).
FINE_STEPS_PER_PERIOD = 20_000
#: The central differences' step, relative to the length (velocity) scale: short enough that the
#: perturbed orbits keep the event structure of a row 1e-6 from a grazing (measured: the last row of
#: a branch that ends at a grazing, |μ| 0.3085 and 1.4674 exactly, gave 0.6728 with steps 1e-6 and
#: 1e-5 and rattle's values from 1e-7 down), long enough for the reference's 1e-12 accuracy.
FD_STEP = 1e-7


class Reference:
    """The independent period map z(0) ↦ z(T) of a case, its Jacobian by central differences and
    Newton on it."""

    def __init__(self, system, period: int = 1) -> None:
        self.system, self.period = system, period
        self.chain = not system.is_single_equation
        self.L = float(system.length_scale())
        self.s = np.concatenate([np.full(self.dim // 2, self.L), np.full(self.dim // 2, self.L * self.frequency())])
        self.steps = STEPS_PER_PERIOD

    def resolve(self, z: np.ndarray, w: float) -> None:
        """Steps of T/1000, or T/20000 where the orbit z at w is not periodic with the former."""
        self.steps = STEPS_PER_PERIOD
        if np.max(np.abs((self.map(z, w) - z) / self.s)) > 1e-8:
            self.steps = FINE_STEPS_PER_PERIOD

    @property
    def dim(self) -> int:
        return 2 * self.system.n if self.chain else 2

    def frequency(self) -> float:
        return float(self.system.frequency_scale()) if self.chain else math.sqrt(self.system.k)

    def map(self, z: np.ndarray, w: float) -> np.ndarray:
        T = self.period * 2.0 * math.pi / w
        step = T / self.steps
        if self.chain:
            return np.asarray(chain_reference(self.system, np.asarray(z, float), T, w, max_step=step), dtype=float)
        return np.asarray(single_reference(self.system, tuple(np.asarray(z, float)), T, w, max_step=step)[0],
                          dtype=float)

    def settle(self, start: np.ndarray, w: float) -> np.ndarray | None:
        """The orbit at w by Newton from ``start`` with steps of T/1000, checked by one period with
        T/20000 steps (solved again with those, at most 4 Newton steps, where it is not periodic
        there); ``steps`` is left at what the orbit needs."""
        self.steps = STEPS_PER_PERIOD
        z = self.solve(start, w)
        self.steps = FINE_STEPS_PER_PERIOD
        if z is not None and np.max(np.abs((self.map(z, w) - z) / self.s)) <= 1e-8:
            self.steps = STEPS_PER_PERIOD
            return z
        return self.solve(start, w, iterations=4)

    def monodromy(self, z: np.ndarray, w: float) -> np.ndarray:
        M = np.empty((self.dim, self.dim))
        for j in range(self.dim):
            h = FD_STEP * self.s[j]
            e = np.zeros(self.dim)
            e[j] = h
            M[:, j] = (self.map(z + e, w) - self.map(z - e, w)) / (2.0 * h)
        return M

    def solve(self, z: np.ndarray, w: float, iterations: int = 8) -> np.ndarray | None:
        z = np.asarray(z, dtype=float).copy()
        for _ in range(iterations):
            r = self.map(z, w) - z
            if np.max(np.abs(r / self.s)) <= 1e-9:
                return z
            try:
                z = z - np.linalg.solve(self.monodromy(z, w) - np.eye(self.dim), r)
            except np.linalg.LinAlgError:
                return None
        return z if np.max(np.abs((self.map(z, w) - z) / self.s)) <= 1e-7 else None

    def verdict(self, z: np.ndarray, w: float) -> tuple[bool, float]:
        mu = np.linalg.eigvals(self.monodromy(z, w))
        return bool(np.max(np.abs(mu)) < 1.0), float(np.max(np.abs(mu)))


def check_case(name: str, system, omega: tuple[float, float], rows: int, delta: float) -> dict:
    t0 = time.process_time()
    frf = rattle.frequency_response(system, omega=omega)
    t_frf = time.process_time() - t0
    out = {"name": name, "rows": 0, "status": str(frf.status), "frf_cpu": t_frf, "verdicts": 0,
           "verdict_bad": [], "mu_err": 0.0, "mu_err_at": float("nan"), "points": 0, "located": 0, "no_change": 0,
           "point_bad": [], "unresolved": []}
    ref = Reference(system)
    for part in (frf.check, *frf.check.branches):  # every branch: from Ω_min, from Ω_max, seeded ones
        _check_part(part, ref, rows, delta, out)
    out["cpu"] = time.process_time() - t0
    return out


def _check_part(ch, ref: Reference, rows: int, delta: float, out: dict) -> None:
    out["rows"] += len(ch.omega)
    om = np.asarray(ch.omega, dtype=float)
    Z = np.asarray(ch.states, dtype=float)
    stable = np.asarray(ch.stable, dtype=bool)
    mu = np.asarray(ch.multipliers)
    labels = [str(x) for x in np.asarray(ch.labels, dtype=object)]
    special = [i for i, lab in enumerate(labels) if lab]
    # (1) verdicts away from the special points
    far = [i for i in range(len(om))
           if all(abs(om[i] - om[k]) > 2e-3 for k in special) and abs(np.max(np.abs(mu[i])) - 1.0) > 1e-3]
    for i in [far[k] for k in np.unique(np.linspace(0, len(far) - 1, rows).astype(int))] if far else []:
        ref.resolve(Z[i], om[i])
        M = ref.monodromy(Z[i], om[i])
        mref = np.sort_complex(np.linalg.eigvals(M))
        out["verdicts"] += 1
        err = float(np.max(np.abs(np.sort(np.abs(mref)) - np.sort(np.abs(mu[i])))))
        if err > out["mu_err"]:
            out["mu_err"], out["mu_err_at"] = err, float(om[i])
        if bool(np.max(np.abs(mref)) < 1.0) != bool(stable[i]):
            out["verdict_bad"].append((float(om[i]), float(np.max(np.abs(mref))), bool(stable[i])))
    # (2) every labelled point: the verdicts δ either side
    for i in special:
        if i == 0 or i == len(om) - 1:
            continue
        out["points"] += 1
        lab, w = labels[i], float(om[i])
        a, c = i - 1, i + 1

        def side(k: int) -> tuple[bool, float] | None:
            # the reference's verdict on the arm from row i to its neighbour k, within δ of Ω*: at
            # row k itself when it is that close, else at the point of the segment i → k whose Ω is
            # δ/2 from Ω* (Newton on the reference's period map from the interpolated state)
            if abs(om[k] - w) <= delta:  # a row: an orbit already, integrated finely if need be
                target = float(om[k])
                ref.resolve(Z[k], target)
                z = ref.solve(Z[k], target)
            else:
                f = 0.5 * delta / abs(om[k] - w)
                target = float(w + f * (om[k] - w))
                guess = (1.0 - f) * Z[i] + f * Z[k]
                z = ref.settle(guess, target)
                # Newton that went farther than the segment is long left the arm (onto a coexisting
                # orbit, next to a grazing where the branch hops between arms): not this arm's verdict
                if z is not None and np.max(np.abs((z - guess) / ref.s)) > np.max(np.abs((Z[k] - Z[i]) / ref.s)):
                    return "left the arm"
            return None if z is None else ref.verdict(z, target)

        va, vc = side(a), side(c)
        changes = bool(stable[a] != stable[c])
        if "left the arm" in (va, vc):
            out["unresolved"].append((lab, w))
            continue
        ok = va is not None and vc is not None and (va[0] != vc[0]) == changes
        if not changes:
            out["no_change"] += 1
        if ok:
            out["located"] += 1
        else:
            out["point_bad"].append((lab, w, va, vc, bool(stable[a]), bool(stable[c])))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=6, help="random single-equation cases (default 6)")
    ap.add_argument("--seed", type=int, default=0, help="first case's seed (default 0)")
    ap.add_argument("--rows", type=int, default=6, help="rows per case checked away from special points")
    ap.add_argument("--delta", type=float, default=1e-4, help="the location tolerance in Ω (default 1e-4)")
    ap.add_argument("--no-chain", action="store_true", help="skip the friction chain")
    args = ap.parse_args()
    from threadpoolctl import threadpool_limits

    cases = [(f"single {s}", *single_case(s)) for s in range(args.seed, args.seed + args.cases)]
    if not args.no_chain:
        cases.append(("friction chain", *chain_case()))
    bad = 0
    totals = {"verdicts": 0, "points": 0, "located": 0, "unresolved": 0}
    with threadpool_limits(1):
        for name, system, omega in cases:
            r = check_case(name, system, omega, args.rows, args.delta)
            for k in totals:
                totals[k] += len(r[k]) if isinstance(r[k], list) else r[k]
            bad += len(r["verdict_bad"]) + len(r["point_bad"])
            print(f"{name:15s} Ω {omega[0]:.4f}–{omega[1]:.4f}: {r['rows']} rows ({r['status']}, frf {r['frf_cpu']:.1f} s CPU); "
                  f"verdicts {r['verdicts'] - len(r['verdict_bad'])}/{r['verdicts']} (largest |μ| difference "
                  f"{r['mu_err']:.1e} at Ω {r['mu_err_at']:.6f}); labelled points located within {args.delta:g}: {r['located']}/{r['points']}"
                  f" ({r['no_change']} without a stability change, {len(r['unresolved'])} not resolved: the reference left the arm); "
                  f"{r['cpu']:.0f} s", flush=True)
            for item in r["verdict_bad"] + r["point_bad"]:
                print("    DISAGREES:", item, flush=True)
    print(f"total: verdicts {totals['verdicts']} checked, labelled points {totals['located']}/{totals['points']} "
          f"confirmed within {args.delta:g} in Ω ({totals['unresolved']} not resolved); {bad} disagreement(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
