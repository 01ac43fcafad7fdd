"""Benchmark: rattle beside NLvib (Krack & Gross's MATLAB/Octave harmonic balance + continuation) in one run.

Run:  python benchmarks/bench_nlvib.py  [--nlvib PATH] [--octave octave-cli] [--repeat 3] [--ds 0.01]
      python benchmarks/bench_nlvib.py  --profile      (where rattle's time goes, reference case H = 32)

Needs GNU Octave (``octave-cli`` on PATH or ``--octave``; ``apt-get install octave``) and an NLvib
checkout (``--nlvib PATH`` or the environment variable ``NLVIB_PATH``; ``git clone
https://github.com/maltekrack/NLvib``), used unmodified; without either the benchmark says how to
get them and exits 0 ("skipped"). Only the drivers in ``benchmarks/nlvib/`` (the clutch's residual
and the two continuation calls) are rattle's. Both sides run with OMP_NUM_THREADS=1.

**Case 1, the paper's reference clutch** (``examples/reference_clutch.toml``: I δ'' + C δ' + K f(δ)
= F_m + F_p cos Ωt, f the two-stage clutch law) over its Ω = 0.1 … 3.0, at H = 20 and H = 32, both
sides with N = 1024 AFT samples per period (rattle's default for these H; NLvib's unilateral example
uses 2^10 too):

* NLvib: ``solve_and_continue`` (its arc length, tangent predictor, step adaptation, Octave's
  ``fsolve``) on ``benchmarks/nlvib/clutch_residual.m`` — an AFT residual written like NLvib's
  ``HB_residual_Duffing.m`` with the analytical Jacobian its ``HB_residual.m`` provides; started
  from the linear solution at Ω = 0.1; step ``--ds`` (default 0.01, the Duffing example's; NLvib's
  dsmax = 5 ds) and dsmin = ds/100 (see case 2). Timed inside Octave around the continuation only
  (tic/toc and ``cputime``), best of ``--repeat``. NLvib computes no stability.
* rattle in-process (``time.process_time``, best of ``--repeat`` after a warm-up run, so numba's
  compilation is excluded): ``rattle.frequency_response`` as it always runs (exact Floquet stability
  of every point, special points located, SPEC measures, adaptive H, the exact up/down sweep
  check); the same with ``check=None``; the same with steps about as coarse as NLvib's
  (``COARSE``: about 225 points instead of about 830, the special points checked to be the same);
  and the bare continuation without stability
  (``rattle.continuation.ContinuationStepper`` on ``rattle.hb.HarmonicBalance`` with no monitor —
  ``frequency_response`` has no switch to turn stability off).
* Ratios NLvib CPU / rattle CPU; agreement: at every NLvib point, rattle's HB solution at the
  same Ω (same H and N; Newton from the nearest row of rattle's branch in (Ω, rms)) — the largest
  relative difference of the rms of δ and of the coefficients; beside it the HB truncation (the
  rms difference H = 20 vs H = 32 at the same points), and the folds (NLvib's Ω reversals vs
  rattle's located folds).

**Case 2, NLvib's EXAMPLES/03_twoDOFoscillator_unilateralSpring** (masses 1/1, springs 0/1/1,
dampers 0.03 each, a unilateral spring of stiffness 100 at gap 1 on the first mass, force 0.1 on the
second; H = 21, N = 2^10, Ω = 0.8 → 0.5, ds = 0.0085) — its HB continuation with the example's
parameters (``benchmarks/nlvib/nlvib_unilateral.m``), and rattle's chain with a ``Unilateral``
element (as ``tests/analysis/test_coverage.py`` writes it, issue 24): ``frequency_response``
started at the high end, default, with ``adaptive=None`` (issue 24's setting), with ``adaptive=None,
check=None`` (no exact sweep check), and the bare continuation. Points, rejected steps, times, ratios, folds and the stop's rms at NLvib's points.
Two things are set that an Octave user of NLvib must set: the solver options are passed as
``optimset('fsolve')`` (NLvib's default line calls ``optimset(@fsolve)``, which Octave refuses),
and dsmin = ds/100 (with NLvib's ds/5, Octave's fsolve fails near Ω = 0.58 and NLvib stops).
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import pstats
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

if __name__ == "__main__":  # one thread for numpy's BLAS, as for Octave (set before numpy loads it)
    os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import numpy as np  # noqa: E402

import rattle  # noqa: E402
from rattle.continuation import ContinuationOptions, ContinuationStepper, solve_fixed  # noqa: E402
from rattle.hb import HarmonicBalance, HBOptions, resize_harmonics  # noqa: E402
from rattle.model import Chain, Element, Link, Torque, Unilateral  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DRIVERS = Path(__file__).resolve().parent / "nlvib"
CLUTCH = ROOT / "examples" / "reference_clutch.toml"
#: Steps about as coarse as NLvib's on the clutch (≈ 225 points instead of ≈ 830; the default targets 3 Newton
#: iterations and a tangent turn of 0.1 rad per step, at most 0.08 in scaled arc length).
COARSE = ContinuationOptions(max_step=0.3, target_turn=0.3, max_turn=0.6, target_iterations=5)
SAMPLES = 1024  # AFT samples per period on both sides (rattle's default_samples for H = 20 and 32)
HOW_TO = """\
bench_nlvib: skipped — {missing}.
  GNU Octave:  apt-get install octave          (then `octave-cli` is on PATH, or give --octave PATH)
  NLvib:       git clone https://github.com/maltekrack/NLvib
               then  --nlvib /path/to/NLvib   or   export NLVIB_PATH=/path/to/NLvib
