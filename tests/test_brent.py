"""Brent's root finder of the root package (rattle._brent) against scipy.optimize.brentq: the same
step rules, so the same iterates to the last bit — and the failures in the same places."""

from __future__ import annotations

import math
import signal
import sys

import numpy as np
import pytest
import scipy.optimize

from rattle._brent import BracketError, NoConvergence, brent_root
from rattle._lazy import import_held, lazy_module


def _cases(rng: np.random.Generator) -> list:
    cs = rng.uniform(-1.0, 1.0, 40)
    return ([lambda x, c=c: math.tanh(x - c) * 3 + 0.1 * (x - c) ** 3 for c in cs]
            + [lambda x, c=c: (x - c) ** 3 for c in cs]
            + [lambda x, c=c: math.exp(x) - 1 - 0.5 * c for c in cs]
            + [lambda x, c=c: math.copysign(abs(x - c) ** 0.3, x - c) for c in cs])  # steep: some fail in 100 steps


def test_the_same_roots_as_scipy_to_the_last_bit() -> None:
    rng = np.random.default_rng(7)
    failures = 0
    for f in _cases(rng):
        for xtol in (1e-12, 1e-6, 1e-3):
            try:
                expected: float | str = scipy.optimize.brentq(f, -1.3, 1.7, xtol=xtol)
            except RuntimeError:
                expected = "no convergence"
            try:
                got: float | str = brent_root(f, -1.3, 1.7, xtol=xtol)
            except NoConvergence:
                got = "no convergence"
            assert got == expected
            failures += expected == "no convergence"
    assert 0 < failures < 160  # both kinds of outcome were compared


def test_given_end_values_are_not_evaluated_again() -> None:
    calls: list[float] = []

    def f(x: float) -> float:
        calls.append(x)
        return x * x - 2.0

    root = brent_root(f, 0.0, 2.0, fa=-2.0, fb=2.0, xtol=1e-14)
    assert abs(root - math.sqrt(2.0)) < 1e-13 and 0.0 not in calls and 2.0 not in calls


def test_bad_brackets_and_tolerances_are_refused() -> None:
    with pytest.raises(BracketError, match="same sign"):
        brent_root(lambda x: x * x + 1.0, -1.0, 1.0)
    with pytest.raises(ValueError, match="xtol"):
        brent_root(lambda x: x, -1.0, 1.0, xtol=0.0)
    with pytest.raises(ValueError, match="rtol"):
        brent_root(lambda x: x, -1.0, 1.0, rtol=1e-17)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="no signal masks on this platform")
def test_a_lazy_module_is_imported_on_first_use_with_the_signals_held(monkeypatch: pytest.MonkeyPatch) -> None:
    """The mask in force while the module is imported holds SIGINT/SIGTERM/SIGHUP, and is the old
    one again afterwards."""
    seen: list[set] = []
    real = __import__("importlib").import_module

    def spy(name: str, package: str | None = None):  # type: ignore[no-untyped-def]
        seen.append(signal.pthread_sigmask(signal.SIG_BLOCK, set()))
        return real(name, package)

    monkeypatch.setattr("rattle._lazy.importlib.import_module", spy)
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    before = signal.pthread_sigmask(signal.SIG_BLOCK, set())
    proxy = lazy_module("colorsys")
    assert seen == []  # nothing imported yet
    assert proxy.rgb_to_hsv(1.0, 0.0, 0.0)[0] == 0.0
    assert seen and {signal.SIGINT, signal.SIGTERM, signal.SIGHUP} <= set(seen[0])
    assert signal.pthread_sigmask(signal.SIG_BLOCK, set()) == before
    assert import_held("colorsys") is sys.modules["colorsys"]
