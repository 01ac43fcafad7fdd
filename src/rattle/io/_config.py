"""Strict reading of the SPEC §2 configuration file into a :class:`RunConfig`.

Schema (every other key is refused)::

    [model]              inertia, damping, stiffness      numbers, required
    [model.elastic]      type                             "linear" | "backlash" | "clutch" | "piecewise"
                         + the parameters of that type    backlash: b; clutch: alpha, b;
                                                          piecewise: breakpoints, slopes
    [excitation]         mean                             number, required
                         amplitudes                       array of numbers, required, not empty
                         phases                           array of numbers, optional (default 0)
    [analysis]           omega                            [min, max] in rad/s, optional (default [0.1, 3.0])
                         harmonics                        integer 1 … 256, optional (default 32)

SPEC §5 chains (``[model] inertias``, ``[[model.links]]``, ``[[model.elements]]``,
``[[excitation.torques]]``) and SPEC §6: ``[model] units`` ("dimensionless" or "SI", a
declaration: the numbers are used as given); angles in degrees through ``b_deg`` and
``breakpoints_deg`` in ``[model.elastic]`` and every ``[[model.elements]]``, converted here, once,
to the radian keys (both given: refused); ``[engine]`` (chains in SI only: inertia, cylinders,
speed_rpm, mean_torque, orders, amplitudes, phases) resolved here into an ordinary torque in
harmonics of the orders' base order (:mod:`rattle.model._engine`), ``Chain.speed_order`` and the
analysis range Ω = base order · 2π/60 · rpm.

Bounds shared with the library (:mod:`rattle._limits`, the reasons are in the messages): every
number finite with magnitude <= 1e50 (and K/I, C/I, the force and deflection scales too);
``model.damping`` > 0 (an undamped system has no stable periodic orbit to analyse);
``analysis.omega`` within 1e-3 … 1e3 times the stiffest stage's natural frequency; at most 256
entries per array. A clearance ``b`` (or breakpoint) above pi/2 rad is warned about (degrees by
mistake?), not refused.

The ``[analysis]`` table holds numerical settings, not physics, so it may be left out: the
defaults are the SPEC §2 example values and end up in the run metadata. Every physical
quantity is required; nothing physical is defaulted.

The value rules (positive inertia, increasing breakpoints, 0 <= alpha < 1, …) live in the model
dataclasses, the single source of truth; this module checks only what they cannot see (the
table structure, unknown and missing keys, the TOML type of each value, the ``[analysis]``
table) and re-raises their errors as :class:`~rattle.errors.ConfigError` with the full key.
Every message names the key in backticks, shows the value received, states the rule and says
the fix.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import json
import math
import os
import re
import sys
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from .. import _limits
from ..errors import ConfigError
from ..model import AbstractElastic, ELASTIC_LAWS, Excitation, Model, Piecewise, check_analysable_model
from ..model._discontinuous import Friction, NonsmoothSystem, Preload
from ..model._elastic import _check_real
from ._checks import (
    ANGLE_KEYS, _EXAMPLES, _Checker, _did_you_mean, _example, _in_radians, _join, _kind, _show, rename_keys,
)
from ..files._read import read_bounded

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "DEFAULT_OMEGA", "DEFAULT_HARMONICS", "AnalysisSettings", "RunConfig",
    "load_config", "config_from_dict", "model_to_toml_dict", "dumps_toml", "rename_keys", "check_harmonics",
    "check_analysis", "DEFAULT_REGULARISATION", "DEFAULT_NONSMOOTH_HARMONICS",
]

#: Default forcing-frequency range ``analysis.omega`` (rad/s): the SPEC §2 example.
DEFAULT_OMEGA: tuple[float, float] = (0.1, 3.0)
#: Default number of harmonics ``analysis.harmonics``: the SPEC §2 example.
DEFAULT_HARMONICS: int = 32
#: Defaults for a discontinuous law (a preload or friction: ``rattle.analysis.nonsmooth_response``):
#: ``analysis.regularisation`` ε and ``analysis.harmonics`` (those of ``RegularisationOptions``).
DEFAULT_REGULARISATION: float = 0.01
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
    """

    omega_min: float = DEFAULT_OMEGA[0]
    omega_max: float = DEFAULT_OMEGA[1]
    harmonics: int = DEFAULT_HARMONICS
    regularisation: float | None = None
    refine: float | None = None

    def __post_init__(self) -> None:
        omega_min = _check_real("omega_min", self.omega_min)
        omega_max = _check_real("omega_max", self.omega_max)
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
            eps = _check_real("regularisation", self.regularisation)
            if not 0.0 < eps < 1.0:
                raise ValueError(
                    f"`regularisation` (relative width ε of the smooth steps replacing the jumps and the friction) "
                    f"must satisfy 0 < ε < 1, got {eps!r}; use e.g. 0.01 (smaller is closer to the exact law and "
                    "needs more harmonics)"
                )
            object.__setattr__(self, "regularisation", eps)
        if self.refine is not None:
            tol = _check_real("refine", self.refine)
            if not 0.0 <= tol < 1.0:
                raise ValueError(
                    f"`refine` (the relative HB rms error above which a row's regularisation is continued to its "
                    f"limit) must satisfy 0 <= refine < 1, got {tol!r}; use 0.005 (0.5 %), or 0 to turn it off"
                )
            object.__setattr__(self, "refine", tol)
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
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class RunConfig:
    """A validated configuration file.

    Attributes
    ----------
    model : Model, Chain or NonsmoothSystem
        The ``[model]`` and ``[excitation]`` tables: a :class:`~rattle.model.NonsmoothSystem` when
        ``[model.elastic]`` is discontinuous (a ``preload`` > 0 or a ``friction`` level > 0; only
        ``rattle frf`` and :func:`rattle.analysis.nonsmooth_response` solve it), else a Model or a
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
    #: frequency bounds (:mod:`rattle._limits`); None otherwise.
    continuous_model: Model | None = field(default=None, compare=False, repr=False)

    @property
    def discontinuous(self) -> bool:
        """True when :attr:`model` is a :class:`~rattle.model.NonsmoothSystem` (a jump or friction)."""
        return isinstance(self.model, NonsmoothSystem)

    @property
    def bounds_model(self) -> Any:
        """The model whose stages set the frequency bounds: :attr:`continuous_model` for a
        discontinuous law, :attr:`model` otherwise."""
        return self.continuous_model if self.discontinuous else self.model

    def to_dict(self) -> dict[str, Any]:
        """The resolved configuration (defaults filled in) as a TOML-shaped dict (angles in rad, an
        ``[engine]`` resolved into its torque and ``[model] speed_order``; a discontinuous law with
        its preload and friction as written: relative to K, or in N m with ``units = "SI"``)."""
        if self.discontinuous:
            out = _nonsmooth_to_toml_dict(self.model, self.continuous_model, self.analysis, self.units)
        else:
            out = model_to_toml_dict(self.model, self.analysis)
        if self.units != "dimensionless":
            out["model"] = {"units": self.units, **out["model"]}
        return out


# --------------------------------------------------------------------------------------------
# Schema
# --------------------------------------------------------------------------------------------
_TOP_KEYS = ("model", "excitation", "analysis", "engine", "paths", "drag")
_MODEL_KEYS = ("inertia", "damping", "stiffness", "elastic")
_EXCITATION_KEYS = ("mean", "amplitudes", "phases")
_ANALYSIS_KEYS = ("omega", "harmonics", "regularisation", "refine")
#: Keys of ``[model.elastic]`` besides the continuous laws' parameters: ``friction`` (any type) and
#: the parameters of type = "preload" (the discontinuous laws, :mod:`rattle.model._discontinuous`).
_MODEL_ELASTIC_KEYS = ("friction", "preload", "clearance", "slope")
#: Every ``[model.elastic] type``: the continuous laws and the preload (a torque jump).
_LAWS: dict[str, type] = {**ELASTIC_LAWS, "preload": Preload}
_EXAMPLES.update({
    "model.elastic.preload": "preload = 0.05",
    "model.elastic.clearance": "clearance = 0.0",
    "model.elastic.slope": "slope = 1.0",
    "model.elastic.friction": "friction = 0.02",
    "analysis.regularisation": "regularisation = 0.01",
    "analysis.refine": "refine = 0.005",
})

def _law_params(law: type) -> dict[str, tuple[str, bool]]:
    """Constructor parameters of an elastic law: name -> (kind "number"/"array", required)."""
    params = {}
    for f in dataclasses.fields(law):  # type: ignore[arg-type]
        if not f.init:
            continue
        kind = "array" if str(f.type).startswith(("tuple", "list", "Sequence")) else "number"
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        params[f.name] = (kind, required)
    return params


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
    """
    name = os.fspath(path)
    try:
        # a regular file of at most MAX_CONFIG_BYTES, checked before reading (not /dev/zero, not a FIFO)
        data = tomllib.loads(read_bounded(path).decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(
            f"configuration file {name!r} does not exist; check the path "
            f"(relative paths start at {os.getcwd()!r})"
        ) from None
    except IsADirectoryError:
        raise ConfigError(f"configuration file {name!r} is a directory; give the path of a .toml file") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"configuration file {name!r} is not UTF-8 text ({exc.reason} at byte {exc.start}); "
            "save it with UTF-8 encoding"
        ) from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{name} is not valid TOML: {exc}; correct the syntax there") from None
    except OSError as exc:
        raise ConfigError(f"cannot read configuration file {name!r}: {exc.strerror or exc}") from None
    return config_from_dict(data, source_name=name)


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
                "`paths` (sound paths) is not supported with a discontinuous law (`model.elastic.preload` or "
                "`model.elastic.friction`) yet: the sound pressure is computed from the smooth laws' responses; "
                "remove [[paths]] (rattle frf gives the law's response without it)"
            )
        return with_paths(rest, data["paths"], source_name)
    from ._subsystems import expand_subsystems  # damper, spline, gear pair shapes → the ordinary tables

    if (expanded := expand_subsystems(data, source_name)) is not data:
        return dataclasses.replace(config_from_dict(expanded, source_name), source=copy.deepcopy(dict(data)))

    # Structure of every table first, so that a misspelt key is reported before its values.
    check.keys(data, "", _TOP_KEYS, required=("model",) if "engine" in data else ("model", "excitation"))
    model_t = check.table(data, "model", "model")
    units = _units(check, model_t)
    model_t = _model_in_radians(check, model_t)
    if "inertias" in model_t:  # SPEC §5: a chain of inertias
        return _chain_config(check, data, model_t, units)
    if "drag" in data:
        raise check.error(
            "`drag` needs a chain of inertias (SPEC §5–6): the drag torque acts on one inertia, but [model] is the "
            "single equation (inertia, damping, stiffness); use `[model] inertias` with [[model.links]] and "
            "[[model.elements]], or put a constant drag into `excitation.mean`"
        )
    if "engine" in data:
        raise check.error(
            "`engine` needs a chain of inertias (SPEC §5–6): the engine torque acts on one inertia, but [model] "
            "is the single equation (inertia, damping, stiffness); use `[model] inertias` with [[model.links]] "
            "and [[model.elements]] (a two-inertia free chain is the single equation), or give the excitation "
            "in [excitation] instead of [engine]"
        )
    if "excitation" not in data:
        check.keys(data, "", _TOP_KEYS, required=("model", "excitation"))
    check.keys(model_t, "model", _MODEL_KEYS, required=_MODEL_KEYS)
    elastic_t = check.table(model_t, "elastic", "model.elastic")
    law, law_params = _elastic_structure(check, {k: v for k, v in elastic_t.items() if k != "friction"})
    excitation_t = check.table(data, "excitation", "excitation")
    check.keys(excitation_t, "excitation", _EXCITATION_KEYS, required=("mean", "amplitudes"))
    analysis_t: Mapping[str, Any] = {}
    if "analysis" in data:
        analysis_t = check.table(data, "analysis", "analysis")
        check.keys(analysis_t, "analysis", _ANALYSIS_KEYS, required=())

    # TOML value types.
    for key in ("inertia", "damping", "stiffness"):
        check.number(model_t[key], f"model.{key}")
    for key, (kind, _) in law_params.items():
        if key in elastic_t:
            (check.array if kind == "array" else check.number)(elastic_t[key], f"model.elastic.{key}")
    if "friction" in elastic_t:
        friction_t = elastic_t["friction"]
        (check.array if isinstance(friction_t, (list, tuple)) else check.number)(friction_t, "model.elastic.friction")
    check.number(excitation_t["mean"], "excitation.mean")
    check.array(excitation_t["amplitudes"], "excitation.amplitudes")
    if "phases" in excitation_t:
        check.array(excitation_t["phases"], "excitation.phases")

    # Values: the dataclasses' own rules.
    elastic = check.build(
        law, {k: f"model.elastic.{k}" for k in law_params} or {"type": "model.elastic.type"},
        **{k: elastic_t[k] for k in law_params if k in elastic_t},
    )
    excitation = check.build(
        Excitation, {k: f"excitation.{k}" for k in _EXCITATION_KEYS},
        **{k: excitation_t[k] for k in _EXCITATION_KEYS if k in excitation_t},
    )
    model = check.build(
        Model, {k: f"model.{k}" for k in (*_MODEL_KEYS, "excitation")},
        inertia=model_t["inertia"], damping=model_t["damping"], stiffness=model_t["stiffness"],
        elastic=_continuous_part(check, elastic), excitation=excitation,
    )
    system = _nonsmooth_system(check, model, elastic, elastic_t.get("friction"), units)
    analysis = _analysis(check, analysis_t, discontinuous=system is not None)
    check_harmonics(model, analysis.harmonics)
    try:
        check_analysis(model, analysis)
    except ConfigError as exc:
        raise check.error(str(exc)) from None
    if system is not None:
        return RunConfig(model=system, analysis=analysis, source=copy.deepcopy(dict(data)), source_name=source_name,
                         units=units, continuous_model=model)
    return RunConfig(model=model, analysis=analysis, source=copy.deepcopy(dict(data)), source_name=source_name,
                     units=units)


