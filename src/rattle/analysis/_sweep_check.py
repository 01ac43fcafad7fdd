"""The attractors an exact up/down sweep settles on that the continued branches miss.

Continuation from the start solution at one end of the range follows one branch (and, where it
does not cover the range, the branch through the other end). A periodic attractor on a branch
connected to neither — a rattling orbit beside a stable non-impacting one, reached by running the
speed up through the rattle region — is missed. A coarse exact time sweep both ways carries its
state from one frequency to the next as a run-up and run-down do, so it settles on those
attractors. Every period-1 motion it settles on that no stable computed stretch explains (Ω and
rms within ``rtol``) is closed by the exact flow already (the sweep's steady state is a shot
orbit), analysed into harmonics and continued as a branch of its own
(:func:`~rattle.analysis._branches.branch_from_seed`, both ways in Ω). Sub-harmonic motions are
left to ``subharmonics=True`` and the regions' labels.

Cost: the sweep (``points`` frequencies each way, ~20 ms a frequency on the single equation)
and one branch per attractor found. What it can still miss: an attractor whose basin neither a
run-up nor a run-down enters, or that exists only between two sweep frequencies (narrower than
(Ω_max − Ω_min)/``points``); the map's fuller search (:mod:`rattle.analysis._attractors`,
``rattle map``) looks there too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .. import _validate
from ..hb import HarmonicBalance
from ..results import FrequencyResponse
from ._attractors import trajectory_coefficients
from ._branches import branch_from_seed, explained
from ._settings import RunSettings


@dataclass(frozen=True, slots=True)
class SweepCheck:
    """The exact up/down sweep that checks a frequency response for attractors its branches
    miss (module docstring): ``points`` frequencies each way (default 16), an attractor is
    explained when a stable stretch of a computed branch crosses its Ω with an rms within
    ``rtol`` (default 1 %) of it, at most ``max_branches`` new branches (default 4); a motion
    not settled on a period-1 orbit within ``max_periods`` forcing periods (default 200) is not
    one of them (a non-periodic motion, or a sub-harmonic: ``subharmonics=True``)."""

    points: int = 16
    rtol: float = 1e-2
    max_branches: int = 4
    max_periods: int = 200

    def __post_init__(self) -> None:
        _validate.check_int("points", self.points, 2)
        _validate.check_int("max_periods", self.max_periods, 10)
        _validate.check_int("max_branches", self.max_branches, 0)
        rtol = _validate.check_real(self.rtol, "rtol")
        if not 0.0 < rtol < 1.0:
            raise ValueError(f"`rtol` must be in (0, 1), got {self.rtol!r}")


def missed_branches(frf: FrequencyResponse, omega_range: tuple[float, float], run: RunSettings, check: SweepCheck,
                    *, first_branch: int) -> tuple[list[FrequencyResponse], dict[str, Any]]:
    """The branches through the period-1 attractors of an exact up/down sweep over
    ``omega_range`` that ``frf``'s branches do not explain (ids from ``first_branch``), and a
    record of the check (points, attractors seen, seeded, explained)."""
    from ._steady import SteadyStateOptions
    from ._time_sweep import time_sweep

    model = frf.model
    lo, hi = omega_range
    # A motion that has not settled within max_periods is not periodic for this check (a period-1
    # attractor settles in tens of periods once the state is carried; chaos would take the default 1500)
    sweep = time_sweep(model, omega=(lo, hi), points=check.points, direction="both",
                       options=SteadyStateOptions(max_periods=check.max_periods, max_period_multiple=1,
                                                  record_periods=1))
    H = run.hb.harmonics
    hb = HarmonicBalance(model, run.for_harmonics(H), period=1)
    out: list[FrequencyResponse] = []
    tried: list[FrequencyResponse] = []  # seeded branches that did not explain their attractor
    record: dict[str, Any] = {"points": check.points, "attractors": 0, "unexplained": [], "seeded": [],
                              "on_a_seeded_branch": []}
    for j, (traj, window) in enumerate(sweep.records()):
        if traj is None or int(sweep.period[j]) != 1:
            continue
        record["attractors"] += 1
        w, rms = float(sweep.omega[j]), float(sweep.rms[j])
        known = FrequencyResponse.concatenate([frf, *out]) if out else frf
        if explained(known, 1, w, rms, check.rtol):
            continue
        record["unexplained"].append([w, rms])
        if len(out) >= check.max_branches:
            continue
        if any(explained(b, 1, w, rms, check.rtol, stable_only=False) for b in tried):
            # on a branch already seeded that the harmonic balance calls unstable there (its
            # truncation: measured, NLvib's unilateral example at H = 21, where the HB has a period
            # doubling the exact flow has not): seeding it again gives the same branch
            record["on_a_seeded_branch"].append([w, rms])
            continue
        q = trajectory_coefficients(traj, 2.0 * math.pi / w, hb)
        branch = branch_from_seed(model, w, q, 1, (lo, hi), H, run=run, branch_id=first_branch + len(out))
        if branch is not None and len(branch) and explained(FrequencyResponse.concatenate([frf, *out, branch]), 1, w,
                                                            rms, check.rtol):
            out.append(branch)
            record["seeded"].append([w, rms])
        elif branch is not None and len(branch):
            tried.append(branch)
    return out, record


__all__ = ["SweepCheck", "missed_branches"]
