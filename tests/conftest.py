"""Shared fixtures: non-interactive matplotlib, seeded random numbers, reference models."""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

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
