"""The model tables of a configuration file, read into model objects (SPEC §2, §5, §6).

Schema of the physical tables (every other key is refused)::

    [model]              inertia, damping, stiffness      numbers, required
    [model.elastic]      type                             "linear" | "backlash" | "clutch" | "piecewise" | "unilateral"
                                                          | "preload"
                         + the parameters of that type    backlash: b; clutch: alpha, b;
                                                          piecewise: breakpoints, slopes;
                                                          preload: preload, clearance, slope
                         friction                         number or one per stage, optional
    [excitation]         mean                             number, required
                         amplitudes                       array of numbers, required, not empty
                         phases                           array of numbers, optional (default 0)

SPEC §5 chains (``[model] inertias``, ``[[model.links]]``, ``[[model.elements]]``,
``[[excitation.torques]]``) and SPEC §6: ``[model] units`` ("dimensionless" or "SI", a
declaration: the numbers are used as given); angles in degrees through ``b_deg`` and
``breakpoints_deg`` in ``[model.elastic]`` and every ``[[model.elements]]``, converted here, once,
to the radian keys (both given: refused); ``[engine]`` (chains in SI only: inertia, cylinders,
speed_rpm, mean_torque, orders, amplitudes, phases) resolved here into an ordinary torque in
harmonics of the orders' base order (:mod:`._engine`) and ``Chain.speed_order``; ``[drag]``.
The data-sheet shapes (damper, spline, gear pair, loose gear) are first rewritten into these
tables (:mod:`._table_shapes`). ``[[model.elements]] friction`` (Coulomb levels, one or one per
stage of the element's law, relative to its stiffness K_e, or in N m with ``units = "SI"``) and
``[[model.elements]] type = "preload"`` (a torque jump, ``preload``, ``clearance``, ``slope``, the
jump relative to K_e or in N m) make the model the chain's :class:`System` with its elements' whole laws.

The run's own tables, ``[analysis]`` and ``[[paths]]``, are known here by name only: the
configuration reader (:mod:`rattle.io`) reads them and, from an ``[engine]``'s speed range
(:attr:`ModelTables.engine`), the analysis range Ω = base order · 2π/60 · rpm.

The value rules (positive inertia, increasing breakpoints, 0 <= alpha < 1, …) live in the model
dataclasses, the single source of truth; this module checks only what they cannot see (the
table structure, unknown and missing keys, the TOML type of each value) and re-raises their
errors as :class:`~rattle.errors.ConfigError` with the full key. Every message names the key in
backticks, shows the value received, states the rule and says the fix. No file is read here:
:func:`model_tables` is registered, when this module is loaded, as the reader that
:meth:`Model.from_toml` and :meth:`Chain.from_toml` call on a file's parsed tables (:mod:`._readers`).
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .. import _limits
from ..errors import ConfigError
from ._chain import Chain, Element, Link, Torque
from ._discontinuous import Friction, Preload
from ._drag import Drag
from ._elastic import ELASTIC_LAWS, AbstractElastic, Piecewise
from ._engine import engine_torque
from ._excitation import Excitation
from ._model import Model
from ._readers import register_reader
from ._system import System
from .._table_checks import (
    _EXAMPLES,
    ANGLE_KEYS,
    _Checker,
    positions_from_one,
    _did_you_mean,
    _example,
    _in_base_units,
    _join,
    _kind,
    _show,
)
from ._table_shapes import expand_subsystems

__all__ = ["UNITS", "EngineAxis", "ModelTables", "model_tables"]


# --------------------------------------------------------------------------------------------
# Schema
# --------------------------------------------------------------------------------------------
#: The top-level tables of a configuration file; the run's own, ``analysis`` and ``paths``, are
#: read by :mod:`rattle.io` and left alone here.
_TOP_KEYS = ("model", "excitation", "analysis", "engine", "paths", "drag")
_MODEL_KEYS = ("inertia", "damping", "stiffness", "elastic")
_EXCITATION_KEYS = ("mean", "amplitudes", "phases")
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
})


def _law_params(law: type) -> dict[str, tuple[str, bool]]:
    """Constructor parameters of an elastic law: name -> (kind "number"/"array"/"string", required)."""
    params = {}
    for f in dataclasses.fields(law):  # type: ignore[arg-type]
        if not f.init:
            continue
        text = str(f.type)
        kind = "array" if text.startswith(("tuple", "list", "Sequence")) else "string" if text == "str" else "number"
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        params[f.name] = (kind, required)
    return params



# --------------------------------------------------------------------------------------------
# What the model tables describe
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class EngineAxis:
    """An ``[engine]`` resolved: its torque (in harmonics of the base order), the base order, the
    number of harmonics the torque needs, and the crankshaft speed range (rpm) that sets the
    analysis range."""

    torque: Any
    base_order: float
    harmonics: int
    rpm: tuple[float, float]


@dataclass(frozen=True, slots=True)
class ModelTables:
    """The model tables of one configuration, validated.

    Attributes
    ----------
    model : Model, Chain or System (the single equation's or a chain's whole laws)
        The single equation's :class:`System` (:meth:`System.from_model`) when ``[model.elastic]`` is discontinuous (a ``preload`` > 0 or
        a ``friction`` level > 0); a :class:`System` with its elements' whole laws (``Chain.friction_system()``) for a
        chain with a ``friction`` level > 0 on some ``[[model.elements]]``; else a Model or a Chain.
    units : str
        ``[model] units``: ``"dimensionless"`` or ``"SI"``.
    continuous_model : Model, Chain or None
        For a discontinuous law the Model of the same inertia, damping, stiffness and excitation
        with the law's continuous part (whose stages set the frequency bounds); for a chain with
        friction the same chain without its friction; None otherwise.
    engine : EngineAxis or None
        The ``[engine]`` of a chain, resolved; None without one.
    chain : Chain or None
        For a chain with friction, the :class:`Chain` itself (its elements with their friction),
        which :meth:`Chain.from_toml` returns; None otherwise.
    """

    model: Any
    units: str = "dimensionless"
    continuous_model: Model | Chain | None = None
    engine: EngineAxis | None = None
    chain: Chain | None = None

    @property
    def discontinuous(self) -> bool:
        """True when :attr:`model` is a :class:`System` with its whole laws: the single equation's
        (a jump or friction) or a chain's (friction or a jump on its elements)."""
        return isinstance(self.model, System) and self.model.discontinuous


