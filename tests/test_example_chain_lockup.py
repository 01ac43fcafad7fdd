"""examples/chain_lockup_clutch.toml: a three-inertia chain with a torque-converter lock-up clutch
(a preload element with a little friction) and a gear with backlash parses into a System with its elements' whole laws,
and on the first part of its range what its header states holds: the clutch slips, then locks a
quarter of the period with a deflection of the order of 1e-3 rad, rows matched by the exact orbit,
the gear's HB rms on the exact one (the library call of the header, the ladder at the example's H).

The run test overrides the file's range (2.0-2.6 rad/s, about 4.5 minutes on one core: the
regularised branch folds twice where the lock sets in, and every locked row is checked at the
limit of its regularisation) with its first part, 2.0-2.1 (about 25 s): the same rows as the
file's run up to 2.1, the slip, the onset of the lock and the first locked row; everything else
is the file's."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rattle.io import load_config
from rattle.model import Backlash, Preload
from test_examples import EXAMPLES  # tests/ is on sys.path through its conftest

NAME = "chain_lockup_clutch.toml"
SUB_RANGE = (2.0, 2.1)  # the first part of the file's range, where the lock sets in (see the docstring)


def test_the_example_is_a_chain_with_a_preloaded_clutch_and_a_gear():
    cfg = load_config(EXAMPLES / NAME)
    fs = cfg.model
    assert fs.discontinuous and cfg.chain_friction and fs.has_jumps
    assert fs.element_names == ("tcc", "gear")
    tcc, gear = fs.laws
    assert isinstance(tcc.elastic, Preload) and tcc.elastic.preload == 0.03 and tcc.elastic.clearance == 0.0
    assert tcc.friction is not None and tcc.friction.levels == (0.01,)
    assert isinstance(gear.elastic, Backlash) and gear.elastic.b == 0.02 and gear.friction is None
    assert (cfg.analysis.harmonics, cfg.analysis.regularisation, cfg.analysis.refine) == (64, 0.01, 0.0)
    assert cfg.model.frequency_scale() == pytest.approx(3.0754, abs=1e-4)  # "omega_n = 3.0754"


@pytest.mark.slow
def test_the_example_slips_then_locks_as_stated():
    from rattle.analysis._friction_response import friction_response
    from rattle.analysis._case import regularisation_options

    cfg = load_config(EXAMPLES / NAME)
    assert cfg.analysis.omega == (2.0, 2.6)  # the header's range; the run below takes its first part
    analysis = dataclasses.replace(cfg.analysis, omega_min=SUB_RANGE[0], omega_max=SUB_RANGE[1])
    H = analysis.harmonics
    opts = regularisation_options(analysis)  # what `rattle frf` runs with: the file's settings, but the range
    assert (opts.harmonics, opts.limit_harmonics, opts.refine) == (H, H, None)  # a chain's ladder keeps its H
    r = friction_response(cfg.model, analysis.omega, opts)
    assert r.status.success and len(r) >= 6 and np.sum(r.matched) >= 4
    assert r.omega[0] == SUB_RANGE[0] and r.omega[-1] == pytest.approx(SUB_RANGE[1])
    m = r.matched
    stick = np.nan_to_num(r.stick_fraction[:, 0])
    slipping, locked = m & (stick == 0.0), m & (stick > 0.0)
    assert np.all(np.isnan(r.stick_fraction[~m, 0]))  # an unmatched row has no exact orbit to lock
    # "the rows 2.066 and 2.083 just before, where the lock sets in, and the last row 2.100 are not
    # matched": none amid the slip, at least one between the last slipping and the first locked row
    unmatched = r.omega[~m]
    assert 1 <= unmatched.size <= 4 and np.all(unmatched > r.omega[slipping].max())
    assert np.any(unmatched < r.omega[locked].min())
    # "slips (no lock) up to 2.049": the clutch twist's rms falls from 0.0093 towards the lock
    assert np.sum(slipping) >= 3 and np.all(r.omega[slipping] < 2.06)
    assert np.all(np.diff(r.rms[slipping, 0]) < 0) and 0.007 < r.rms[slipping, 0].min() < r.rms[slipping, 0].max() < 0.011
    # "locked 27 % of the period at 2.099, its exact rms 0.0012 rad, mean 0.0008 rad"
    assert np.any(locked)
    i = np.flatnonzero(locked)[0]
    # the first locked row: 2.083 (26.6 %) since the width ladder runs on the stepper (2.099, 26.7 %,
    # before, when the ladder at 2.083 did not match); either way past the onset row 2.066
    assert r.omega[i] > 2.07 and 0.25 < stick[i] < 0.30
    assert r.rms[i, 0] < 0.002 and abs(r.mean[i, 0]) < 0.002
    assert r.rms_hb[i, 0] > 3.0 * r.rms[i, 0]  # the HB at eps resolves the lock only to its width
    assert r.bifurcation[i] == "grazing_sliding"
    # the gear: the HB rms within 1 % of the exact one on every matched row; the slipping clutch within 6 %
    np.testing.assert_allclose(r.rms_hb[m, 1], r.rms[m, 1], rtol=0.01)
    np.testing.assert_allclose(r.rms_hb[slipping, 0], r.rms[slipping, 0], rtol=0.06)
    assert not np.any(r.stable[m])  # "every row unstable"