"""


def find_tools(octave: str | None, nlvib: str | None) -> tuple[str, Path] | str:
    """The Octave executable and the NLvib checkout, or a sentence saying what is missing."""
    missing = []
    exe = shutil.which(octave or "octave-cli")
    if exe is None:
        missing.append(f"no Octave ({octave or 'octave-cli'} not found)")
    path = nlvib or os.environ.get("NLVIB_PATH")
    if not path:
        missing.append("no NLvib checkout (neither --nlvib nor NLVIB_PATH given)")
    elif not (Path(path) / "SRC" / "solve_and_continue.m").is_file():
        missing.append(f"no NLvib checkout at {path} (SRC/solve_and_continue.m missing)")
    if missing:
        return "; ".join(missing)
    return exe, Path(path).resolve()  # type: ignore[arg-type]


@dataclass
class NLvibRun:
    wall: float  # best of the repeats, s
    cpu: float
    X: np.ndarray  # one solution point per row, the parameter Ω last


def run_octave(exe: str, call: str, outfile: Path) -> NLvibRun:
    """Run ``call`` (a driver of benchmarks/nlvib) in octave-cli; read the times and points it wrote."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    code = f"addpath('{DRIVERS}'); {call}"
    proc = subprocess.run([exe, "--no-gui", "--norc", "-q", "--eval", code], env=env, capture_output=True, text=True,
                          check=False)
    if not outfile.is_file():
        raise SystemExit(f"Octave failed ({exe}):\n{proc.stdout[-1500:]}\n{proc.stderr[-1500:]}")
    lines = outfile.read_text().splitlines()
    wall = min(float(v) for v in lines[0].split())
    cpu = min(float(v) for v in lines[1].split())
    return NLvibRun(wall, cpu, np.loadtxt(lines[2:], ndmin=2))


def best_cpu(fn, repeat: int):
    """Warm-up call (numba's compilation, caches), then the best CPU time of ``repeat`` calls and the last result."""
    out = fn()
    best = np.inf
    for _ in range(repeat):
        c0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - c0)
    return best, out


def bare_continuation(model, harmonics: int, omega: tuple[float, float], start: float):
    """rattle's continuation without stability: the stepper on the HB problem, no monitor, no measures."""
    hb = HarmonicBalance(model, HBOptions(harmonics=harmonics, samples=SAMPLES))
    res = solve_fixed(hb, hb.linear_solution(start), start)
    stepper = ContinuationStepper(hb, res.q, start, omega)
    stepper.run()
    return stepper


def rms_of(blocks: np.ndarray) -> np.ndarray:
    """rms (about zero) of series [a_0, a_1 … a_H, b_1 … b_H] (rows)."""
    return np.sqrt(blocks[..., 0] ** 2 + 0.5 * np.sum(blocks[..., 1:] ** 2, axis=-1))


