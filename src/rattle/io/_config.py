"""Strict reading of the SPEC §2 configuration file into a :class:`RunConfig`.

A configuration file holds the model tables and the run's own tables::

    [model], [excitation], [engine], [drag]    the model: read by :func:`rattle.model.model_tables`
                                               (schema, units, angles in degrees, data-sheet shapes)
    [analysis]           omega                 [min, max] in rad/s, optional (default [0.1, 3.0])
                         harmonics             integer 1 … 256, optional (default 32)
                         regularisation        a discontinuous law's ε, optional (default 0.01; 0.001 for a
                                               chain with friction on its elements)
                         refine                a discontinuous law's refinement, optional (default 0.005)
                         method                a discontinuous law's method: "shooting" (exact shooting
                                               continuation, the default) or "hb" (the regularised
                                               harmonic balance checked by exact shooting)
                         limit_harmonics       the refinement's largest H, optional (default 256; a chain
                                               with friction or jumps on its elements: its harmonics)
    [[paths]]            the sound paths (SPEC §6, :mod:`._paths`)

This module reads the ``[analysis]`` table and joins it to the model: with an ``[engine]`` the
analysis range is Ω = base order · 2π/60 · rpm of ``engine.speed_rpm``.

Bounds shared with the library (:mod:`rattle._limits`, the reasons are in the messages): every
number finite with magnitude <= 1e50 (and K/I, C/I, the force and deflection scales too);
``model.damping`` > 0 (an undamped system has no stable periodic orbit to analyse);
``analysis.omega`` within 1e-3 … 1e3 times the stiffest stage's natural frequency; at most 256
entries per array. A clearance ``b`` (or breakpoint) above pi/2 rad is warned about (degrees by
mistake?), not refused.

The ``[analysis]`` table holds numerical settings, not physics, so it may be left out: the
defaults are the SPEC §2 example values and end up in the run metadata. Every physical
quantity is required; nothing physical is defaulted.

Every message names the key in backticks, shows the value received, states the rule and says
the fix.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from .. import _limits
from ..errors import ConfigError
from ..files import read_toml
from ..model import Model, Preload, check_analysable_model, forcing_frequency
from ..model import System, model_tables
from .._table_checks import (
    _EXAMPLES,
    _Checker,
    _example,
    _kind,
    _show,
    rename_keys,
)

__all__ = [
    "DEFAULT_HARMONICS",
    "DEFAULT_NONSMOOTH_HARMONICS",
    "DEFAULT_OMEGA",
    "DEFAULT_REGULARISATION",
    "AnalysisSettings",
    "RunConfig",
    "check_analysis",
    "check_harmonics",
    "config_from_dict",
    "dumps_toml",
    "load_config",
    "model_to_toml_dict",
    "rename_keys",
]


#: Default forcing-frequency range ``analysis.omega`` (rad/s): the SPEC §2 example.
DEFAULT_OMEGA: tuple[float, float] = (0.1, 3.0)
#: Default number of harmonics ``analysis.harmonics``: the SPEC §2 example.
DEFAULT_HARMONICS: int = 32
#: Defaults for a discontinuous law (a preload or friction: ``rattle.frequency_response``):
#: ``analysis.regularisation`` ε and ``analysis.harmonics`` (those of ``RegularisationOptions``).
DEFAULT_REGULARISATION: float = 0.01
#: ``analysis.regularisation`` for a chain with friction on its elements: its velocity width ε L ω_n
#: takes the chain's highest natural frequency, ~10× wider against an element's own twist rates than
#: on the single equation; 0.001 meets 0.5 % at ε away from special points (docs/nonsmooth.md).
DEFAULT_CHAIN_REGULARISATION: float = 0.001
#: ``analysis.refine``: the HB rms error (relative, against the exact orbit) above which a row's
#: regularisation is continued to its limit; 0 turns the refinement off.
DEFAULT_REFINE: float = 0.005
DEFAULT_NONSMOOTH_HARMONICS: int = 128

_T = TypeVar("_T")


# --------------------------------------------------------------------------------------------
# Settings and the parsed configuration
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True, kw_only=True)
class AnalysisSettings:
    """Frequency range and harmonic truncation of a frequency-response run.

    Parameters
    ----------
    omega_min, omega_max : float
        Forcing-frequency range Ω (rad/s), 0 < ``omega_min`` < ``omega_max``.
    harmonics : int
        Harmonics kept in the harmonic balance, >= 1.
    regularisation : float or None
        Relative width ε of the smooth steps that replace a discontinuous law's jumps and
        friction in the harmonic balance, 0 < ε < 1; None (the default) for a continuous law.
    refine : float or None
        For a discontinuous law: the relative HB rms error against the exact orbit above which a
        row's regularisation is continued to its limit (0: never); None for a continuous law.
    limit_harmonics : int or None
        For a discontinuous law: the most harmonics the regularisation's ladder may raise H to
        (at or below ``harmonics``: H is kept); None: the library's default (256).
    held_limit : bool or None
        For a chain with friction or torque jumps on its elements: narrow the steps of an element
        held part of the period to their limit (``RegularisationOptions(held=True)``); None
        otherwise.
    method : str or None
        For a discontinuous law (SPEC §8): ``"shooting"`` (exact shooting continuation, the
        default) or ``"hb"`` (the regularised harmonic balance, every row checked by exact
        shooting); None for a continuous law.
    """

    omega_min: float = DEFAULT_OMEGA[0]
    omega_max: float = DEFAULT_OMEGA[1]
    harmonics: int = DEFAULT_HARMONICS
    regularisation: float | None = None
    refine: float | None = None
    limit_harmonics: int | None = None
    held_limit: bool | None = None
    method: str | None = None

    def __post_init__(self) -> None:
        omega_min = _limits.check_magnitude(self.omega_min, "omega_min")
        omega_max = _limits.check_magnitude(self.omega_max, "omega_max")
        if omega_min <= 0:
            raise ValueError(
                f"`omega_min` must be > 0 rad/s (a forcing frequency), got {omega_min!r}; "
                "start the range at a small positive frequency such as 0.1"
            )
        if not omega_min < omega_max:
            raise ValueError(
                f"`omega_min` must be < `omega_max`, got `omega_min` = {omega_min!r} and "
                f"`omega_max` = {omega_max!r}: the frequency range is empty; "
                "give the lower frequency first and make the upper one larger"
            )
        # The same rule (and upper bound, from memory and time) as the library's `harmonics`.
        harmonics = _limits.check_harmonics(self.harmonics, "harmonics")
        if self.regularisation is not None:
            eps = _limits.check_magnitude(self.regularisation, "regularisation")
            if not 0.0 < eps < 1.0:
                raise ValueError(
                    f"`regularisation` (relative width ε of the smooth steps replacing the jumps and the friction) "
                    f"must satisfy 0 < ε < 1, got {eps!r}; use e.g. 0.01 (smaller is closer to the exact law and "
                    "needs more harmonics)"
                )
            object.__setattr__(self, "regularisation", eps)
        if self.refine is not None:
            tol = _limits.check_magnitude(self.refine, "refine")
            if not 0.0 <= tol < 1.0:
                raise ValueError(
                    f"`refine` (the relative HB rms error above which a row's regularisation is continued to its "
                    f"limit) must satisfy 0 <= refine < 1, got {tol!r}; use 0.005 (0.5 %), or 0 to turn it off"
                )
            object.__setattr__(self, "refine", tol)
        if self.method is not None and self.method not in METHODS:
            raise ValueError(f"`method` must be one of {', '.join(repr(m) for m in METHODS)}, got {self.method!r}")
        if self.limit_harmonics is not None:
            lim = _limits.check_harmonics(self.limit_harmonics, "limit_harmonics")
            object.__setattr__(self, "limit_harmonics", int(lim))
        object.__setattr__(self, "omega_min", omega_min)
        object.__setattr__(self, "omega_max", omega_max)
        object.__setattr__(self, "harmonics", int(harmonics))

    @property
    def omega(self) -> tuple[float, float]:
        """The range ``(omega_min, omega_max)`` in rad/s."""
        return (self.omega_min, self.omega_max)

    def to_dict(self) -> dict[str, Any]:
        """The ``[analysis]`` table: ``{"omega": [min, max], "harmonics": h}`` (and ``"regularisation"``
        for a discontinuous law)."""
        out: dict[str, Any] = {"omega": [self.omega_min, self.omega_max], "harmonics": self.harmonics}
        if self.regularisation is not None:
            out["regularisation"] = self.regularisation
        if self.refine is not None:
            out["refine"] = self.refine
        if self.limit_harmonics is not None:
            out["limit_harmonics"] = self.limit_harmonics
        if self.held_limit is not None:
            out["held_limit"] = self.held_limit
        if self.method is not None:
            out["method"] = self.method
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class RunConfig:
    """A validated configuration file.

    Attributes
    ----------
    model : Model, Chain or System (continuous, or with its whole laws: the single equation's or a chain's)
        The ``[model]`` and ``[excitation]`` tables: a single-equation :class:`~rattle.model.System` when
        ``[model.elastic]`` is discontinuous (a ``preload`` > 0 or a ``friction`` level > 0; only
        ``rattle frf``, ``rattle orbit`` and :func:`rattle.frequency_response` solve it), a
        :class:`~rattle.model.System` with its elements' whole laws for a chain with a ``friction`` level > 0 on some
        ``[[model.elements]]`` (only ``rattle frf``, ``rattle orbit``, ``frequency_response`` and
        ``nonsmooth_orbit``), else a Model or a
        Chain.
    analysis : AnalysisSettings
        The ``[analysis]`` table, defaults filled in.
    source : dict
        The parsed TOML as read (a deep copy), for provenance in the run metadata.
    source_name : str
        Where it came from (the file path, or ``"<dict>"``), used in messages.
    """

    model: Model
    analysis: AnalysisSettings = field(default_factory=AnalysisSettings)
    source: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)
    source_name: str = field(default="<dict>", compare=False)
    #: ``[[paths]]`` (SPEC §6): the sound paths (:class:`rattle.model.SoundPath`), read by ``rattle.io._paths``.
    paths: tuple[Any, ...] = ()
    #: ``[model] units`` (SPEC §6): ``"dimensionless"`` or ``"SI"``; the model holds the numbers as given
    #: (angles converted to rad) either way.
    units: str = "dimensionless"
    #: For a discontinuous law: the Model of the same inertia, damping, stiffness and excitation
    #: with the law's continuous part (f without its jumps and friction), whose stages set the
    #: frequency bounds (:mod:`rattle._limits`); for a chain with friction the same chain without
    #: its friction; None otherwise.
    continuous_model: Any = field(default=None, compare=False, repr=False)

    @property
    def discontinuous(self) -> bool:
        """True when :attr:`model` is a :class:`~rattle.model.System` with its whole laws: the single
        equation's (a jump or friction) or a chain's (friction or a jump on its elements)."""
        return isinstance(self.model, System) and self.model.discontinuous

    @property
    def chain_friction(self) -> bool:
        """True when :attr:`model` is a chain's :class:`~rattle.model.System` with its elements' whole
        laws: Coulomb friction or a jump on some ``[[model.elements]]`` (``rattle frf`` and ``rattle
        orbit`` solve it)."""
        return self.discontinuous and not self.model.is_single_equation

    @property
    def bounds_model(self) -> Any:
        """The model whose stages set the frequency bounds: :attr:`continuous_model` for a
        discontinuous law, :attr:`model` otherwise."""
        return self.continuous_model if self.discontinuous else self.model

    def to_dict(self) -> dict[str, Any]:
        """The resolved configuration (defaults filled in) as a TOML-shaped dict (angles in rad, an
        ``[engine]`` resolved into its torque and ``[model] speed_order``; a discontinuous law with
        its preload and friction as written: relative to K, or in N m with ``units = "SI"``)."""
        if self.chain_friction:
            out = _friction_chain_to_toml_dict(self.model, self.continuous_model, self.analysis, self.units)
        elif self.discontinuous:
            out = _nonsmooth_to_toml_dict(self.model, self.continuous_model, self.analysis, self.units)
        else:
            out = model_to_toml_dict(self.model, self.analysis)
        if self.units != "dimensionless":
            out["model"] = {"units": self.units, **out["model"]}
        return out


# --------------------------------------------------------------------------------------------
# Schema of [analysis] (the model tables: rattle.model._tables)
# --------------------------------------------------------------------------------------------
_ANALYSIS_KEYS = ("omega", "harmonics", "regularisation", "refine", "limit_harmonics", "held_limit", "method")
#: ``analysis.method`` of a discontinuous law (SPEC §8), the default first.
METHODS = ("shooting", "hb")
_EXAMPLES.update({
    "analysis": "[analysis] with omega = [0.1, 3.0], harmonics = 32",
    "analysis.omega": "omega = [0.1, 3.0]",
    "analysis.harmonics": "harmonics = 32",
    "analysis.regularisation": "regularisation = 0.01",
    "analysis.refine": "refine = 0.005",
    "analysis.limit_harmonics": "limit_harmonics = 64",
    "analysis.held_limit": "held_limit = true",
    "analysis.method": 'method = "shooting"',
})


# --------------------------------------------------------------------------------------------
# Readers
# --------------------------------------------------------------------------------------------
def load_config(path: str | os.PathLike[str]) -> RunConfig:
    """Read and validate a SPEC §2 configuration file.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file.

    Returns
    -------
    RunConfig
        The model, the analysis settings (defaults filled in) and the parsed source.

    Raises
    ------
    ConfigError
        If the file cannot be read, is not TOML, or breaks a rule of the schema (see the module
        docstring); the message names the key, the value, the rule and the fix.
    TypeError
        If ``path`` is not a path (None, a number …), naming it and showing the value.
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"`path` must be the path of a TOML configuration file (a str or os.PathLike), got {path!r} "
                        f"({type(path).__name__})")
    return config_from_dict(read_toml(path), source_name=os.fsdecode(path))


