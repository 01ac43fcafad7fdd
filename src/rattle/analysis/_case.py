"""A case file read whole (model and ``[analysis]``), with the front ends run on its settings.

``rattle.load_case(path)`` is what the command line does with a file, from Python: the file's
frequency range and harmonic count go to the front ends unless given explicitly. It lives here,
above ``io`` (which reads the file) and beside the front ends it calls, so that ``io`` imports
no analysis.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from ..io import AnalysisSettings, RunConfig, load_config
from ..model import Model, System
from ._compare import compare
from ._frequency_response import frequency_response
from ._exact_branch import ShootingOptions
from ._nonsmooth import RegularisationOptions
from ._nonsmooth_orbit import nonsmooth_orbit
from ._orbit import periodic_orbit
from ._time_sweep import time_sweep


def regularisation_options(analysis: AnalysisSettings) -> RegularisationOptions:
    """The :class:`RegularisationOptions` of a case file's ``[analysis]`` (``harmonics``,
    ``regularisation``, ``refine``: 0 none, ``limit_harmonics``: None the default,
    ``held_limit``: ``held``) for a
    discontinuous law: what ``rattle frf``, ``orbit`` and ``compare`` and :class:`Case` run with."""
    kw: dict = {} if analysis.limit_harmonics is None else {"limit_harmonics": analysis.limit_harmonics}
    if analysis.held_limit:
        kw["held"] = True
    return RegularisationOptions(harmonics=analysis.harmonics, regularisation=analysis.regularisation,
                                 refine=analysis.refine or None, **kw)


def method_options(analysis: AnalysisSettings) -> ShootingOptions | RegularisationOptions:
    """The method of a discontinuous law's ``[analysis] method`` (SPEC §8): ``"shooting"`` (the
    default) :class:`ShootingOptions`, ``"hb"`` :func:`regularisation_options`."""
    return regularisation_options(analysis) if analysis.method == "hb" else ShootingOptions()


def case_arguments(model: Any, analysis: AnalysisSettings, options: dict[str, Any] | None = None) -> dict[str, Any]:
    """The keywords of :func:`rattle.frequency_response` for ``model`` with a case file's
    ``[analysis]``: its range ``omega``, and for a continuous law its ``harmonics``, for a law with
    jumps or friction (``model.discontinuous``) its method (:func:`method_options`); ``options``
    (keywords given) override them."""
    options = dict(options or {})
    kw: dict[str, Any] = {"omega": analysis.omega}
    if getattr(model, "discontinuous", False):
        kw["options"] = method_options(analysis)
    elif "hb" not in options:  # the harmonic count given inside hb= replaces the file's
        kw["harmonics"] = analysis.harmonics
    return {**kw, **options}


@dataclass(frozen=True, slots=True)
class Case:
    """A validated case file: its ``config`` (:class:`~rattle.io.RunConfig`), with ``model``,
    ``analysis`` and ``source`` at hand, and the front ends on the file's settings."""

    config: RunConfig

    @property
    def model(self) -> Model | System:
        """The model: a :class:`~rattle.model.Model` (or chain), a
        single-equation :class:`~rattle.model.System` when the law has a preload or friction, or a
        :class:`~rattle.model.System` with its elements' whole laws for a chain with friction on its elements."""
        return self.config.model

    @property
    def discontinuous(self) -> bool:
        """True when the law has a jump or friction, or the chain friction on an element (the front
        ends of :mod:`._nonsmooth`)."""
        return self.config.discontinuous

    def regularisation_options(self) -> RegularisationOptions:
        """The file's ``harmonics``, ``regularisation``, ``refine`` and ``limit_harmonics`` for a
        discontinuous law (:func:`regularisation_options`)."""
        return regularisation_options(self.analysis)

    @property
    def analysis(self) -> AnalysisSettings:
        return self.config.analysis

    @property
    def source(self) -> dict[str, Any]:
        return self.config.source

    def frequency_response(self, **options: Any) -> Any:
        """:func:`rattle.frequency_response` of this case over the file's ``analysis.omega`` with
        its ``analysis.harmonics`` — what ``rattle frf CONFIG`` computes. Keyword ``options``
        (``subharmonics=True``, ``omega=…``, ``hb=HBOptions(…)``, ``newton=…``, …) are passed on
        and override the file; an unknown keyword raises TypeError.

        For a discontinuous law, or a chain with friction on its elements, the file's method
        (:func:`method_options`: ``[analysis] method``) instead of its harmonics (keywords
        ``omega``, ``options``, ``continuation``, ``newton``, ``subharmonics``, ``throw``,
        ``progress`` override)."""
        return frequency_response(self.model, **case_arguments(self.model, self.analysis, options))

    def periodic_orbit(self, omega: float, **options: Any) -> Any:
        """:func:`rattle.periodic_orbit` at ``omega`` with the file's harmonics, the primary branch
        followed over ``analysis.omega`` (as ``rattle orbit CONFIG --omega W``); for a
        discontinuous law, or a chain with friction or preloads on its elements,
        :func:`rattle.analysis.nonsmooth_orbit` with :meth:`regularisation_options`."""
        if self.discontinuous:
            kw: dict[str, Any] = {"options": self.regularisation_options(), **options}
            return nonsmooth_orbit(self.model, omega, **kw)  # type: ignore[arg-type]
        return periodic_orbit(self.model, omega, **self._with_analysis(options, "search_range"))

    def compare(self, **options: Any) -> Any:
        """:func:`rattle.compare` over the file's range with its harmonics (as ``rattle compare``);
        for a discontinuous law with :meth:`regularisation_options` (its response beside the exact
        sweep)."""
        if self.discontinuous:
            kw: dict[str, Any] = {"omega": self.analysis.omega, "regularisation": self.regularisation_options(),
                                  **options}
            return compare(self.model, **kw)  # type: ignore[arg-type]
        return compare(self.model, **self._with_analysis(options, "omega"))

    def time_sweep(self, **options: Any) -> Any:
        """:func:`rattle.time_sweep` over the file's range (as ``rattle sweep``; the exact
        event-driven flow for a discontinuous law)."""
        kw = {"omega": self.analysis.omega, **options}
        return time_sweep(self.model, **kw)

    def _with_analysis(self, options: dict[str, Any], range_name: str) -> dict[str, Any]:
        kw: dict[str, Any] = {range_name: self.analysis.omega}
        if "hb" not in options:  # the harmonic count given inside hb= replaces the file's
            kw["harmonics"] = self.analysis.harmonics
        kw.update(options)
        return kw


def load_case(path: str | os.PathLike[str]) -> Case:
    """Read a configuration file into its model *and* its ``[analysis]`` settings.

    ``rattle.Model.from_toml(path)`` gives the model alone; ``load_case`` keeps the analysis too,
    so that the library computes what the command line does from the same file::

        case = rattle.load_case("case.toml")
        frf = case.frequency_response()          # = rattle frf case.toml
        frf = rattle.frequency_response(case.model, omega=case.analysis.omega,
                                        harmonics=case.analysis.harmonics)   # the same

    Raises ConfigError on a bad file (see :func:`rattle.io.load_config`).
    """
    return Case(load_config(path))


__all__ = ["Case", "load_case", "case_arguments", "method_options", "regularisation_options"]