def model_tables(data: Mapping[str, Any], source_name: str = "<dict>") -> ModelTables:
    """Validate the model tables of an already parsed configuration (the dict ``tomllib.load``
    returns) and build the model they describe.

    ``[analysis]`` and ``[[paths]]`` are allowed and left alone (:mod:`rattle.io` reads them).

    Parameters
    ----------
    data : mapping
        Tables ``model`` (with ``elastic``, or a chain's ``inertias``), ``excitation`` (or an
        ``engine``), optionally ``engine`` and ``drag``.
    source_name : str, default "<dict>"
        Shown at the start of error messages.

    Returns
    -------
    ModelTables

    Raises
    ------
    ConfigError
        On the first broken rule (structure first, then values).
    """
    check = _Checker(source_name)
    if not isinstance(data, Mapping):
        raise check.error(f"the configuration must be a table of tables, got {_kind(data)}")
    data = expand_subsystems(data, source_name, check)  # damper, spline, gear pair shapes → the ordinary tables

    # Structure of every table first, so that a misspelt key is reported before its values.
    check.keys(data, "", _TOP_KEYS, required=("model",) if "engine" in data else ("model", "excitation"))
    model_t = check.table(data, "model", "model")
    units = _units(check, model_t)
    model_t = _model_in_radians(check, model_t)
    if "inertias" in model_t:  # SPEC §5: a chain of inertias
        return _chain_tables(check, data, model_t, units)
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

    # TOML value types.
    for key in ("inertia", "damping", "stiffness"):
        check.number(model_t[key], f"model.{key}")
    for key, (kind, _) in law_params.items():
        if key in elastic_t:
            check.value(kind, elastic_t[key], f"model.elastic.{key}")
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
    if system is not None:
        return ModelTables(model=system, units=units, continuous_model=model)
    return ModelTables(model=model, units=units)



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


def _friction(check: _Checker, elastic: Any, friction_t: Any, key: str) -> Friction:
    """The :class:`Friction` of ``friction_t`` (written at ``key``): levels >= 0, one (every stage)
    or one per stage of the law ``elastic``."""
    try:
        friction = check.build(Friction, {"levels": key}, levels=friction_t)
    except ConfigError as exc:
        if isinstance(friction_t, (list, tuple)):
            raise
        shown = positions_from_one(key)  # the message counts positions from 1 already
        raise check.error(str(exc).split(": ", 1)[1].replace(f"`{shown}.1`", f"`{shown}`")) from None  # as written
    n = len(elastic.stages.slopes)
    if len(friction.levels) not in (1, n):
        raise check.error(
            f"`{key}` must hold one level (every stage) or one per stage of the law: type = "
            f"{json.dumps(elastic.name if isinstance(elastic, Preload) else elastic.to_dict()['type'])} has "
            f"{n} stage{'' if n == 1 else 's'} ({_stage_names(elastic)}), got {len(friction.levels)} levels "
            f"{_show(list(friction.levels))}; give {n} levels or a single number"
        )
    return friction