def config_from_dict(data: Mapping[str, Any], source_name: str = "<dict>") -> RunConfig:
    """Validate an already parsed configuration (the dict ``tomllib.load`` returns).

    Parameters
    ----------
    data : mapping
        Tables ``model`` (with ``elastic``), ``excitation`` and optionally ``analysis``.
    source_name : str, default "<dict>"
        Shown at the start of error messages.

    Returns
    -------
    RunConfig

    Raises
    ------
    ConfigError
        On the first broken rule (structure first, then values).
    """
    check = _Checker(source_name)
    if not isinstance(data, Mapping):
        raise check.error(f"the configuration must be a table of tables, got {_kind(data)}")
    if "paths" in data:  # [[paths]] (SPEC §6): the rest first, then the path tables checked against its model
        from ._paths import with_paths

        rest = config_from_dict({k: v for k, v in data.items() if k != "paths"}, source_name)
        if rest.discontinuous:
            raise check.error(
                "`paths` (sound paths) is not supported with a discontinuous law (`model.elastic.preload`, "
                "`model.elastic.friction`, a `model.elements.K.friction` or a `model.elements.K` with type = "
                "\"preload\") yet: the sound pressure is computed "
                "from the smooth laws' responses; remove [[paths]] (rattle frf gives the law's response without it)"
            )
        return with_paths(rest, data["paths"], source_name)

    # Structure of [analysis] first, then the model tables (structure before values), then the values.
    analysis_t: Mapping[str, Any] = {}
    if "analysis" in data:
        analysis_t = check.table(data, "analysis", "analysis")
        check.keys(analysis_t, "analysis", _ANALYSIS_KEYS, required=())
    tables = model_tables(data, source_name)
    engine = tables.engine
    omega_names = None
    if engine is not None:  # the analysis axis is the crankshaft speed
        if "omega" in analysis_t:
            raise check.error(
                "`analysis.omega` and `engine.speed_rpm` are both given: with [engine] the analysis axis is the "
                "crankshaft speed; remove `analysis.omega` (engine.speed_rpm sets the range)"
            )
        analysis_t = {**analysis_t, "omega": [float(forcing_frequency(r, engine.base_order)) for r in engine.rpm]}
        omega_names = {"omega_min": "engine.speed_rpm[0]", "omega_max": "engine.speed_rpm[1]"}
    analysis = _analysis(check, analysis_t, discontinuous=tables.discontinuous,
                         chain=tables.chain is not None and not tables.chain.has_jumps,
                         system=tables.chain is not None)
    if engine is not None and analysis.harmonics < engine.harmonics:
        raise check.error(
            f"`analysis.harmonics` must be >= {engine.harmonics}: the highest of `engine.orders` is harmonic "
            f"{engine.harmonics} of their base order {engine.base_order:g}, got {analysis.harmonics}; raise "
            "`analysis.harmonics`"
        )
    model = tables.continuous_model if tables.discontinuous else tables.model  # its stages set the bounds
    check_harmonics(model, analysis.harmonics)
    try:
        check_analysis(model, analysis, omega_names)
    except ConfigError as exc:
        if engine is None:
            raise check.error(str(exc)) from None
        rpm = 60.0 / (2.0 * math.pi * engine.base_order)  # rpm per rad/s of Ω
        w_s = model.natural_frequency
        raise check.error(
            f"{exc} (rad/s of Ω = {engine.base_order:g} × crankshaft speed; in rpm the range must lie within "
            f"{_limits.MIN_OMEGA_RATIO * w_s * rpm:.4g} … {_limits.MAX_OMEGA_RATIO * w_s * rpm:.4g} rpm)"
        ) from None
    return RunConfig(model=tables.model, analysis=analysis, source=copy.deepcopy(dict(data)), source_name=source_name,
                     units=tables.units, continuous_model=tables.continuous_model)