def nlvib_to_rattle(X: np.ndarray, n: int) -> np.ndarray:
    """NLvib's [Q0 (n); Qc1 (n); Qs1 (n); …] (rows, Ω dropped) as rattle's per-coordinate [a_0, a_1…a_H, b_1…b_H]."""
    x = X[:, :-1]
    H = (x.shape[1] // n - 1) // 2
    out = np.empty((x.shape[0], n, 2 * H + 1))
    out[:, :, 0] = x[:, :n]
    cs = x[:, n:].reshape(x.shape[0], H, 2, n)  # (point, harmonic, cos/sin, coordinate)
    out[:, :, 1:H + 1] = cs[:, :, 0, :].transpose(0, 2, 1)
    out[:, :, H + 1:] = cs[:, :, 1, :].transpose(0, 2, 1)
    return out.reshape(x.shape[0], -1)


def reversals(omega: np.ndarray) -> np.ndarray:
    """Ω where a computed branch turns back (its folds, seen as reversals of Ω between points)."""
    d = np.diff(omega)
    return omega[1:-1][d[1:] * d[:-1] < 0]


def branch_distance(frf, omega: float, rms: float) -> float:
    """Relative distance from (Ω, rms) to rattle's computed branch: the nearest point of the polyline through
    consecutive rows of one branch, in the plane (Ω / omega, rms / rms) (a fold's nearly vertical stretch is
    measured across, not by interpolating in Ω)."""
    same = frf.branch[1:] == frf.branch[:-1]
    p = np.column_stack([frf.omega / omega, frf.rms / rms])
    a, b = p[:-1][same], p[1:][same]
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", np.array([1.0, 1.0]) - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300),
                0.0, 1.0)
    return float(np.min(np.hypot(*(a + t[:, None] * d - 1.0).T)))


def agreement(model, frf, X: np.ndarray, harmonics: int, n: int = 1, truncation_h: int | None = None) -> dict:
    """At every NLvib point: rattle's HB solution at the same Ω (same H and N) by Newton from NLvib's point.

    Returns the largest relative differences: ``rms`` (of the first coordinate) and ``q`` (coefficients, to the
    largest) between NLvib's point and that solution (NLvib's solver tolerance); ``branch``, the solution's
    distance to rattle's computed branch (:func:`branch_distance`: the same branch, to its interpolation);
    ``rms_median`` the median of the first; ``truncation``, the rms with ``truncation_h`` harmonics against ``harmonics`` at the same points (the HB
    truncation); ``used`` the points inside rattle's range whose Newton converged (not at a fold, where the
    Jacobian at fixed Ω is singular).
    """
    hb = HarmonicBalance(model, HBOptions(harmonics=harmonics, samples=SAMPLES))
    hb2 = HarmonicBalance(model, HBOptions(harmonics=truncation_h, samples=SAMPLES)) if truncation_h else None
    size = 2 * harmonics + 1
    out: dict[str, list[float]] = {"rms": [], "q": [], "branch": [], "truncation": []}
    lo, hi = float(frf.omega.min()), float(frf.omega.max())
    for w, q in zip(X[:, -1], nlvib_to_rattle(X, n)):
        if not lo <= w <= hi:
            continue  # NLvib's last step passes the end of the range; rattle's ends on it
        sol = solve_fixed(hb, q, float(w))
        if not sol.converged:
            continue
        r = float(rms_of(sol.q[:size]))
        out["rms"].append(abs(float(rms_of(q[:size])) - r) / r)
        out["q"].append(float(np.max(np.abs(q - sol.q)) / np.max(np.abs(sol.q))))
        out["branch"].append(branch_distance(frf, float(w), r))
        if hb2 is not None:
            s2 = solve_fixed(hb2, resize_harmonics(sol.q.reshape(n, -1), truncation_h).ravel(), float(w))
            if s2.converged:
                out["truncation"].append(abs(float(rms_of(s2.q[:2 * truncation_h + 1])) - r) / r)
    res = {k: (float(np.nanmax(v)) if v else np.nan) for k, v in out.items()}
    res["rms_median"] = float(np.median(out["rms"])) if out["rms"] else np.nan
    res["used"] = len(out["rms"])
    return res


def unilateral_chain() -> Chain:
    """NLvib's two-DOF oscillator with a unilateral spring as a rattle chain (tests/analysis/test_coverage.py)."""
    return Chain(
        inertias=(1.0, 1.0),
        links=(Link(between=(1, 2), stiffness=1.0, damping=0.03), Link(between=(2, 0), stiffness=1.0, damping=0.03)),
        elements=(Element(name="stop", between=(1, 0), stiffness=100.0, law=Unilateral(gap=1.0)),),
        torques=(Torque(inertia=2, mean=0.0, amplitudes=(0.1,), phases=(0.0,)),),
    )


def special_difference(a, b) -> float:
    """Largest |ΔΩ| between the special points of two runs (inf when their kinds or numbers differ)."""
    pa = sorted((p.kind, p.omega) for p in a.special_points)
    pb = sorted((p.kind, p.omega) for p in b.special_points)
    if [k for k, _ in pa] != [k for k, _ in pb]:
        return float("inf")
    return max((abs(x - y) for (_, x), (_, y) in zip(pa, pb)), default=0.0)


