"""Figures behind the size bounds of ``rattle._limits`` (run: ``python benchmarks/bench_limits.py``).

Prints, for the reference clutch:

1. a frequency response over Ω = 0.35 … 0.5 (two period doublings, located again with 2H) for
   H = 32, 64, 128, 256 (``--full``: also 512): points, wall time, time per point, peak memory
   (VmHWM of a fresh process per H);
2. the time of one steady-state simulation from rest at Ω = 1e-2 … 1e-5 × ω_s (the bound
   is 1e-3; ``orbit --omega 1e-6`` took 314 s before it);
3. how long refusing a hostile argument takes (the checks run before any work).

Each case runs in its own process so that the peak memory is that case's alone.
"""

from __future__ import annotations

import subprocess
import sys
import time

_FRF = """
import resource, time, rattle
m = rattle.reference_case()
t = time.perf_counter()
frf = rattle.frequency_response(m, omega=(0.35, 0.5), harmonics={H}, throw=False)
dt = time.perf_counter() - t
print(f"{{len(frf)}} {{dt:.2f}} {{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}}")
"""

_STEADY = """
import time, numpy as np, rattle
from rattle.analysis._steady import SteadyStateOptions, _ModelFlow, _Settler
from rattle.timeint import ExactIntegrator
m = rattle.reference_case()
t = time.perf_counter()
# below the bound, steady_state() refuses: run the settler
s = _Settler(_ModelFlow(m, ExactIntegrator(m), {W}), {W}, np.zeros(2), SteadyStateOptions(), ()).run()
print(f"{{s.period}} {{time.perf_counter() - t:.2f}}")
"""


def _run(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")[-2]


def main() -> None:
    sizes = [32, 64, 128, 256] + ([512] if "--full" in sys.argv else [])
    print("frequency response, reference clutch, Ω = 0.35 … 0.5 (2 period doublings, re-located with 2H)")
    print(f"{'H':>5} {'points':>7} {'time s':>8} {'ms/point':>9} {'peak MB':>8}")
    for H in sizes:
        points, dt, mb = _run(_FRF.format(H=H)).split()
        print(f"{H:>5} {points:>7} {float(dt):>8.2f} {1e3 * float(dt) / int(points):>9.1f} {mb:>8}")
    print("\nsteady state from rest, reference clutch (ω_s = 1 rad/s)")
    for w in (1e-2, 1e-3, 1e-4, 1e-5):
        period, dt = _run(_STEADY.format(W=w)).split()
        print(f"  Ω = {w:g} ω_s: period {period}, {float(dt):.2f} s")
    import numpy as np

    import rattle

    model = rattle.reference_case()
    print("\nrefusals (the checks run before any work; the package is imported first)")
    rattle.frequency_response  # noqa: B018 - the lazy import, outside the timing
    for label, call in [
        ("harmonics=10000", lambda: rattle.frequency_response(model, harmonics=10000)),
        ("omega=1e-6 (orbit)", lambda: rattle.periodic_orbit(model, 1e-6)),
        ("points=1e9 (sweep)", lambda: rattle.time_sweep(model, points=10**9)),
        ("harmonics=np.int64(10**6)", lambda: rattle.frequency_response(model, harmonics=np.int64(10**6))),
    ]:
        t = time.perf_counter()
        try:
            call()
        except (ValueError, TypeError) as exc:
            print(f"  {label}: {type(exc).__name__} after {1e3 * (time.perf_counter() - t):.2f} ms")


if __name__ == "__main__":
    main()
