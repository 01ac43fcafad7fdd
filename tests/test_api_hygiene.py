"""The public surface: curated exports, documented, no keyword sinks."""

from __future__ import annotations

import inspect

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
