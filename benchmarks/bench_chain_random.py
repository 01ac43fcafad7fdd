"""Random chains against the exact N-DOF shooting reference: special points, kinds and order.

Run:  python benchmarks/bench_chain_random.py [SEED] [SECONDS]     (defaults 5 and 600)

Random free or grounded chains of 2–3 inertias with 1–3 clearance elements (clutch, backlash,
asymmetric three-stage laws), random links, damping and one engine harmonic, over a range
around their natural frequencies: ``rattle.frequency_response`` (H = 32) against
``tests/_exact_branch.py`` (shooting continuation on the exact flow, every change of stability
located to 1e-11). A case whose branch leaves the range at the end it started from is reported
as it is (the reference follows it outside the range and may find points on its way back in).
"""
import time, sys, warnings, numpy as np, rattle
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parents[1] / 'tests'))
import _exact_branch as xb
from test_chains import _state
from rattle.model import Chain, Link, Element, Torque, Clutch, Backlash, Piecewise
warnings.simplefilter("ignore")
rng = np.random.default_rng(int(sys.argv[1]) if len(sys.argv) > 1 else 1)
def law():
    k = rng.integers(3)
    b = float(rng.uniform(0.05, 0.3))
    if k == 0: return Clutch(alpha=float(rng.uniform(0.1, 0.5)), b=b)
    if k == 1: return Backlash(b=b)
    return Piecewise(breakpoints=(-b, 0.5*b), slopes=(1.0, float(rng.uniform(0.05, 0.4)), 1.0))
def case():
    N = int(rng.integers(2, 4)); grounded = bool(rng.integers(2))
    I = tuple(float(x) for x in rng.uniform(0.3, 2.0, N))
    links, elements = [], []
    for i in range(1, N):
        links.append(Link(between=(i, i+1), stiffness=float(rng.choice([0.0, rng.uniform(0.1, 1.0)])), damping=float(rng.uniform(0.02, 0.08))))
    e_pairs = [(i, i+1) for i in range(1, N)]
    if grounded:
        links.append(Link(between=(1, 0), damping=float(rng.uniform(0.01, 0.05)), stiffness=float(rng.uniform(0.0, 0.5))))
        e_pairs.append((N, 0))
    for k, p in enumerate(e_pairs[: int(rng.integers(1, len(e_pairs)+1))]):
        elements.append(Element(name=f"e{k}", between=p, stiffness=float(rng.uniform(0.5, 2.0)), law=law()))
    Tm = float(rng.uniform(0.02, 0.08))
    torques = [Torque(inertia=1, mean=Tm, amplitudes=(float(rng.uniform(0.02, 0.06)),))]
    if not grounded: torques.append(Torque(inertia=N, mean=-Tm))
    return Chain(inertias=I, links=tuple(links), elements=tuple(elements), torques=tuple(torques))
done = 0
t_end = time.time() + float(sys.argv[2]) if len(sys.argv) > 2 else time.time() + 600
while time.time() < t_end:
    try:
        m = case()
    except ValueError as e:
        continue
    wn = m.system().natural_frequencies()
    lo, hi = 0.3 * wn[0] if wn[0] > 0 else 0.2, 1.5 * wn[-1]
    lo, hi = max(lo, 0.15), min(hi, 3.0)
    try:
        f = rattle.frequency_response(m, omega=(lo, hi), harmonics=32, confirm_tori=False, throw=False)
    except Exception as e:
        print("HB ERR", type(e).__name__, str(e)[:100]); continue
    if not f.status.success or len(f.special_points) > 12:
        print("skip", f.status.name, len(f.special_points)); continue
    try:
        r = xb.exact_special_points(m, (lo, hi), x0=_state(f, m, 0), max_step=1e-2, max_domega=5e-3)
    except Exception as e:
        print("REF ERR", str(e)[:80]); continue
    hb = [(s.kind, s.omega) for s in f.special_points]
    same = [k for k, _ in hb] == [k for k, _ in r.special]
    worst = max((abs(a[1]-b[1]) for a, b in zip(hb, r.special)), default=0.0) if same else None
    done += 1
    print(f"case {done}: N={m.n_inertias} free={m.free} m={len(m.elements)} Ω=({lo:.3f},{hi:.3f}) HB {len(hb)} exact {len(r.special)} same={same} worst={worst}", flush=True)
    if not same:
        print("   HB   ", [(k[:4], round(w, 6)) for k, w in hb]); print("   exact", [(k[:4], round(w, 6)) for k, w in r.special], flush=True)
