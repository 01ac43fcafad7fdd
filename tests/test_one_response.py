"""One frequency response for every law (issue 23, item 4).

Counted on the source (AST): one frequency-response result class in ``rattle.results`` (beside the
closed-form ``LinearResponse``) and one public ``*_response`` front end over Ω in
``rattle.analysis.__all__``; then what the one front end does with a law with jumps or friction.
"""

from __future__ import annotations

import ast
import dataclasses
import tempfile
from pathlib import Path

import numpy as np
import pytest
from _cases import preload_spring_toml  # tests/ is on sys.path through its conftest

import rattle
from rattle.analysis import RegularisationOptions, ShootingOptions, frequency_response
from rattle.errors import Status
from rattle.results import FrequencyResponse, NonsmoothCheck

SRC = Path(__file__).resolve().parents[1] / "src" / "rattle"


def _all(path: Path) -> list[str]:
    """The names of the module's ``__all__`` list, read from its source."""
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            return [ast.literal_eval(e) for e in node.value.elts]  # type: ignore[attr-defined]
    raise AssertionError(f"{path} has no __all__")


def test_one_frequency_response_result_class() -> None:
    defined = {node.name for f in (SRC / "results").glob("*.py")
               for node in ast.walk(ast.parse(f.read_text(encoding="utf-8")))
               if isinstance(node, ast.ClassDef) and node.name.endswith("Response")}
    assert defined == {"FrequencyResponse", "LinearResponse"}
    exported = [n for n in _all(SRC / "results" / "__init__.py") if n.endswith("Response")]
    assert sorted(exported) == ["FrequencyResponse", "LinearResponse"]


def test_one_response_front_end_over_omega() -> None:
    assert [n for n in _all(SRC / "analysis" / "__init__.py") if n.endswith("_response")] == ["frequency_response"]
    top = [n for n in _all(SRC / "__init__.py") if n.endswith("_response")]
    assert sorted(top) == ["frequency_response", "linear_frequency_response"]  # the closed-form linear one aside


def test_the_command_line_has_no_law_branch_in_frf() -> None:
    """``rattle frf`` is one path: no discontinuous-law test in the command line's frf code and no
    summary or metadata of a law there (the result writes and summarises itself)."""
    source = (SRC / "cli" / "commands.py").read_text(encoding="utf-8")
    functions = {node.name: "\n".join(ast.unparse(stmt) for stmt in node.body if not (  # the code, not its docstring
                     isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant)))
                 for node in ast.parse(source).body if isinstance(node, ast.FunctionDef)}
    for name in ("compute_frf", "run_frf", "frf_command"):
        code = functions[name]
        assert "discontinuous" not in code and "nonsmooth" not in code and "friction" not in code, name
    output = (SRC / "cli" / "output.py").read_text(encoding="utf-8")
    assert "nonsmooth" not in output and "friction" not in output


def _preload(omega: tuple[float, float]) -> rattle.System:
    from rattle.io import load_config

    path = Path(tempfile.mkdtemp()) / "case.toml"
    path.write_text(preload_spring_toml(omega, 32, friction=None), encoding="utf-8")
    return load_config(path).model


def test_a_law_with_jumps_is_shot_exactly_by_default() -> None:
    """The preloaded spring over Ω = 1.2 … 1.21 (no fold there): the default method is exact shooting
    continuation; the SPEC columns are the exact orbits' (rms_ac² + mean² = rms², as measured), the
    exact-check group rides along, the file is its columns."""
    system = _preload((1.2, 1.21))
    frf = frequency_response(system, (1.2, 1.21))
    assert isinstance(frf, FrequencyResponse) and isinstance(frf.check, NonsmoothCheck)
    assert frf.check.followed == "exact shooting" and frf.status.success and len(frf) >= 2
    np.testing.assert_array_equal(frf.rms, frf.check.rms)
    np.testing.assert_allclose(frf.check.stick_fraction, frf.check.stick_time * frf.omega / (2 * np.pi), rtol=1e-15)
    np.testing.assert_allclose(frf.rms_ac**2 + frf.mean**2, frf.rms**2, rtol=1e-12)
    assert np.all(frf.branch == 0) and np.all(frf.period == 1) and frf.coefficients.shape == (len(frf), 0)
    assert frf.settings["method"].startswith("exact shooting") and frf.settings["subharmonics"] is False
    assert "exact shooting continuation" in frf.summary() and frf.metadata()["points"] == len(frf)
    buffer = Path(tempfile.mkdtemp()) / "frf.csv"
    header = frf.to_csv(buffer).read_text(encoding="utf-8").splitlines()[0].split(",")
    assert header == frf.check.column_names() and "stick_time" in header
    with pytest.raises(ValueError, match="no Fourier coefficients"):
        frf.time_history(0)
    with pytest.raises(ValueError, match="a law with jumps or friction has none"):
        frf.linear_response()
    assert "exact shooting" in repr(frf)
    assert frf.select(0).check is not None and len(frf.select(0)) == len(frf)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = frf.plot()  # the panels follow from the columns: the exact-check group's
    assert set(axes) == {"rms", "stick"}
    plt.close(fig)
    with pytest.raises(TypeError, match="leave them at their defaults"):
        frf.plot(quantity="p2p")