# --------------------------------------------------------------------------------------------
# Discontinuous laws, the rules of model and analysis together, [analysis]
# --------------------------------------------------------------------------------------------
def _nonsmooth_to_toml_dict(system: System, model: Model | None, analysis: AnalysisSettings,
                            units: str) -> dict[str, Any]:
    """The tables of a discontinuous configuration (round trip through :func:`config_from_dict`):
    the preload and friction as written (× K back to N m with ``units = "SI"``)."""
    assert model is not None
    scale = model.stiffness if units == "SI" else 1.0
    law = system.law
    elastic = dict(law.elastic.to_dict())
    if isinstance(law.elastic, Preload):
        elastic["preload"] = law.elastic.preload * scale
    if law.friction is not None:
        elastic["friction"] = [r * scale for r in law.friction.levels]
    out = model_to_toml_dict(model, analysis)
    out["model"]["elastic"] = elastic
    return out


def _friction_chain_to_toml_dict(system: System, chain: Any, analysis: AnalysisSettings,
                                 units: str) -> dict[str, Any]:
    """The tables of a chain with friction or preloads (round trip through
    :func:`config_from_dict`): the chain without them (``chain``, every law's continuous part),
    each element's ``friction`` as written and a preloaded element's ``type = "preload"`` with its
    keys (both relative to its stiffness K_e, or × K_e back to N m with ``units = "SI"``)."""
    out = model_to_toml_dict(chain, analysis)
    for e, (law, element) in enumerate(zip(system.laws, chain.elements)):
        scale = element.stiffness if units == "SI" else 1.0
        table = out["model"]["elements"][e]
        if isinstance(law.elastic, Preload):
            for key in ("type", "b", "alpha", "breakpoints", "slopes"):
                table.pop(key, None)
            table.update(type="preload", preload=law.elastic.preload * scale, clearance=law.elastic.clearance,
                         slope=law.elastic.slope)
        if law.friction is not None and any(law.friction.levels):
            table["friction"] = [r * scale for r in law.friction.levels]
    return out


