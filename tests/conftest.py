"""Shared fixtures: non-interactive matplotlib, seeded random numbers, reference models."""

from __future__ import annotations

import os
import sys
from pathlib import Path

# One BLAS thread per process, set before numpy loads: the suite's matrices are small (a few
# hundred rows at most), where threads buy nothing, and the tests that run worker processes
# would otherwise oversubscribe the two cores (a 196×196 eigenproblem took 4 s instead of 0.02 s
# on a loaded machine). A value the user set is kept.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# Ctrl-C as an interactive shell delivers it: a suite started in the background by a shell
# without job control (`bash .ci/run &` in a script) inherits SIGINT *ignored*, and so would
# every process the signal tests start — their SIGINT would never arrive. A Python handler here
# is reset to the default in every child at exec, where Python installs KeyboardInterrupt again.
import signal

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

import matplotlib
import numpy as np
import pytest
from hypothesis import settings as _hypothesis_settings

matplotlib.use("Agg")

# Property tests draw the same examples on every run (a CI run must not fail on a draw a local
# run never made); run with HYPOTHESIS_PROFILE=explore to draw new ones (and record failures).
_hypothesis_settings.register_profile("ci", derandomize=True, deadline=None)
_hypothesis_settings.register_profile("explore", deadline=None)
_hypothesis_settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The command-line tests' shared helpers (tests/cli/_cli_helpers.py) are importable from every
# test module, as tests/_cases.py is (pytest puts this folder on sys.path for its conftest).
sys.path.insert(0, str(Path(__file__).resolve().parent / "cli"))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def reference_model():
    from rattle.model import reference_case

    return reference_case()


@pytest.fixture(scope="session")
def reference_frf(reference_model):
    """The reference case's frequency response, computed once per test session."""
    from rattle import frequency_response

    return frequency_response(reference_model, omega=(0.1, 3.0), harmonics=32)


@pytest.fixture(scope="session")
def reference_frf_all(reference_model):
    """The reference case with its period-doubled branches, computed once per test session."""
    from rattle import frequency_response

    return frequency_response(reference_model, omega=(0.1, 3.0), harmonics=32, subharmonics=True)
