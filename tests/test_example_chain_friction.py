"""examples/chain_clutch_friction.toml: a chain with friction per stage on its clutch damper parses
into a and on a part of its range the stability changes and the stick it states
hold (at its own harmonics and regularisation), as tests/test_examples.py does for the single
equation's discontinuous examples."""

from __future__ import annotations

import numpy as np
import pytest

from rattle.io import load_config
from test_examples import EXAMPLES, _stated_changes  # tests/ is on sys.path through its conftest

NAME = "chain_clutch_friction.toml"


def test_the_example_is_a_chain_with_friction_per_stage():
    cfg = load_config(EXAMPLES / NAME)
    assert cfg.model.discontinuous and cfg.chain_friction
    np.testing.assert_array_equal(cfg.model.friction_levels(0), [0.004, 0.002, 0.001, 0.002, 0.004])
    assert (cfg.analysis.harmonics, cfg.analysis.regularisation, cfg.analysis.refine) == (32, 0.001, 0.005)
    # "twisting the damper to 0.09 rad at rest": f(0.09) = 0.08·0.05 + 0.4·0.04 = 0.02, the mean torque
    law = cfg.model.continuous().elements[0].law
    assert float(law.force(np.array([0.09]))[0]) == pytest.approx(0.02, abs=1e-15)


def test_the_example_as_stated_on_its_period_doubling_range():
    from rattle.analysis import RegularisationOptions
    from rattle.analysis._nonsmooth import nonsmooth_response

    cfg = load_config(EXAMPLES / NAME)
    omega = (0.4, 0.5)
    result = nonsmooth_response(cfg.model, omega, RegularisationOptions(harmonics=cfg.analysis.harmonics,
                                                                        regularisation=cfg.analysis.regularisation,
                                                                        refine=None))
    assert result.status.success and np.all(result.matched)
    labels = result.bifurcation
    found = sorted((str(labels[i]), float(result.omega[i])) for i in range(len(result))
                   if labels[i] in ("fold", "period_doubling", "neimark_sacker"))  # not the grazings
    stated = sorted((k, lo, hi) for k, lo, hi in _stated_changes(EXAMPLES / NAME) if omega[0] <= lo and hi < omega[1])
    assert [k for k, _ in found] == [k for k, _, _ in stated] == ["period_doubling"] * 4, (found, stated)
    for (_, w), (_, lo, hi) in zip(sorted(found, key=lambda x: x[1]), sorted(stated, key=lambda x: x[1])):
        assert lo - 2e-3 <= w <= hi + 2e-3, (w, lo, hi)
    stick = np.nan_to_num(result.stick_fraction[:, 0])
    assert np.all(stick > 0.02)  # "2-5 % of the period over Omega = 0.40-0.50 (most, 4.7 %, at 0.472)"
    assert np.max(stick) == pytest.approx(0.047, abs=0.002) and 0.47 < result.omega[np.argmax(stick)] < 0.475
    err = np.abs(result.rms_error)
    assert np.max(err) < 0.006 and np.mean(err <= 0.005) > 0.95  # "within 0.5 % … (the first row: 0.525 %)"