def check_harmonics(model: Model, harmonics: int, name: str = "analysis.harmonics") -> None:
    """The harmonic balance must hold every excitation harmonic: ``harmonics`` >= their count."""
    if getattr(model, "excitation", None) is not None:
        needed, where = len(model.excitation.amplitudes), f"`excitation.amplitudes` has {len(model.excitation.amplitudes)}"
    else:
        needed, where = model.forced_harmonics, f"the longest `excitation.torques` amplitudes list has {model.forced_harmonics}"
    if harmonics < needed:
        raise ConfigError(
            f"`{name}` must be >= {needed}, the number of excitation harmonics "
            f"({where}), got {harmonics}; raise `{name}`"
        )
    system = getattr(model, "system", None)
    if callable(system):  # a chain's coordinates share the effective harmonics of one problem
        try:
            _limits.check_harmonics(harmonics, name, coordinates=int(system().n))
        except ValueError as exc:
            raise ConfigError(str(exc)) from None


def check_analysis(
    model: Model, analysis: AnalysisSettings, names: Mapping[str, str] | None = None
) -> None:
    """The rules that need the model and the analysis settings together (after
    :func:`check_harmonics`): the analyses refuse zero damping, and the frequency range must lie
    within the bounds relative to the model's stiffest stage (:mod:`rattle._limits`).

    ``names`` maps ``omega_min`` / ``omega_max`` to the key or option the value came from
    (default ``analysis.omega.1`` / ``analysis.omega.2``; the command line passes
    ``--omega-min`` / ``--omega-max`` for the values it overrides). Raises ConfigError.
    """
    names = {"omega_min": "analysis.omega.1", "omega_max": "analysis.omega.2", **(names or {})}
    try:
        check_analysable_model(model)
        _limits.check_frequency_range(model, analysis.omega_min, analysis.omega_max,
                                      (names["omega_min"], names["omega_max"]))
    except (ValueError, TypeError) as exc:
        raise ConfigError(str(exc)) from None


