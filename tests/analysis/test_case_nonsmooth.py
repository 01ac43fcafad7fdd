"""A case file with a preload or friction from Python: load_case dispatches to the front ends of the
discontinuous laws with the file's settings (response, orbit, sweep, comparison), and
Model.from_toml refuses it clearly."""

from __future__ import annotations

import numpy as np
import pytest

import rattle
from rattle.errors import ConfigError
from rattle.results import FrequencyResponse, NonsmoothCheck, NonsmoothOrbitResult

CASE = """
[model]
inertia = 1.0
damping = 0.05
stiffness = 1.0
[model.elastic]
type = "preload"
preload = 0.05
friction = 0.02
[excitation]
mean = 0.01
amplitudes = [0.3]
phases = [0.3]
[analysis]
omega = [1.2, 1.23]
harmonics = 32
regularisation = 0.02
refine = 0
method = "hb"
"""


def test_load_case_runs_the_discontinuous_front_ends_on_the_file_settings(tmp_path) -> None:
    path = tmp_path / "case.toml"
    path.write_text(CASE)
    case = rattle.load_case(path)
    assert case.discontinuous and case.model.is_single_equation
    opts = case.regularisation_options()
    assert (opts.harmonics, opts.regularisation, opts.refine) == (32, 0.02, None)
    frf = case.frequency_response()
    assert isinstance(frf, FrequencyResponse) and isinstance(frf.check, NonsmoothCheck)
    assert frf.check.harmonics == 32 and frf.check.regularisation == 0.02
    assert frf.omega[0] == 1.2 and frf.omega[-1] == pytest.approx(1.23) and frf.check.limit_index.size == 0
    orbit = case.periodic_orbit(1.21)
    assert isinstance(orbit, NonsmoothOrbitResult) and orbit.converged
    i = int(np.argmin(np.abs(frf.omega - 1.21)))
    assert orbit.rms == pytest.approx(frf.rms[i], rel=0.05)  # the same branch, a row nearby
    sweep = case.time_sweep(points=4, direction="up")  # the exact event-driven sweep over the file's range
    assert sweep.omega[0] == pytest.approx(1.2) and sweep.omega[-1] == pytest.approx(1.23)
    held = np.asarray(sweep.extra_columns["stick_fraction"])
    assert held.shape == (4,) and np.all((held >= 0) & (held <= 1))
    both = case.compare(points=4)
    assert both.frf.check.harmonics == 32 and both.frf.check.regularisation == 0.02 and len(both.sweep.omega) == 8
    with pytest.raises(ConfigError, match="load_case"):
        rattle.Model.from_toml(path)
