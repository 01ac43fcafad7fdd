"""rattle — non-linear frequency response of drivetrain rattle.

Harmonic balance (alternating frequency–time, analytic Jacobians), pseudo-arclength
continuation in the forcing frequency with self-adjusting steps, Floquet stability and
bifurcation labels for torsional sub-systems with clearance non-linearities:

    δ'' + (C/I) δ' + (K/I) f(δ) = F_m + Σ_n F_pn cos(n Ω t + φ_n).

>>> import rattle
>>> model = rattle.reference_case()
>>> frf = rattle.frequency_response(model, omega=(0.1, 3.0), harmonics=32)

The curated public API (``__all__``): the front ends and their result types, the model types
(``Model``, ``Chain``, ``System``), the option objects, and the extension points — the elastic
law base class ``AbstractElastic``, the exact flow (``ExactIntegrator``, every system),
the continuation core (``ContinuationProblem``, implemented by ``HarmonicBalance`` and
``ShootingProblem``; ``ContinuationStepper``) and the stability method objects (``Monodromy``,
``Hill``). Everything else lives in the sub-packages.

The names below are re-exported lazily (PEP 562): ``import rattle`` is cheap, and a name's
sub-package (numpy, scipy) is imported the first time the name is used — so ``rattle --help``
and a refused input answer without loading the numerics. ``from rattle import X``,
``rattle.X`` and ``dir(rattle)`` work as with eager imports.
"""

from __future__ import annotations

# First, before any slower import: in the command-line process (`rattle …`, `python -m rattle …`)
# SIGINT/SIGTERM/SIGHUP exit 128 + n with one line from here on; a no-op for a library import.
from ._signals import install_at_start as _install_at_start

_install_at_start()

import importlib
from typing import TYPE_CHECKING, Any


def _version() -> str:
    from ._release import version

    return version()

#: Public name → the sub-module that defines it (the one registry of the lazy re-exports).
_LAZY: dict[str, str] = {
    **dict.fromkeys(
        ["RegularisationOptions", "ShootingOptions", "SteadyStateOptions", "compare", "frequency_response",
         "load_case", "periodic_orbit", "steady_state", "time_sweep"],
        ".analysis",
    ),
    **dict.fromkeys(
        ["ContinuationOptions", "ContinuationProblem", "ContinuationStepper", "NewtonOptions"], ".continuation"
    ),
    **dict.fromkeys(["ConfigError", "ConvergenceError", "RattleError", "Status"], ".errors"),
    **dict.fromkeys(["HBOptions", "HarmonicBalance"], ".hb"),
    **dict.fromkeys(
        ["AbstractElastic", "Backlash", "Chain", "Clutch", "Element", "Excitation", "Linear", "Link", "Model",
         "Piecewise", "System", "Torque", "Unilateral", "backlash_case", "reference_case"],
        ".model",
    ),
    **dict.fromkeys(
        ["Comparison", "FrequencyResponse", "LinearResponse", "OrbitSolution", "PeriodicOrbit", "Region",
         "SpecialPoint", "SweepResult", "linear_frequency_response"],
        ".results",
    ),
    **dict.fromkeys(["Hill", "Monodromy"], ".stability"),
    **dict.fromkeys(["AttractorSearch", "ResponseMap", "response_map"], ".maps"),
    **dict.fromkeys(
        ["ExactIntegrator", "ShootingProblem", "shoot_periodic_orbit"], ".timeint",
    ),
    **dict.fromkeys(["SoundPath", "Drag"], ".model"),
    **dict.fromkeys(["NonsmoothLaw", "Preload", "PiecewiseJump", "Friction"], ".model"),
    **dict.fromkeys(["clutch_damper", "hub_spline", "gear_pair", "loose_gear"], ".model"),
    **dict.fromkeys(["SoundPressure", "linear_sound_pressure", "sound_pressure"], ".results"),
}

#: Sub-packages reachable as attributes of ``rattle`` (imported on first use, as eagerly before).
_SUBPACKAGES = frozenset({
    "analysis", "continuation", "demo", "engines", "errors", "hb", "io", "maps", "measures", "model", "plotting",
    "results",
    "stability", "timeint",
})

__all__ = [
    "__version__",
    # models
    "Model", "Excitation", "Linear", "Backlash", "Clutch", "Piecewise", "Unilateral", "AbstractElastic", "reference_case",
    "backlash_case", "Chain", "Link", "Element", "Torque", "System", "Drag",
    # sub-system builders (a data sheet → an ordinary chain element or chain)
    "clutch_damper", "hub_spline", "gear_pair", "loose_gear",
    # front ends and their results
    "load_case", "frequency_response", "FrequencyResponse", "SpecialPoint", "Region", "LinearResponse",
    "linear_frequency_response", "time_sweep", "SweepResult", "steady_state", "SteadyStateOptions",
    "shoot_periodic_orbit", "periodic_orbit", "PeriodicOrbit", "OrbitSolution", "compare", "Comparison",
    "response_map", "ResponseMap", "AttractorSearch",
    # laws with torque jumps or friction (System.single: one equation; a Chain's elements take them too)
    "NonsmoothLaw", "Preload", "PiecewiseJump", "Friction",
    # options and method objects (ShootingOptions, RegularisationOptions: the method for jumps or friction)
    "ShootingOptions", "RegularisationOptions", "HBOptions", "NewtonOptions", "ContinuationOptions", "Monodromy", "Hill",
    # extension points: problems, the stepper, the integrators
    "ContinuationProblem", "HarmonicBalance", "ShootingProblem", "ContinuationStepper", "ExactIntegrator",
    # sound pressure at a receiver (SPEC §6)
    "sound_pressure", "linear_sound_pressure", "SoundPressure", "SoundPath",
    # status and errors
    "Status", "RattleError", "ConfigError", "ConvergenceError",
]


def __getattr__(name: str) -> Any:
    """Import the sub-module that defines ``name`` on first use and cache the name here."""
    if name == "__version__":
        value: Any = _version()
    elif name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    elif name in _SUBPACKAGES:  # ``rattle.analysis.x`` without importing rattle.analysis first
        value = importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module 'rattle' has no attribute {name!r}")
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # static checkers and IDEs see the eager imports
    __version__: str
    from .analysis import (
        RegularisationOptions, ShootingOptions, SteadyStateOptions, compare, frequency_response, load_case,
        periodic_orbit, steady_state, time_sweep,
    )
    from .continuation import ContinuationOptions, ContinuationProblem, ContinuationStepper, NewtonOptions
    from .errors import ConfigError, ConvergenceError, RattleError, Status
    from .hb import HarmonicBalance, HBOptions
    from .model import (
        AbstractElastic, Backlash, Chain, Clutch, Element, Excitation, Linear, Link, Model, Piecewise, System, Torque,
        Unilateral,
        backlash_case, reference_case,
    )
    from .results import (
        Comparison, FrequencyResponse, LinearResponse, OrbitSolution, PeriodicOrbit, Region, SpecialPoint,
        SweepResult, linear_frequency_response,
    )
    from .maps import AttractorSearch, ResponseMap, response_map
    from .stability import Hill, Monodromy
    from .timeint import ExactIntegrator, ShootingProblem, shoot_periodic_orbit
    from .model import Drag, SoundPath
    from .model import Friction, NonsmoothLaw, PiecewiseJump, Preload
    from .model import clutch_damper, gear_pair, hub_spline, loose_gear
    from .results import SoundPressure, linear_sound_pressure, sound_pressure