def _analysis(check: _Checker, table: Mapping[str, Any], discontinuous: bool = False,
              chain: bool = False, system: bool = False) -> AnalysisSettings:
    """``[analysis]``; for a discontinuous law also ``regularisation`` (refused otherwise; default
    :data:`DEFAULT_REGULARISATION`, :data:`DEFAULT_CHAIN_REGULARISATION` for a ``chain`` with
    friction and no jump on its elements: a jump's position step at 0.001 makes the continuation
    crawl, docs/nonsmooth.md), and the harmonics default :data:`DEFAULT_NONSMOOTH_HARMONICS`;
    ``limit_harmonics`` (discontinuous laws only) defaults to the harmonics for a chain (``system``)
    with friction or jumps on its elements."""
    regularisation = None
    if "regularisation" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.regularisation` = {_show(table['regularisation'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0, a `model.elastic.friction` or `model.elements.K.friction` level > 0, "
                "a `model.elements.K.preload` > 0), "
                "whose jumps the harmonic balance smooths; this law is continuous and solved without it: remove "
                "`analysis.regularisation`"
            )
        regularisation = table["regularisation"]
        check.number(regularisation, "analysis.regularisation")
    elif discontinuous:
        regularisation = DEFAULT_CHAIN_REGULARISATION if chain else DEFAULT_REGULARISATION
    refine = DEFAULT_REFINE if discontinuous else None
    if "refine" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.refine` = {_show(table['refine'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0, a `model.elastic.friction` or `model.elements.K.friction` level > 0, "
                "a `model.elements.K.preload` > 0), "
                "whose regularised harmonic balance it refines; this law is continuous: remove `analysis.refine`"
            )
        refine = table["refine"]
        check.number(refine, "analysis.refine")
    omega = table.get("omega", list(DEFAULT_OMEGA))
    check.array(omega, "analysis.omega")
    if len(omega) != 2:
        raise check.error(
            f"`analysis.omega` must be a list of two numbers [min, max] (rad/s), got {_show(omega)} "
            f"({len(omega)} number{'' if len(omega) == 1 else 's'}); write e.g. {_example('analysis.omega')}"
        )
    harmonics = table.get("harmonics", DEFAULT_NONSMOOTH_HARMONICS if discontinuous else DEFAULT_HARMONICS)
    check.integer(harmonics, "analysis.harmonics")
    limit_harmonics = None
    if "limit_harmonics" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.limit_harmonics` = {_show(table['limit_harmonics'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0, a `model.elastic.friction` or `model.elements.K.friction` level > 0, "
                "a `model.elements.K.preload` > 0), whose regularisation it continues to its limit; this law is "
                "continuous: remove `analysis.limit_harmonics`"
            )
        limit_harmonics = table["limit_harmonics"]
        check.integer(limit_harmonics, "analysis.limit_harmonics")
    elif system and discontinuous:
        # a chain's ladder keeps its H: each doubling multiplies a dense Jacobian of n(2H + 1)
        # unknowns (at n = 3, H = 256 about 40 s a row against 2 s at H = 64, measured in
        # docs/nonsmooth.md), and H = harmonics meets 0.5 % away from special points there
        limit_harmonics = harmonics
    held_limit = None
    if "held_limit" in table:
        if not (system and discontinuous):
            raise check.error(
                f"`analysis.held_limit` = {_show(table['held_limit'])} applies only to a chain with friction or a "
                "torque jump on its elements (a `model.elements.K.friction` level > 0 or a `model.elements.K.preload` "
                "> 0), whose held elements' steps it narrows: remove `analysis.held_limit`"
            )
        held_limit = table["held_limit"]
        if not isinstance(held_limit, bool):
            raise check.error(f"`analysis.held_limit` must be true or false, got {_show(held_limit)}; "
                              f"write e.g. {_example('analysis.held_limit')}")
    method = METHODS[0] if discontinuous else None
    if "method" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.method` = {_show(table['method'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0, a `model.elastic.friction` or `model.elements.K.friction` level > 0, "
                "a `model.elements.K.preload` > 0), which exact shooting or the regularised harmonic balance "
                "solves; this law is continuous and solved by harmonic balance: remove `analysis.method`"
            )
        method = table["method"]
        if method not in METHODS:
            raise check.error(f"`analysis.method` must be \"shooting\" (exact shooting continuation, the default) or "
                              f"\"hb\" (the regularised harmonic balance), got {_show(method)}; "
                              f"write e.g. {_example('analysis.method')}")
    return check.build(
        AnalysisSettings,
        {"omega_min": "analysis.omega.1", "omega_max": "analysis.omega.2", "harmonics": "analysis.harmonics",
         "regularisation": "analysis.regularisation", "refine": "analysis.refine",
         "limit_harmonics": "analysis.limit_harmonics", "held_limit": "analysis.held_limit",
         "method": "analysis.method"},
        omega_min=omega[0], omega_max=omega[1], harmonics=harmonics, regularisation=regularisation, refine=refine,
        limit_harmonics=limit_harmonics, held_limit=held_limit, method=method,
    )


# --------------------------------------------------------------------------------------------
# Writers (round trip)
# --------------------------------------------------------------------------------------------
def model_to_toml_dict(model: Model, analysis: AnalysisSettings | None = None) -> dict[str, Any]:
    """The SPEC §2 tables describing ``model`` (and ``analysis`` if given).

    ``config_from_dict(model_to_toml_dict(m)).model == m`` for every valid model. Angles are
    written in rad (``b``, ``breakpoints``; never the ``_deg`` keys), a chain's engine as its
    torques and ``[model] speed_order``.

    Parameters
    ----------
    model : Model
    analysis : AnalysisSettings, optional
        Adds an ``analysis`` table when given.

    Returns
    -------
    dict
        ``{"model": {..., "elastic": {...}}, "excitation": {...}[, "analysis": {...}]}``.
    """
    if not hasattr(model, "elastic"):  # a chain
        d = model.to_dict()
        elements = [{k: v for k, v in e.items()} for e in d["elements"]]
        out_c: dict[str, Any] = {"model": {"inertias": d["inertias"], "links": d["links"], "elements": elements},
                                 "excitation": {"torques": d["torques"]}}
        if d.get("speed_order") is not None:  # an [engine]'s base order: results keep their rpm
            out_c["model"]["speed_order"] = d["speed_order"]
        if d.get("drag") is not None:  # written with its balancing inertia (no [engine] to infer it from)
            out_c["drag"] = d["drag"]
        if not d["links"]:
            del out_c["model"]["links"]
        if analysis is not None:
            out_c["analysis"] = analysis.to_dict()
        return out_c
    out: dict[str, Any] = {
        "model": {
            "inertia": model.inertia,
            "damping": model.damping,
            "stiffness": model.stiffness,
            "elastic": model.elastic.to_dict(),
        },
        "excitation": model.excitation.to_dict(),
    }
    if analysis is not None:
        out["analysis"] = analysis.to_dict()
    return out


_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key, ensure_ascii=False)


def _toml_value(value: Any, key: str) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return repr(x) if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(v, key) for v in value) + "]"
    raise TypeError(f"`{key}`: cannot write {value!r} ({type(value).__name__}) as a TOML value")


def dumps_toml(data: Mapping[str, Any]) -> str:
    """Format nested tables of numbers, strings, booleans and arrays as TOML text.

    Enough for configuration files (:func:`model_to_toml_dict`); arrays of tables and dates
    are not supported.

    Parameters
    ----------
    data : mapping
        Nested mappings; leaves are scalars or arrays of scalars.

    Returns
    -------
    str
    """
    lines: list[str] = []

    def emit(table: Mapping[str, Any], path: list[str]) -> None:
        def is_array_of_tables(v: Any) -> bool:
            return isinstance(v, (list, tuple)) and bool(v) and all(isinstance(x, Mapping) for x in v)

        scalars = [(k, v) for k, v in table.items() if not isinstance(v, Mapping) and not is_array_of_tables(v)]
        tables = [(k, v) for k, v in table.items() if isinstance(v, Mapping)]
        arrays = [(k, v) for k, v in table.items() if is_array_of_tables(v)]
        if path and (scalars or not (tables or arrays)):
            if lines:
                lines.append("")
            lines.append("[" + ".".join(_toml_key(p) for p in path) + "]")
        for k, v in scalars:
            lines.append(f"{_toml_key(str(k))} = {_toml_value(v, '.'.join([*path, str(k)]))}")
        for k, v in arrays:
            for item in v:
                if lines:
                    lines.append("")
                lines.append("[[" + ".".join(_toml_key(p) for p in [*path, str(k)]) + "]]")
                for kk, vv in item.items():
                    lines.append(f"{_toml_key(str(kk))} = {_toml_value(vv, '.'.join([*path, str(k), str(kk)]))}")
        for k, v in tables:
            emit(v, [*path, str(k)])

    emit(data, [])
    return "\n".join(lines) + "\n"