def _nonsmooth_system(check: _Checker, model: Model, elastic: Any, friction_t: Any,
                      units: str) -> System | None:
    """The single equation's :class:`System` (:meth:`System.from_model`) of a law with a jump (``preload`` > 0) or ``friction`` (a level
    > 0); None for a continuous law. Preload and friction are torques relative to K (the torque
    jump is K T_p, the friction torque K r); with ``units = "SI"`` they are given in N m and
    divided here by ``model.stiffness`` K."""
    friction = None if friction_t is None else _friction(check, elastic, friction_t, "model.elastic.friction")
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
    return check.build(System.from_model, {"model": "model", "elastic": "model.elastic",
                                                   "friction": "model.elastic.friction"},
                       model=model, elastic=elastic, friction=friction)



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
        out["elastic"] = _in_base_units(check, out["elastic"], "model.elastic", [*laws, *_MODEL_ELASTIC_KEYS],
                                     angles=(*ANGLE_KEYS, "clearance"))
    elements = out.get("elements")
    if isinstance(elements, (list, tuple)) and all(isinstance(t, Mapping) for t in elements):
        out["elements"] = [_in_base_units(check, t, f"model.elements[{k}]",
                                       [*_MODEL_ELEMENTS_KEYS, "friction", *laws, *_MODEL_ELASTIC_KEYS],
                                       angles=(*ANGLE_KEYS, "clearance"))
                           for k, t in enumerate(elements)]
    return out


# --------------------------------------------------------------------------------------------
# [engine] (SPEC §6): the engine torque by order on one inertia, the speed range in rpm
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


def _engine(check: _Checker, data: Mapping[str, Any], n: int, units: str) -> EngineAxis:
    t = check.table(data, "engine", "engine")
    if units != "SI":
        raise check.error(
            f"`engine` needs `model.units` = \"SI\" (got {json.dumps(units)}): its speeds are in rpm and its "
            "torques in N m; add units = \"SI\" to [model] and give the model in SI units"
        )
    t = _in_base_units(check, t, "engine", _ENGINE_KEYS, angles=("phases",))
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
    return EngineAxis(torque=torque, base_order=q0, harmonics=len(torque.amplitudes), rpm=(float(rpm[0]), float(rpm[1])))


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


def _drag(check: _Checker, data: Mapping[str, Any], n: int, engine: EngineAxis | None, free: bool) -> Any:
    """The :class:`~rattle.model.Drag` of ``[drag]``: on a free chain the engine's inertia delivers
    it (``balance``, default the [engine]'s inertia)."""
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