def folds_of(frf) -> list[float]:
    return sorted(round(p.omega, 4) for p in frf.special_points if p.kind == "fold")


def clutch_case(exe: str, nlvib: Path, tmp: Path, args) -> None:
    model = rattle.Model.from_toml(CLUTCH)
    lo, hi = 0.1, 3.0
    law, exc = model.elastic, model.excitation
    params = (f"struct('I',{model.inertia!r},'c',{model.damping!r},'k',{model.stiffness!r},'alpha',{law.alpha!r},'b',{law.b!r},"
              f"'Fm',{exc.mean!r},'Fp',{exc.amplitudes[0]!r})")
    print(f"Case 1 — the reference clutch ({CLUTCH.relative_to(ROOT)}), Ω = {lo} … {hi}, N = {SAMPLES}; "
          f"NLvib ds = {args.ds:g} (dsmin ds/100, dsmax 5 ds), best of {args.repeat}")
    frfs = {}
    for H in args.harmonics:
        out = tmp / f"clutch_{H}.txt"
        nl = run_octave(exe, f"nlvib_clutch('{nlvib}', {params}, {H}, {SAMPLES}, {lo}, {hi}, {args.ds}, "
                             f"{args.ds / 100}, {args.repeat}, '{out}')", out)
        t_full, frf = best_cpu(lambda: rattle.frequency_response(model, omega=(lo, hi), harmonics=H), args.repeat)
        t_nochk, _ = best_cpu(lambda: rattle.frequency_response(model, omega=(lo, hi), harmonics=H, check=None),
                              args.repeat)
        t_coarse, frf_coarse = best_cpu(lambda: rattle.frequency_response(model, omega=(lo, hi), harmonics=H,
                                                                          continuation=COARSE), args.repeat)
        t_bare, stepper = best_cpu(lambda: bare_continuation(model, H, (lo, hi), lo), args.repeat)
        frfs[H] = frf
        other = 32 if H != 32 else 20
        ag = agreement(model, frf, nl.X, H, truncation_h=other)
        npts = nl.X.shape[0]
        print(f"  H = {H}:")
        print(f"    NLvib solve_and_continue        {npts:5d} points  CPU {nl.cpu:7.3f} s  (wall {nl.wall:.3f} s)"
              f"  {nl.cpu / npts * 1e3:6.2f} ms/point")
        for label, t, pts in (("rattle frequency_response       ", t_full, len(frf)),
                              ("rattle frequency_response check=None", t_nochk, len(frf)),
                              ("rattle frequency_response coarse steps", t_coarse, len(frf_coarse)),
                              ("rattle bare continuation, no stab.", t_bare, len(stepper.points))):
            print(f"    {label:34s}{pts:5d} points  CPU {t:7.3f} s  {t / pts * 1e3:6.2f} ms/point  "
                  f"ratio NLvib/rattle {nl.cpu / t:6.1f} x  (per point {nl.cpu / npts / (t / pts):6.1f} x)")
        print(f"    agreement at {ag['used']}/{npts} NLvib points: rattle's HB solution at the same Ω (same H, N; "
              f"Newton from NLvib's point) — rms within {ag['rms']:.1e} (median {ag['rms_median']:.0e}), coefficients within {ag['q']:.1e} "
              f"(relative; NLvib's fsolve tolerance); it lies on rattle's computed branch within {ag['branch']:.1e} "
              f"(relative, to the polyline of its rows); HB truncation, rms H = {H} vs {other} there: {ag['truncation']:.1e}")
        print(f"    folds: NLvib's Ω reversals {[round(float(w), 4) for w in sorted(reversals(nl.X[:, -1]))]}")
        print(f"           rattle's located    {folds_of(frf)}; coarse steps: the same "
              f"{len(frf.special_points)} special points within "
              f"{special_difference(frf, frf_coarse):.1e} in Ω")


