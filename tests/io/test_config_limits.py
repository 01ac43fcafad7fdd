"""The configuration's model-dependent rules (check_analysis) with the names the values came from."""

from __future__ import annotations

import dataclasses
import sys

import pytest

from rattle.errors import ConfigError
from rattle.io import config_from_dict
from rattle.io._config import check_analysis

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

TEXT = """
[model]
inertia = 1.0
damping = 0.05
stiffness = 4.0
[model.elastic]
type = "backlash"
b = 0.1
[excitation]
mean = 0.05
amplitudes = [0.03]
[analysis]
omega = [0.1, 3.0]
harmonics = 16
"""


def test_bounds_scale_with_the_stiffest_stage() -> None:
    config = config_from_dict(tomllib.loads(TEXT))  # ω_s = sqrt(4) = 2 rad/s
    low = dataclasses.replace(config.analysis, omega_min=0.0019)
    with pytest.raises(ConfigError, match=r"`analysis.omega\.1` must be >= 0.002 rad/s .* 2 rad/s\), got 0.0019"):
        check_analysis(config.model, low)
    with pytest.raises(ConfigError, match=r"`--omega-min` must be >= 0.002"):
        check_analysis(config.model, low, {"omega_min": "--omega-min"})
    high = dataclasses.replace(config.analysis, omega_max=2001.0)
    with pytest.raises(ConfigError, match=r"`--omega-max` must be <= 2000 rad/s"):
        check_analysis(config.model, high, {"omega_max": "--omega-max"})
    check_analysis(config.model, dataclasses.replace(config.analysis, omega_min=0.002, omega_max=2000.0))


def test_zero_damping_names_the_key() -> None:
    with pytest.raises(ConfigError, match=r"^<dict>: `model.damping` must be > 0 for an analysis, got 0.0"):
        config_from_dict(tomllib.loads(TEXT.replace("damping = 0.05", "damping = 0")))
