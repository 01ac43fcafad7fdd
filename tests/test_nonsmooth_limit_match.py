"""The single equation's check at the regularisation's limit (``nonsmooth_response``): where the
exact orbit shot from the regularised HB at ε departs from it and δ sticks part of the period,
the HB is taken down the ε ladder and the exact orbit shot from its state there is matched
against that HB orbit."""

from __future__ import annotations

import numpy as np
import pytest

import rattle.analysis._nonsmooth as ns
from rattle.analysis import RegularisationOptions
from rattle.analysis._nonsmooth import nonsmooth_response
from rattle.model import Excitation, Friction, NonsmoothLaw, Preload, System

OPTIONS = RegularisationOptions(harmonics=128, regularisation=0.01, refine=0.005)
OMEGA = (0.525, 0.53)


def _heavy() -> System:
    """A heavy preload with Coulomb friction (T_p = 0.2, r = 0.05, c = 0.05, k = 1,
    F = 0.01 + 0.3 cos(Ωt + 0.3)): near Ω = 0.53 δ sticks ~5 % of the period and the HB at
    ε = 0.01 misses the exact rms by ~13 %."""
    law = NonsmoothLaw(elastic=Preload(preload=0.2), friction=Friction(levels=0.05))
    return System.single(damping=0.05, stiffness=1.0, law=law,
                           excitation=Excitation(mean=0.01, amplitudes=(0.3,), phases=(0.3,)))


def test_a_sticking_row_the_plain_check_misses_is_matched_at_the_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    system = _heavy()
    checked: list[tuple[float, float | None]] = []
    at_limit = ns._match_at_limit

    def recording(*args, **kwargs):  # type: ignore[no-untyped-def]
        found = at_limit(*args, **kwargs)
        checked.append((float(args[3]), None if found is None else found[1]))
        return found

    monkeypatch.setattr(ns, "_match_at_limit", recording)
    res = nonsmooth_response(system, OMEGA, OPTIONS)
    assert len(res) >= 2 and np.all(res.matched)
    # every row went to the limit (the plain check failed there) and matched well inside `match`
    assert sorted(w for w, _ in checked) == pytest.approx(sorted(res.omega))
    assert all(d is not None and d <= 0.05 for _, d in checked)
    # the exact orbit sticks part of the period; the HB at ε is far off, the HB at its limit is not
    frac = res.stick_time * res.omega / (2 * np.pi)
    assert np.all((frac > 0.02) & (frac < 0.2))
    assert np.all(np.abs(res.rms_error) > 0.05)
    assert np.array_equal(np.sort(res.limit_index), np.arange(len(res)))  # refined, on the ladder already found
    assert np.all(np.abs(res.hb_error) < 0.01)
    assert np.all(res.stable)

    # without the check at the limit the same rows are unmatched: the exact orbit from the HB at ε departs
    monkeypatch.setattr(ns, "_match_at_limit", lambda *args, **kwargs: None)
    plain = nonsmooth_response(system, OMEGA, OPTIONS)
    np.testing.assert_array_equal(plain.omega, res.omega)
    assert not np.any(plain.matched)
    np.testing.assert_array_equal(plain.rms_hb, res.rms_hb)
    assert np.all(np.isnan(plain.rms)) and plain.limit_index.size == 0


def test_rows_the_plain_check_matches_are_not_taken_to_the_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    """A law whose rows all match plainly (friction without a held lock-up near Ω = 1.2): the limit
    check is never run, so those rows are the plain check's."""
    law = NonsmoothLaw(elastic=Preload(preload=0.05), friction=Friction(levels=0.02))
    system = System.single(damping=0.05, stiffness=1.0, law=law,
                             excitation=Excitation(mean=0.01, amplitudes=(0.3,), phases=(0.3,)))

    def never(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("a plainly matched row was taken to the limit")

    monkeypatch.setattr(ns, "_match_at_limit", never)
    res = nonsmooth_response(system, (1.2, 1.21), OPTIONS)
    assert len(res) >= 2 and np.all(res.matched)