def unilateral_case(exe: str, nlvib: Path, tmp: Path, args) -> None:
    chain = unilateral_chain()
    lo, hi, H = 0.5, 0.8, 21
    print("Case 2 — NLvib's EXAMPLES/03_twoDOFoscillator_unilateralSpring (H = 21, N = 1024, Ω 0.8 → 0.5, "
          f"ds = 0.0085 scaled, dsmin ds/100), best of {args.repeat}")
    out = tmp / "unilateral.txt"
    nl = run_octave(exe, f"nlvib_unilateral('{nlvib}', {0.0085 / 100}, {args.repeat}, '{out}')", out)
    t_full, frf = best_cpu(lambda: rattle.frequency_response(chain, omega=(lo, hi), harmonics=H, start="high"),
                           args.repeat)
    t_fixed, frf_fixed = best_cpu(lambda: rattle.frequency_response(chain, omega=(lo, hi), harmonics=H, start="high",
                                                                    adaptive=None), args.repeat)
    t_nochk, frf_nochk = best_cpu(lambda: rattle.frequency_response(chain, omega=(lo, hi), harmonics=H, start="high",
                                                                    adaptive=None, check=None), args.repeat)
    t_bare, stepper = best_cpu(lambda: bare_continuation(chain, H, (lo, hi), hi), args.repeat)
    npts = nl.X.shape[0]
    print(f"    NLvib solve_and_continue (HB_residual)  {npts:5d} points  CPU {nl.cpu:7.3f} s  (wall {nl.wall:.3f} s)"
          f"  reaches Ω = {nl.X[:, -1].min():.4f}")
    for label, t, pts, extra in (
            ("rattle frequency_response (default)", t_full, len(frf), ""),
            ("rattle frequency_response adaptive=None", t_fixed, len(frf_fixed), ""),
            ("rattle … adaptive=None, check=None", t_nochk, len(frf_nochk), ""),
            ("rattle bare continuation, no stab.", t_bare, len(stepper.points), f", {stepper.rejected} rejected")):
        print(f"    {label:40s}{pts:5d} points{extra}  CPU {t:7.3f} s  ratio NLvib/rattle {nl.cpu / t:6.2f} x")
    ag = agreement(chain, frf_fixed, nl.X, H, n=2)
    print(f"    agreement at {ag['used']}/{npts} NLvib points: rattle's HB solution at the same Ω (same H, N; "
          f"Newton from NLvib's point) — stop rms within {ag['rms']:.1e} (median {ag['rms_median']:.0e}), coefficients within {ag['q']:.1e} "
          f"(relative); it lies on rattle's computed branch within {ag['branch']:.1e} (relative, to the polyline of its rows)")
    print(f"    folds: NLvib's Ω reversals {[round(float(w), 4) for w in sorted(reversals(nl.X[:, -1]))]}")
    print(f"           rattle's located    {folds_of(frf_fixed)} (adaptive=None); special points "
          f"{sorted((p.kind, round(p.omega, 4)) for p in frf_fixed.special_points)}")


def profile(harmonics: int = 32, top: int = 10) -> None:
    """cProfile of rattle.frequency_response on the reference case (after a warm-up): the biggest costs."""
    model = rattle.Model.from_toml(CLUTCH)
    rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=harmonics)
    prof = cProfile.Profile()
    prof.enable()
    rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=harmonics)
    prof.disable()
    for key in ("cumulative", "tottime"):
        s = io.StringIO()
        pstats.Stats(prof, stream=s).strip_dirs().sort_stats(key).print_stats(top)
        table = s.getvalue()
        print(f"--- rattle.frequency_response, reference case H = {harmonics}: top {top} by {key} ---")
        print(table[table.index("   ncalls"):].rstrip())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--octave", help="the Octave executable (default: octave-cli on PATH)")
    parser.add_argument("--nlvib", help="an NLvib checkout (default: $NLVIB_PATH)")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs of each side, best reported (default 3)")
    parser.add_argument("--ds", type=float, default=0.01, help="NLvib's step on the clutch (default 0.01)")
    parser.add_argument("--harmonics", type=int, nargs="+", default=[20, 32], help="H of case 1 (default 20 32)")
    parser.add_argument("--case", choices=("clutch", "unilateral", "both"), default="both")
    parser.add_argument("--profile", action="store_true", help="only profile rattle's reference FRF at H = 32")
    args = parser.parse_args(argv)
    if args.profile:
        profile()
        return 0
    tools = find_tools(args.octave, args.nlvib)
    if isinstance(tools, str):
        print(HOW_TO.format(missing=tools), end="")
        return 0
    exe, nlvib = tools
    version = subprocess.run([exe, "--version"], capture_output=True, text=True, check=False).stdout.splitlines()
    print(f"NLvib {nlvib} on {version[0] if version else exe}; rattle {rattle.__version__} "
          f"({Path(rattle.__file__).parent}); load average {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        if args.case in ("clutch", "both"):
            clutch_case(exe, nlvib, Path(tmp), args)
        if args.case in ("unilateral", "both"):
            unilateral_case(exe, nlvib, Path(tmp), args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