# --------------------------------------------------------------------------------------------
# Discontinuous laws: a preload (torque jump) and friction in [model.elastic]
# --------------------------------------------------------------------------------------------
def _continuous_part(check: _Checker, elastic: Any) -> AbstractElastic:
    """The continuous law of ``elastic``: itself, or for a :class:`Preload` the piecewise-linear law
    of its stages without the jumps (slope s, and 0 inside a clearance b), which carries c, k and
    the stiffest stage into :class:`Model` (the frequency bounds, the scales)."""
    if not isinstance(elastic, Preload):
        return elastic
    st = elastic.stages
    if elastic.clearance > 0:  # the warning of a clearance in degrees by mistake, named as written
        check.build(_limits.warn_clearance, {"clearance": "model.elastic.clearance"}, b=elastic.clearance,
                    name="clearance", stacklevel=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Piecewise(breakpoints=tuple(st.breakpoints.tolist()), slopes=tuple(st.slopes.tolist()))


def _stage_names(elastic: Any) -> str:
    """The stages of a law in words, for the message on a per-stage friction list."""
    d = [float(x) for x in elastic.stages.breakpoints]
    if not d:
        return "δ"
    return ", ".join([f"δ < {d[0]:.6g}", *[f"{a:.6g} < δ < {b:.6g}" for a, b in itertools.pairwise(d)], f"δ > {d[-1]:.6g}"])


def _nonsmooth_system(check: _Checker, model: Model, elastic: Any, friction_t: Any,
                      units: str) -> NonsmoothSystem | None:
    """The :class:`NonsmoothSystem` of a law with a jump (``preload`` > 0) or ``friction`` (a level
    > 0); None for a continuous law. Preload and friction are torques relative to K (the torque
    jump is K T_p, the friction torque K r); with ``units = "SI"`` they are given in N m and
    divided here by ``model.stiffness`` K."""
    friction = None
    if friction_t is not None:
        friction = check.build(Friction, {"levels": "model.elastic.friction"}, levels=friction_t)
        n = len(elastic.stages.slopes)
        if len(friction.levels) not in (1, n):
            raise check.error(
                f"`model.elastic.friction` must hold one level (every stage) or one per stage of the law: type = "
                f"{json.dumps(elastic.name if isinstance(elastic, Preload) else elastic.to_dict()['type'])} has "
                f"{n} stage{'' if n == 1 else 's'} ({_stage_names(elastic)}), got {len(friction.levels)} levels "
                f"{_show(list(friction.levels))}; give {n} levels or a single number"
            )
    if not isinstance(elastic, Preload) and (friction is None or not any(friction.levels)):
        return None
    if isinstance(elastic, Preload) and elastic.preload == 0.0 and (friction is None or not any(friction.levels)):
        return None  # no jump, no friction: the continuous law (slope s, clearance b) of `model`
    if units == "SI":  # torques in N m → relative to K
        K = model.stiffness
        if isinstance(elastic, Preload):
            elastic = Preload(preload=elastic.preload / K, clearance=elastic.clearance, slope=elastic.slope)
        if friction is not None:
            friction = Friction(levels=tuple(r / K for r in friction.levels))
    return check.build(NonsmoothSystem.from_model, {"model": "model", "elastic": "model.elastic",
                                                   "friction": "model.elastic.friction"},
                       model=model, elastic=elastic, friction=friction)


def _nonsmooth_to_toml_dict(system: NonsmoothSystem, model: Model | None, analysis: AnalysisSettings,
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


def check_harmonics(model: Model, harmonics: int, name: str = "analysis.harmonics") -> None:
    """The harmonic balance must hold every excitation harmonic: ``harmonics`` >= their count."""
    if hasattr(model, "excitation"):
        needed, where = len(model.excitation.amplitudes), f"`excitation.amplitudes` has {len(model.excitation.amplitudes)}"
    else:
        needed, where = model.forced_harmonics, f"the longest `excitation.torques` amplitudes list has {model.forced_harmonics}"
    if harmonics < needed:
        raise ConfigError(
            f"`{name}` must be >= {needed}, the number of excitation harmonics "
            f"({where}), got {harmonics}; raise `{name}`"
        )


def check_analysis(
    model: Model, analysis: AnalysisSettings, names: Mapping[str, str] | None = None
) -> None:
    """The rules that need the model and the analysis settings together (after
    :func:`check_harmonics`): the analyses refuse zero damping, and the frequency range must lie
    within the bounds relative to the model's stiffest stage (:mod:`rattle._limits`).

    ``names`` maps ``omega_min`` / ``omega_max`` to the key or option the value came from
    (default ``analysis.omega[0]`` / ``analysis.omega[1]``; the command line passes
    ``--omega-min`` / ``--omega-max`` for the values it overrides). Raises ConfigError.
    """
    names = {"omega_min": "analysis.omega[0]", "omega_max": "analysis.omega[1]", **(names or {})}
    try:
        check_analysable_model(model)
        _limits.check_frequency_range(model, analysis.omega_min, analysis.omega_max,
                                      (names["omega_min"], names["omega_max"]))
    except (ValueError, TypeError) as exc:
        raise ConfigError(str(exc)) from None


def _elastic_structure(
    check: _Checker, table: Mapping[str, Any]
) -> tuple[type[AbstractElastic], dict[str, tuple[str, bool]]]:
    """Resolve ``model.elastic.type`` through ELASTIC_LAWS and check the keys against its parameters."""
    allowed_types = list(_LAWS)
    if "type" not in table:
        raise check.error(
            f"`model.elastic.type` is missing: [model.elastic] needs type = one of "
            f"{_join([json.dumps(t) for t in allowed_types])}; add e.g. {_example('model.elastic.type')}"
        )
    name = table["type"]
    if not isinstance(name, str) or name not in _LAWS:
        hint = _did_you_mean(name, allowed_types).replace("`", '"') if isinstance(name, str) else ""
        raise check.error(
            f"`model.elastic.type` must be one of {_join([json.dumps(t) for t in allowed_types])}, "
            f"got {_show(name)} ({_kind(name)}); {hint}use one of these names"
        )
    law = _LAWS[name]
    params = _law_params(law)
    for key in table:
        if key == "type" or key in params:
            continue
        users = [t for t, other in _LAWS.items() if key in _law_params(other)]
        if users:
            raise check.error(
                f"`model.elastic.{key}` does not belong to type = {json.dumps(name)}, whose "
                f"parameters are: {_join(list(params))}; remove it, or choose a type that uses it "
                f"({_join([json.dumps(u) for u in users])})"
            )
        allowed = ["type", *params]
        raise check.error(
            f"`model.elastic.{key}` is not a known key: [model.elastic] with type = "
            f"{json.dumps(name)} allows only {_join(allowed)}; {_did_you_mean(str(key), allowed)}"
            "remove it or correct its spelling"
        )
    required = [k for k, (_, req) in params.items() if req]
    for key in required:
        if key not in table:
            raise check.error(
                f"`model.elastic.{key}` is missing: type = {json.dumps(name)} requires "
                f"{_join(required)}; add e.g. {_example('model.elastic.' + key)}"
            )
    return law, params


def _analysis(check: _Checker, table: Mapping[str, Any], discontinuous: bool = False) -> AnalysisSettings:
    """``[analysis]``; for a discontinuous law also ``regularisation`` (refused otherwise), and the
    harmonics default :data:`DEFAULT_NONSMOOTH_HARMONICS`."""
    regularisation = None
    if "regularisation" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.regularisation` = {_show(table['regularisation'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0 or a `model.elastic.friction` level > 0), whose jumps the harmonic "
                "balance smooths; this law is continuous and solved without it: remove `analysis.regularisation`"
            )
        regularisation = table["regularisation"]
        check.number(regularisation, "analysis.regularisation")
    elif discontinuous:
        regularisation = DEFAULT_REGULARISATION
    refine = DEFAULT_REFINE if discontinuous else None
    if "refine" in table:
        if not discontinuous:
            raise check.error(
                f"`analysis.refine` = {_show(table['refine'])} applies only to a discontinuous law "
                "(`model.elastic.preload` > 0 or a `model.elastic.friction` level > 0), whose regularised harmonic "
                "balance it refines; this law is continuous: remove `analysis.refine`"
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
    return check.build(
        AnalysisSettings,
        {"omega_min": "analysis.omega[0]", "omega_max": "analysis.omega[1]", "harmonics": "analysis.harmonics",
         "regularisation": "analysis.regularisation", "refine": "analysis.refine"},
        omega_min=omega[0], omega_max=omega[1], harmonics=harmonics, regularisation=regularisation, refine=refine,
    )


# --------------------------------------------------------------------------------------------
# Units (SPEC §6): ``[model] units``, angles in degrees through ``_deg`` keys
# --------------------------------------------------------------------------------------------
#: ``[model] units``: the numbers are taken as given either way (the numerics are scale-aware);
#: ``"SI"`` declares kg m², N m/rad, N m s/rad, N m and rad, and is required by ``[engine]``.
UNITS = ("dimensionless", "SI")


def _units(check: _Checker, model_t: Mapping[str, Any]) -> str:
    if "units" not in model_t:
        return "dimensionless"
    value = model_t["units"]
    if not isinstance(value, str) or value not in UNITS:
        hint = _did_you_mean(value, UNITS).replace("`", '"') if isinstance(value, str) else ""
        raise check.error(
            f"`model.units` must be one of {_join([json.dumps(u) for u in UNITS])}, got {_show(value)} "
            f"({_kind(value)}); {hint}write units = \"SI\" (kg m², N m/rad, N m s/rad, N m, rad) or leave it out "
            "(dimensionless)"
        )
    return value


def _model_in_radians(check: _Checker, model_t: Mapping[str, Any]) -> dict[str, Any]:
    """``[model]`` without ``units``, its angles in rad (``[model.elastic]``, ``[[model.elements]]``)."""
    out = {k: v for k, v in model_t.items() if k != "units"}
    laws = sorted({p for law in ELASTIC_LAWS.values() for p in _law_params(law)} | {"type"})
    if isinstance(out.get("elastic"), Mapping):  # also the preload's clearance (clearance_deg)
        out["elastic"] = _in_radians(check, out["elastic"], "model.elastic", [*laws, *_MODEL_ELASTIC_KEYS],
                                     angles=(*ANGLE_KEYS, "clearance"))
    elements = out.get("elements")
    if isinstance(elements, (list, tuple)) and all(isinstance(t, Mapping) for t in elements):
        out["elements"] = [_in_radians(check, t, f"model.elements[{k}]", [*_MODEL_ELEMENTS_KEYS, *laws])
                           for k, t in enumerate(elements)]
    return out


# --------------------------------------------------------------------------------------------
# [engine] (SPEC §6): the engine torque by order on one inertia, the analysis axis in rpm
# --------------------------------------------------------------------------------------------
_ENGINE_KEYS = ("inertia", "cylinders", "speed_rpm", "mean_torque", "orders", "amplitudes", "phases")
_EXAMPLES.update({
    "engine": "[engine] with inertia = 1, speed_rpm = [600, 3000], orders = [2.0], amplitudes = [60.0]",
    "engine.inertia": "inertia = 1",
    "engine.cylinders": "cylinders = 4",
    "engine.speed_rpm": "speed_rpm = [600, 3000]",
    "engine.mean_torque": "mean_torque = 0.0",
    "engine.orders": "orders = [2.0, 4.0]",
    "engine.amplitudes": "amplitudes = [60.0, 15.0]",
    "engine.phases": "phases = [0.0, 0.0]",
})


@dataclass(frozen=True, slots=True)
class _Engine:
    torque: Any
    base_order: float
    harmonics: int
    rpm: tuple[float, float]


def _engine(check: _Checker, data: Mapping[str, Any], n: int, units: str) -> _Engine:
    from ..model._engine import engine_torque

    t = check.table(data, "engine", "engine")
    if units != "SI":
        raise check.error(
            f"`engine` needs `model.units` = \"SI\" (got {json.dumps(units)}): its speeds are in rpm and its "
            "torques in N m; add units = \"SI\" to [model] and give the model in SI units"
        )
    t = _in_radians(check, t, "engine", _ENGINE_KEYS, angles=("phases",))
    check.keys(t, "engine", _ENGINE_KEYS, required=("inertia", "speed_rpm", "orders", "amplitudes"))
    check.integer(t["inertia"], "engine.inertia")
    if not 1 <= t["inertia"] <= n:
        raise check.error(f"`engine.inertia` must be an inertia number 1 … {n} (`model.inertias` has {n}), "
                          f"got {t['inertia']}; give the inertia the engine drives (the flywheel)")
    if "cylinders" in t:
        check.integer(t["cylinders"], "engine.cylinders")
        if t["cylinders"] < 1:
            raise check.error(f"`engine.cylinders` must be an integer >= 1, got {t['cylinders']}")
    rpm = t["speed_rpm"]
    check.array(rpm, "engine.speed_rpm")
    if len(rpm) != 2 or not 0 < rpm[0] < rpm[1]:
        raise check.error(
            f"`engine.speed_rpm` must be [lowest, highest] crankshaft speed in rpm with 0 < lowest < highest, got "
            f"{_show(rpm)}; write e.g. {_example('engine.speed_rpm')}"
        )
    if "mean_torque" in t:
        check.number(t["mean_torque"], "engine.mean_torque")
    for key in ("orders", "amplitudes", "phases"):
        if key in t:
            check.array(t[key], f"engine.{key}")
    if not t["orders"]:
        raise check.error(f"`engine.orders` must hold at least one engine order, got []; write e.g. "
                          f"{_example('engine.orders')}")
    for i, q in enumerate(t["orders"]):
        if not q > 0:
            raise check.error(f"`engine.orders[{i}]` must be > 0 (a multiple of the crankshaft speed), got {_show(q)}")
    torque, q0 = check.build(
        engine_torque, {"inertia": "engine.inertia", "orders": "engine.orders", "amplitudes": "engine.amplitudes",
                        "phases": "engine.phases", "mean": "engine.mean_torque"},
        inertia=t["inertia"], orders=t["orders"], amplitudes=t["amplitudes"], phases=t.get("phases"),
        mean=t.get("mean_torque", 0.0),
    )
    return _Engine(torque=torque, base_order=q0, harmonics=len(torque.amplitudes), rpm=(float(rpm[0]), float(rpm[1])))


# --------------------------------------------------------------------------------------------
# [drag] (SPEC §6): the drag torque by speed on one inertia
# --------------------------------------------------------------------------------------------
_DRAG_KEYS = ("inertia", "speed_rpm", "torque", "balance")
_EXAMPLES.update({
    "drag": "[drag] with inertia = 2, speed_rpm = [600, 1500, 3000], torque = [2.0, 2.6, 3.5]",
    "drag.inertia": "inertia = 2",
    "drag.speed_rpm": "speed_rpm = [600, 1500, 3000]",
    "drag.torque": "torque = [2.0, 2.6, 3.5]",
    "drag.balance": "balance = 1",
})


def _drag(check: _Checker, data: Mapping[str, Any], n: int, engine: _Engine | None, free: bool) -> Any:
    """The :class:`~rattle.model.Drag` of ``[drag]``: on a free chain the engine's inertia delivers
    it (``balance``, default the [engine]'s inertia)."""
    from ..model import Drag

    t = check.table(data, "drag", "drag")
    check.keys(t, "drag", _DRAG_KEYS, required=("inertia", "speed_rpm", "torque"))
    for key in ("inertia", "balance"):
        if key in t:
            check.integer(t[key], f"drag.{key}")
            low = 0 if key == "inertia" and "balance" in t else 1  # 0: ground, with a balance
            if not low <= t[key] <= n:
                raise check.error(f"`drag.{key}` must be an inertia number 1 … {n} (`model.inertias` has {n}), "
                                  f"got {t[key]}")
    for key in ("speed_rpm", "torque"):
        check.array(t[key], f"drag.{key}")
    balance = t.get("balance")
    if balance is None and free and engine is not None:
        balance = engine.torque.inertia
    return check.build(Drag, {f: f"drag.{f}" for f in _DRAG_KEYS}, inertia=t["inertia"], speed_rpm=t["speed_rpm"],
                       torque=t["torque"], balance=balance)


# --------------------------------------------------------------------------------------------
# Chains (SPEC §5)
# --------------------------------------------------------------------------------------------
_CHAIN_MODEL = ("inertias", "links", "elements", "speed_order")
_MODEL_LINKS_KEYS = ("between", "stiffness", "damping")
_MODEL_ELEMENTS_KEYS = ("name", "between", "stiffness")
_EXCITATION_TORQUES_KEYS = ("inertia", "mean", "amplitudes", "phases")
_EXAMPLES.update({
    "model.inertias": "inertias = [2.0, 2.0]",
    "model.elements": '[[model.elements]] with name = "clutch", between = [1, 2], stiffness = 1.0, type = "clutch", alpha = 0.25, b = 0.174533',
    "excitation.torques": "[[excitation.torques]] with inertia = 1, mean = 0.05, amplitudes = [0.06]",
})


def _tables(check: _Checker, parent: Mapping[str, Any], key: str, full: str) -> list[Mapping[str, Any]]:
    """An array of tables ``[[full]]``."""
    value = parent[key]
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, Mapping) for v in value):
        raise check.error(
            f"`{full}` must be an array of tables (one [[{full}]] section each), got {_show(value)} "
            f"({_kind(value)}); write e.g. {_example(full)}"
        )
    return list(value)