def test_the_harmonic_balance_arguments_are_refused_for_a_law_with_jumps() -> None:
    system = _preload((1.2, 1.21))
    with pytest.raises(TypeError, match="`harmonics`, `start` must be left at the default"):
        frequency_response(system, (1.2, 1.21), 64, start="high")
    with pytest.raises(TypeError, match="`options` must be None, a ShootingOptions"):
        frequency_response(system, (1.2, 1.21), options=rattle.HBOptions(harmonics=8))
    with pytest.raises(TypeError, match="`options` chooses the method of a law with jumps or friction"):
        frequency_response(rattle.reference_case(), (0.5, 0.6), options=ShootingOptions())


def test_sub_harmonic_branches_are_rows_with_their_branch_and_period() -> None:
    """A hand-made check group with one period-2 branch: its rows follow the primary's in every
    column, numbered by ``branch`` and ``period``; a located period doubling is a special point."""
    def group(w: np.ndarray, period: int, branch: int, labels: list[str]) -> NonsmoothCheck:
        n = w.size
        mu = np.tile([0.5 + 0j, 0.1 + 0j], (n, 1))
        return NonsmoothCheck(
            omega=w, rms_hb=np.full(n, np.nan), mean=np.zeros(n), rms=np.linspace(0.1, 0.2, n), rms_ac=np.zeros(n),
            p2p=np.ones(n), acc_p2p=np.ones(n), regime=np.full(n, "single_sided", dtype=object),
            stable=np.ones(n, dtype=bool), multipliers=mu, multipliers_hb=mu, stick_time=np.zeros(n),
            matched=np.ones(n, dtype=bool), status=Status.SUCCESS, message="", regularisation=np.nan, harmonics=0,
            limit_index=np.zeros(0, dtype=int), limit_eps=np.zeros(0), limit_rms=np.zeros(0),
            limit_richardson=np.zeros(0), limit_linear=np.zeros(0, dtype=bool), period=period, branch=branch,
            followed="exact shooting", labels=np.array(labels, dtype=object))

    sub = group(np.array([0.5, 0.55]), 2, 1, ["", ""])
    primary = group(np.array([0.4, 0.5, 0.6]), 1, 0, ["", "period_doubling", ""])
    check = dataclasses.replace(primary, branches=(sub,))
    frf = FrequencyResponse.from_check(check, model=None, settings={"subharmonics": True}, timings={})
    assert frf.branch.tolist() == [0, 0, 0, 1, 1] and frf.period.tolist() == [1, 1, 1, 2, 2]
    assert frf.omega.tolist() == [0.4, 0.5, 0.6, 0.5, 0.55]
    assert [(s.kind, s.index, s.located) for s in frf.special_points] == [("period_doubling", 1, True)]
    cols = frf.columns()
    assert cols["branch"].tolist() == frf.branch.tolist() and cols["period"].tolist() == frf.period.tolist()
    assert "branch 1 (period 2" in frf.summary()
    assert len(frf.select(1)) == 2 and frf.select(1).check.branch == 1


def test_rattle_exports_what_every_law_needs() -> None:
    for name in ("frequency_response", "FrequencyResponse", "ShootingOptions", "RegularisationOptions",
                 "System", "NonsmoothLaw", "Preload", "Friction", "Chain"):
        assert name in rattle.__all__
    assert isinstance(RegularisationOptions(), rattle.RegularisationOptions)
