"""The public surface: curated exports (a snapshot), documented, no keyword sinks; method objects
and names at the boundary."""

from __future__ import annotations

import inspect
import re

import numpy as np
import pytest

import rattle


def test_all_exports_exist_and_are_documented():
    for name in rattle.__all__:
        obj = getattr(rattle, name)
        if name == "__version__":
            continue
        assert inspect.getdoc(obj), f"rattle.{name} has no docstring"


@pytest.mark.parametrize("name", [n for n in rattle.__all__ if callable(getattr(rattle, n, None))])
def test_no_var_keyword_sinks(name):
    """No public callable accepts **kwargs: an unknown keyword must raise TypeError."""
    obj = getattr(rattle, name)
    if getattr(obj, "_is_protocol", False):  # a typing.Protocol: not instantiable at all
        with pytest.raises(TypeError):
            obj(bogus=1)
        return
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):  # pragma: no cover - builtins
        return
    assert not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values()), name


def test_unknown_keywords_raise():
    with pytest.raises(TypeError):
        rattle.frequency_response(rattle.reference_case(), omega=(0.5, 1.0), harmonic=4)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        rattle.Clutch(alpha=0.2, b=0.1, beta=1.0)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        rattle.ContinuationOptions(max_step=0.1, step=0.1)  # type: ignore[call-arg]


def test_options_are_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        rattle.HBOptions(32)  # type: ignore[misc]
    opts = rattle.NewtonOptions()
    with pytest.raises(AttributeError):
        opts.max_iterations = 3  # type: ignore[misc]


#: The curated top-level API. A change here is a change of the public contract: update
#: docs/python.md with it.
PUBLIC_API = {
    "__version__",
    "Model", "Excitation", "Linear", "Backlash", "Clutch", "Piecewise", "Unilateral", "AbstractElastic", "reference_case",
    "backlash_case", "Chain", "Link", "Element", "Torque", "System",
    "load_case", "frequency_response", "FrequencyResponse", "SpecialPoint", "Region", "LinearResponse",
    "linear_frequency_response", "time_sweep", "SweepResult", "steady_state", "SteadyStateOptions",
    "shoot_periodic_orbit", "periodic_orbit", "PeriodicOrbit", "OrbitSolution", "compare", "Comparison",
    "response_map", "ResponseMap", "AttractorSearch",
    "NonsmoothLaw", "Preload", "PiecewiseJump", "Friction",
    "ShootingOptions", "RegularisationOptions", "HBOptions", "NewtonOptions", "ContinuationOptions", "Monodromy", "Hill",
    "ContinuationProblem", "HarmonicBalance", "ShootingProblem", "ContinuationStepper", "ExactIntegrator",
    "sound_pressure", "linear_sound_pressure", "SoundPressure", "SoundPath",
    "Drag", "clutch_damper", "hub_spline", "gear_pair", "loose_gear",
    "Status", "RattleError", "ConfigError", "ConvergenceError",
}


def test_public_api_snapshot():
    assert set(rattle.__all__) == PUBLIC_API
    assert len(rattle.__all__) == len(PUBLIC_API)  # no name listed twice


@pytest.mark.parametrize("package", ["analysis", "continuation", "engines", "hb", "maps", "model", "results", "stability",
                                     "timeint"])
def test_subpackage_exports_exist(package):
    import importlib

    module = importlib.import_module(f"rattle.{package}")
    assert module.__doc__, f"rattle.{package} has no docstring"
    for name in module.__all__:
        assert hasattr(module, name), f"rattle.{package}.{name} is in __all__ but missing"


def test_every_top_level_name_is_in_the_python_page():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "python.md").read_text(encoding="utf-8")
    missing = [n for n in rattle.__all__ if n != "__version__" and not re.search(rf"(?<![\w.]){n}(?!\w)", text)
               and f"rattle.{n}" not in text]
    assert not missing, f"not in docs/python.md: {missing}"


def test_extension_points_are_what_the_core_works_with(reference_model):
    assert issubclass(rattle.Clutch, rattle.AbstractElastic)
    hb = rattle.HarmonicBalance(reference_model, rattle.HBOptions(harmonics=4))
    shooting = rattle.ShootingProblem(reference_model.system())
    assert isinstance(hb, rattle.ContinuationProblem) and isinstance(shooting, rattle.ContinuationProblem)
    assert isinstance(reference_model.system(), rattle.System)


def test_stability_names_at_the_boundary_become_method_objects(reference_model):
    """``stability="hill"`` and ``stability=rattle.Hill()`` are the same run; the settings record
    the name; an unknown name is refused with the allowed ones."""
    from rattle.analysis._settings import RunSettings

    run = RunSettings.make(rattle.HBOptions(harmonics=4), None, None, "hill")
    assert run.stability == rattle.Hill() and run.record()["stability"] == "hill"
    assert RunSettings.make(rattle.HBOptions(harmonics=4), None, None, rattle.Monodromy()).stability == rattle.Monodromy()
    by_name = rattle.frequency_response(reference_model, omega=(1.5, 1.8), harmonics=4, stability="hill")
    by_object = rattle.frequency_response(reference_model, omega=(1.5, 1.8), harmonics=4, stability=rattle.Hill())
    assert by_name.settings["stability"] == by_object.settings["stability"] == "hill"
    assert np.array_equal(by_name.multipliers, by_object.multipliers)
    with pytest.raises(ValueError, match=r"`stability` must be 'monodromy' or 'hill' \(or a method object"):
        rattle.frequency_response(reference_model, omega=(1.5, 1.8), harmonics=4, stability="floquet")
