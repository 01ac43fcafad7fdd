"""Model-level rules: magnitudes and derived scales bounded, zero damping a valid model (refused
only by the analyses), clearances beyond pi/2 rad warned about."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from rattle import _limits
from rattle.model import Backlash, Clutch, Excitation, Linear, Model, check_analysable_model


def _model(**kw) -> Model:
    base = dict(inertia=1.0, damping=0.05, stiffness=1.0, elastic=Linear(), excitation=Excitation(mean=0.0, amplitudes=(0.1,)))
    base.update(kw)
    return Model(**base)


def test_zero_damping_is_a_valid_model_but_not_analysable() -> None:
    model = _model(damping=0.0)
    assert model.damping == 0.0 and model.zeta == 0.0
    with pytest.raises(ValueError, match=r"`model.damping` must be > 0 for an analysis"):
        check_analysable_model(model)
    assert check_analysable_model(_model(damping=1e-6)).damping == 1e-6


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"inertia": 1e-45, "stiffness": 1e-45, "damping": 5e-47}, None),  # tiny numbers, K/I = 1: fine
        ({"stiffness": 1e51}, r"`stiffness` must have magnitude <= 1e\+50"),
        ({"inertia": 1e-30, "stiffness": 1e30}, r"`stiffness` / `inertia` give K/I = 1e\+60"),
        ({"inertia": 1e30, "damping": 1e-30}, r"`damping` / `inertia` give C/I = 1e-60"),
        ({"excitation": Excitation(mean=1e-60, amplitudes=(0.0,))}, r"force scale"),
        ({"stiffness": 1e-40, "excitation": Excitation(mean=1e20, amplitudes=(0.0,))}, r"deflection scale"),
    ],
)
def test_derived_scales_are_bounded(kwargs, match) -> None:
    if match is None:
        assert _model(**kwargs).k == pytest.approx(1.0)
        return
    with pytest.raises(ValueError, match=match):
        _model(**kwargs)


def test_zero_forcing_and_zero_damping_scales_are_allowed() -> None:
    _model(damping=0.0, excitation=Excitation(mean=0.0, amplitudes=(0.0,)))


def test_bounds_hold_at_the_limit() -> None:
    m = _model(inertia=1e25, stiffness=2e-25, damping=1e-24, excitation=Excitation(mean=0.0, amplitudes=(1e-45,)))
    assert m.k == pytest.approx(2e-50)  # near the bound: accepted
    assert _limits.check_magnitude(np.float64(1e50), "x") == 1e50
    with pytest.raises(ValueError, match=r"`x` must have magnitude"):
        _limits.check_magnitude(-1.0001e50, "x")


def test_clearance_threshold_is_pi_over_two() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Backlash(b=math.pi / 2)
    with pytest.warns(UserWarning, match=r"`b` = 1.6 rad is 92°"):
        Clutch(alpha=0.5, b=1.6)


def _long_chain(n: int, harmonics: int) -> dict:
    """A free chain of n inertias (n − 1 coordinates) with a clutch at one end, as a parsed file."""
    return {"model": {"inertias": [1.0] + [0.5] * (n - 1),
                      "links": [{"between": [i, i + 1], "damping": 0.05, **({"stiffness": 20.0} if i > 1 else {})}
                                for i in range(1, n)],
                      "elements": [{"name": "clutch", "between": [1, 2], "stiffness": 1.0, "type": "clutch",
                                    "alpha": 0.25, "b": 0.1}]},
            "excitation": {"torques": [{"inertia": 1, "mean": 0.05, "amplitudes": [0.03]},
                                       {"inertia": n, "mean": -0.05}]},
            "analysis": {"omega": [0.3, 2.0], "harmonics": harmonics}}


def test_a_chains_coordinates_share_the_effective_harmonics() -> None:
    """n·p·H ≤ 512: one or two coordinates keep H ≤ 256; a free chain of 60 inertias (59
    coordinates) gets H ≤ 8, refused up-front naming the key and the limit (file, API, CLI exit 2)."""
    import rattle
    from rattle.errors import ConfigError
    from rattle.io import config_from_dict

    assert [_limits.max_harmonics_for(n) for n in (1, 2, 3, 30, 59)] == [256, 256, 170, 17, 8]
    assert _limits.max_harmonics_for(30, period=2) == 8
    assert config_from_dict(_long_chain(60, 8)).analysis.harmonics == 8
    with pytest.raises(ConfigError, match=r"`analysis.harmonics` must be <= 8 for a system of 59 coordinates"):
        config_from_dict(_long_chain(60, 9))
    model = config_from_dict(_long_chain(60, 8)).model
    with pytest.raises(ValueError, match=r"`harmonics` must be <= 8 for a system of 59 coordinates .*, got 32"):
        rattle.frequency_response(model, omega=(0.3, 2.0), harmonics=32)


def test_a_too_long_chain_for_its_harmonics_exits_2_writing_nothing(tmp_path) -> None:
    from click.testing import CliRunner

    from rattle.cli.main import cli
    from rattle.io import dumps_toml

    (tmp_path / "chain.toml").write_text(dumps_toml(_long_chain(60, 16)), encoding="utf-8")
    try:
        runner = CliRunner(mix_stderr=False)  # type: ignore[call-arg]
    except TypeError:
        runner = CliRunner()
    result = runner.invoke(cli, ["frf", str(tmp_path / "chain.toml"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2, result.stderr
    assert "`analysis.harmonics` must be <= 8" in result.stderr and not (tmp_path / "out").exists()