def _chain_tables(check: _Checker, data: Mapping[str, Any], model_t: Mapping[str, Any],
                  units: str = "dimensionless") -> ModelTables:
    """The SPEC §5 chain: ``[model] inertias``, ``[[model.links]]``, ``[[model.elements]]``,
    ``[[excitation.torques]]``."""
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
        law_t = {key: v for key, v in t.items() if key not in (*_MODEL_ELEMENTS_KEYS, "friction")}
        for key in ("between", "stiffness"):
            if key not in t:
                raise check.error(f"`{where}.{key}` is missing: every [[model.elements]] needs between, stiffness "
                                  f"and type (+ the parameters of that type); add e.g. {_example('model.elements')}")
        try:
            law, law_params = _elastic_structure(check, law_t)
        except ConfigError as exc:
            message = str(exc).split(": ", 1)[1].replace("model.elastic", where)
            message = message.replace("allows only type,", f"allows only {', '.join(_MODEL_ELEMENTS_KEYS)}, type,")
            message = re.sub(r"(allows only [^;]*);", r"\1 (and friction);", message, count=1)
            raise check.error(message) from None
        name = t.get("name", f"element{k + 1}")
        if not isinstance(name, str):
            raise check.error(f"`{where}.name` must be a string, got {_show(name)} ({_kind(name)}); write e.g. name = \"clutch\"")
        _between(check, t["between"], f"{where}.between", n)
        check.number(t["stiffness"], f"{where}.stiffness")
        for key, (kind, _) in law_params.items():
            if key in law_t:
                check.value(kind, law_t[key], f"{where}.{key}")
        if "friction" in t:
            try:
                (check.array if isinstance(t["friction"], (list, tuple)) else check.number)(t["friction"],
                                                                                            f"{where}.friction")
            except ConfigError as exc:  # the example of the friction key, not of the whole element
                message = str(exc).split(": ", 1)[1].split(", e.g. ")[0]
                raise check.error(f"{message}, e.g. friction = 0.02 (every stage) or friction = [0.0, 0.02, 0.0] "
                                  "(one level per stage of the law)") from None
        elastic = check.build(law, {f: f"{where}.{f}" for f in law_params} or {"type": f"{where}.type"},
                              **{f: law_t[f] for f in law_params if f in law_t})
        if isinstance(elastic, Preload):  # a torque jump: relative to K_e like the slopes (N m with SI)
            elastic = _element_preload(check, elastic, t, where, units)
        friction = _element_friction(check, elastic, t, where, units)
        elements.append(check.build(Element, {"name": f"{where}.name", "between": f"{where}.between",
                                              "stiffness": f"{where}.stiffness", "friction": f"{where}.friction"},
                                    name=name, between=t["between"], stiffness=t["stiffness"], law=elastic,
                                    friction=friction))

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

    if not torques and not has_engine:  # required, and not empty: an unforced chain's response is all zero
        raise check.error("`excitation.torques` must hold at least one torque, got none (torques = []): without a "
                          "torque the chain rests and every response is zero; add e.g. [[excitation.torques]] with "
                          "inertia = 1, mean = 0.05, amplitudes = [0.06] (or an [engine])")
    names = {"inertias": "model.inertias", "links": "model.links", "elements": "model.elements",
             "torques": "excitation.torques", "speed_order": "model.speed_order"}
    engine = _engine(check, data, n, units) if has_engine else None
    speed_order = model_t.get("speed_order")
    if engine is not None:  # its torque joins the others (on the same inertia they add up)
        torques.append(engine.torque)
        speed_order = engine.base_order
        if engine.torque.mean:
            names["torques"] = "engine.mean_torque` with `excitation.torques"
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
    if chain.discontinuous:  # the equations with every element's friction and jumps; the chain without
        # them (every law's continuous part) sets the bounds
        smooth = dataclasses.replace(chain, elements=tuple(dataclasses.replace(e, friction=None, law=e.continuous_law())
                                                           for e in elements))
        return ModelTables(model=chain.friction_system(), units=units, continuous_model=smooth, engine=engine,
                           chain=chain)
    return ModelTables(model=chain, units=units, engine=engine)


def _element_preload(check: _Checker, elastic: Preload, t: Mapping[str, Any], where: str, units: str) -> Preload:
    """``[[model.elements]] type = "preload"``: the preload T_p relative to the element's
    stiffness K_e (the torque jumps by 2 K_e T_p across zero), or in N m with ``units = "SI"``, divided here by
    K_e; a clearance in degrees by mistake is warned about as for the single equation."""
    if elastic.clearance > 0:
        check.build(_limits.warn_clearance, {"clearance": f"{where}.clearance"}, b=elastic.clearance,
                    name="clearance", stacklevel=2)
    K = float(t["stiffness"])
    if units == "SI" and K > 0:  # a stiffness <= 0 is refused by Element
        return Preload(preload=elastic.preload / K, clearance=elastic.clearance, slope=elastic.slope)
    return elastic


def _element_friction(check: _Checker, elastic: Any, t: Mapping[str, Any], where: str, units: str) -> Friction | None:
    """``[[model.elements]] friction``: Coulomb levels r_ej >= 0 relative to the element's stiffness
    K_e (the hysteresis torque is K_e r_ej), one for every stage or one per stage of its law; with
    ``units = "SI"`` torques in N m, divided here by K_e. None when absent or all zero (a chain
    without friction is the smooth chain)."""
    if "friction" not in t:
        return None
    friction = _friction(check, elastic, t["friction"], f"{where}.friction")
    if not any(friction.levels):
        return None
    K = float(t["stiffness"])
    if units == "SI" and K > 0:  # N m → relative to K_e (a stiffness <= 0 is refused by Element)
        friction = Friction(levels=tuple(r / K for r in friction.levels))
    return friction


# Model.from_toml and Chain.from_toml read their files with this reader (they cannot import it:
# it builds them).
register_reader(model_tables)