def _between(check: _Checker, value: Any, key: str, n: int) -> None:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise check.error(
            f"`{key}` must be a pair of inertia numbers [i, j] (j = 0: ground), got {_show(value)}; "
            "write e.g. between = [1, 2]"
        )
    for i, v in enumerate(value):
        check.integer(v, f"{key}[{i}]")
        lo = 1 if i == 0 else 0
        if not lo <= v <= n:
            raise check.error(
                f"`{key}[{i}]` must be an inertia number 1 … {n}{' or 0 (ground)' if i else ''} "
                f"(`model.inertias` has {n}), got {v}"
            )
    if value[0] == value[1]:
        raise check.error(f"`{key}` must join two different inertias, got {_show(value)}")


def _chain_config(check: _Checker, data: Mapping[str, Any], model_t: Mapping[str, Any],
                  units: str = "dimensionless") -> RunConfig:
    """The SPEC §5 chain: ``[model] inertias``, ``[[model.links]]``, ``[[model.elements]]``,
    ``[[excitation.torques]]``."""
    from ..model import Chain, Element, Link, Torque

    for key in _MODEL_KEYS:
        if key in model_t:
            raise check.error(
                f"`model.{key}` belongs to the single-equation form, but [model] has `inertias` (a chain, "
                f"SPEC §5): give the chain's links and elements instead ([[model.links]], "
                f"[[model.elements]]) and remove `model.{key}`"
            )
    check.keys(model_t, "model", _CHAIN_MODEL, required=("inertias", "elements"))
    has_engine = "engine" in data
    excitation_t: Mapping[str, Any] = {}
    if "excitation" in data or not has_engine:
        excitation_t = check.table(data, "excitation", "excitation")
        check.keys(excitation_t, "excitation", ("torques",), required=() if has_engine else ("torques",))
    analysis_t: Mapping[str, Any] = {}
    if "analysis" in data:
        analysis_t = check.table(data, "analysis", "analysis")
        check.keys(analysis_t, "analysis", _ANALYSIS_KEYS, required=())
    if has_engine and "omega" in analysis_t:
        raise check.error(
            "`analysis.omega` and `engine.speed_rpm` are both given: with [engine] the analysis axis is the "
            "crankshaft speed; remove `analysis.omega` (engine.speed_rpm sets the range)"
        )
    if has_engine and "speed_order" in model_t:
        raise check.error(
            "`model.speed_order` and [engine] are both given: [engine] sets the base order from its orders; "
            "remove `model.speed_order`"
        )
    if "speed_order" in model_t:
        check.number(model_t["speed_order"], "model.speed_order")
    check.array(model_t["inertias"], "model.inertias")
    n = len(model_t["inertias"])
    if n == 0:
        raise check.error("`model.inertias` must hold at least one inertia, got []; write e.g. inertias = [2.0, 2.0]")

    links = []
    for k, t in enumerate(_tables(check, model_t, "links", "model.links") if "links" in model_t else []):
        where = f"model.links[{k}]"
        check.keys(t, where, _MODEL_LINKS_KEYS, required=("between",))
        _between(check, t["between"], f"{where}.between", n)
        for key in ("stiffness", "damping"):
            if key in t:
                check.number(t[key], f"{where}.{key}")
        links.append(check.build(Link, {f: f"{where}.{f}" for f in _MODEL_LINKS_KEYS}, **dict(t)))

    elements = []
    for k, t in enumerate(_tables(check, model_t, "elements", "model.elements")):
        where = f"model.elements[{k}]"
        law_t = {key: v for key, v in t.items() if key not in _MODEL_ELEMENTS_KEYS}
        for key in ("between", "stiffness"):
            if key not in t:
                raise check.error(f"`{where}.{key}` is missing: every [[model.elements]] needs between, stiffness "
                                  f"and type (+ the parameters of that type); add e.g. {_example('model.elements')}")
        try:
            law, law_params = _elastic_structure(check, law_t)
        except ConfigError as exc:
            message = str(exc).split(": ", 1)[1].replace("model.elastic", where)
            message = message.replace("allows only type,", f"allows only {', '.join(_MODEL_ELEMENTS_KEYS)}, type,")
            raise check.error(message) from None
        name = t.get("name", f"element{k + 1}")
        if not isinstance(name, str):
            raise check.error(f"`{where}.name` must be a string, got {_show(name)} ({_kind(name)}); write e.g. name = \"clutch\"")
        _between(check, t["between"], f"{where}.between", n)
        check.number(t["stiffness"], f"{where}.stiffness")
        for key, (kind, _) in law_params.items():
            if key in law_t:
                (check.array if kind == "array" else check.number)(law_t[key], f"{where}.{key}")
        elastic = check.build(law, {f: f"{where}.{f}" for f in law_params} or {"type": f"{where}.type"},
                              **{f: law_t[f] for f in law_params if f in law_t})
        elements.append(check.build(Element, {"name": f"{where}.name", "between": f"{where}.between",
                                              "stiffness": f"{where}.stiffness"},
                                    name=name, between=t["between"], stiffness=t["stiffness"], law=elastic))

    torques = []
    for k, t in enumerate(_tables(check, excitation_t, "torques", "excitation.torques") if "torques" in excitation_t else []):
        where = f"excitation.torques[{k}]"
        check.keys(t, where, _EXCITATION_TORQUES_KEYS, required=("inertia",))
        check.integer(t["inertia"], f"{where}.inertia")
        if not 1 <= t["inertia"] <= n:
            raise check.error(f"`{where}.inertia` must be an inertia number 1 … {n} (`model.inertias` has {n}), "
                              f"got {t['inertia']}")
        if "mean" in t:
            check.number(t["mean"], f"{where}.mean")
        for key in ("amplitudes", "phases"):
            if key in t:
                check.array(t[key], f"{where}.{key}")
        torques.append(check.build(Torque, {f: f"{where}.{f}" for f in _EXCITATION_TORQUES_KEYS}, **dict(t)))

    names = {"inertias": "model.inertias", "links": "model.links", "elements": "model.elements",
             "torques": "excitation.torques", "speed_order": "model.speed_order"}
    engine = _engine(check, data, n, units) if has_engine else None
    speed_order = model_t.get("speed_order")
    omega_names = None
    if engine is not None:  # its torque joins the others (on the same inertia they add up)
        from ..model._engine import forcing_frequency

        torques.append(engine.torque)
        speed_order = engine.base_order
        if engine.torque.mean:
            names["torques"] = "engine.mean_torque` with `excitation.torques"
        analysis_t = {**analysis_t, "omega": [float(forcing_frequency(r, speed_order)) for r in engine.rpm]}
        omega_names = {"omega_min": "engine.speed_rpm[0]", "omega_max": "engine.speed_rpm[1]"}
    drag = None
    if "drag" in data:
        free = not any(0 in x.between for x in (*links, *elements))
        drag = _drag(check, data, n, engine, free)
        names["drag"] = "drag"
        if speed_order is None:
            raise check.error("`drag` is tabulated over the crankshaft speed (`drag.speed_rpm`), but there is no "
                              "engine order to map rpm to Ω: give an [engine] (or `model.speed_order`)")
    chain = check.build(Chain, names, inertias=model_t["inertias"], links=tuple(links), elements=tuple(elements),
                        torques=tuple(torques), speed_order=speed_order, drag=drag)
    analysis = _analysis(check, analysis_t)
    if engine is not None and analysis.harmonics < engine.harmonics:
        raise check.error(
            f"`analysis.harmonics` must be >= {engine.harmonics}: the highest of `engine.orders` is harmonic "
            f"{engine.harmonics} of their base order {engine.base_order:g}, got {analysis.harmonics}; raise "
            "`analysis.harmonics`"
        )
    check_harmonics(chain, analysis.harmonics)
    try:
        check_analysis(chain, analysis, omega_names)
    except ConfigError as exc:
        if engine is None:
            raise check.error(str(exc)) from None
        rpm = 60.0 / (2.0 * math.pi * engine.base_order)  # rpm per rad/s of Ω
        w_s = chain.natural_frequency
        raise check.error(
            f"{exc} (rad/s of Ω = {engine.base_order:g} × crankshaft speed; in rpm the range must lie within "
            f"{_limits.MIN_OMEGA_RATIO * w_s * rpm:.4g} … {_limits.MAX_OMEGA_RATIO * w_s * rpm:.4g} rpm)"
        ) from None
    return RunConfig(model=chain, analysis=analysis, source=copy.deepcopy(dict(data)), source_name=check.source_name,
                     units=units)


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

