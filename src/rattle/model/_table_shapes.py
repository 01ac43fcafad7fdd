"""Sub-system shapes of the configuration file, rewritten into the ordinary chain tables.

A drivetrain part may be described as its data sheet gives it; each shape is checked here,
built by its Python builder (:mod:`rattle.model._builders`, where the physics is stated) and
handed on as the SPEC §5 tables the reader already knows::

    [[model.elements]]                 type = "damper": a multi-stage clutch damper
    type = "damper"                    drive_stiffness, coast_stiffness   N m/rad (or *_per_deg: N m/deg)
    between = [1, 2]                   drive_angles, coast_angles         rad (or *_deg), one fewer than stages
                                       free_play                          rad (or free_play_deg), optional
                                       friction                           optional, passed on (per stage of
                                                                          the law built: coast … drive)
        → stiffness = the stiffest stage, type = "piecewise", breakpoints, slopes (and friction)

    [[model.elements]]                 type = "spline": a clutch hub spline
    type = "spline"                    stiffness                          N m/rad when engaged
                                       backlash                           total free play, rad (or backlash_deg)
        → type = "backlash", b = backlash / 2

    [model.gear_pair]                  base_radii, inertias, mesh_stiffness (N/m), mesh_damping_ratio,
                                       backlash (m, total, along the line of action; or backlash_mm,
                                       backlash_um; base_radii_mm …), name
        → [model] inertias = [J1, J2 (r1/r2)²], the mesh damping link and the mesh element on gear 1's
          side; torques on inertia 2 ([[excitation.torques]], [engine], [drag]) × r1/r2

    [model.loose_gear]                 base_radii, inertia, mesh_stiffness, mesh_damping_ratio, backlash
                                       (or backlash_um), drag_torque (N m), name; speed_rpm, orders,
                                       drive_acceleration (rad/s² of gear 1 per order), drive_phases
        → a grounded one-inertia chain in δ = (r1/r2) θ1 − θ2 and its [engine] table (the base excitation
          J2 (r1/r2) θ1'' and the drag as the mean torque)

Refusals are :class:`~rattle.errors.ConfigError` naming the key the user wrote. The resolved
configuration (``RunConfig.to_dict``) holds the ordinary tables; ``RunConfig.source`` the file as
written.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any

from ._builders import backlash_warning, clutch_damper, gear_pair, hub_spline, loose_gear
from ._elastic import ELASTIC_LAWS
from .._table_checks import UNIT_SUFFIXES, _Checker, _in_base_units, _show, rename_keys

__all__ = ["SUBSYSTEM_TYPES", "expand_subsystems"]

#: Element types that are sub-system shapes (rewritten here), besides the elastic laws.
SUBSYSTEM_TYPES = ("damper", "spline")

_DAMPER_KEYS = ("name", "between", "type", "drive_stiffness", "drive_angles", "coast_stiffness", "coast_angles",
                "free_play", "friction")
_SPLINE_KEYS = ("name", "between", "type", "stiffness", "backlash", "friction")
_GEAR_KEYS = ("name", "base_radii", "inertias", "mesh_stiffness", "mesh_damping_ratio", "backlash")
_LOOSE_KEYS = ("name", "base_radii", "inertia", "mesh_stiffness", "mesh_damping_ratio", "backlash", "drag_torque",
               "speed_rpm", "orders", "drive_acceleration", "drive_phases")
_EXAMPLE = {
    "damper": 'type = "damper", between = [1, 2], drive_stiffness = [86.0, 1720.0], drive_angles_deg = [4.0], '
              "coast_stiffness = [60.0, 1200.0], coast_angles_deg = [3.0]",
    "spline": 'type = "spline", between = [2, 3], stiffness = 8000.0, backlash_deg = 1.0',
    "gear_pair": "[model.gear_pair] with base_radii = [0.03, 0.04], inertias = [5e-3, 6e-3], "
                 "mesh_stiffness = 2.0e8, mesh_damping_ratio = 0.05, backlash_um = 60.0",
    "loose_gear": "[model.loose_gear] with base_radii = [0.03, 0.04], inertia = 2e-4, mesh_stiffness = 2.0e8, "
                  "mesh_damping_ratio = 0.05, backlash_um = 100.0, drag_torque = 0.05, speed_rpm = [600, 3000], "
                  "orders = [2.0], drive_acceleration = [300.0]",
}
_DEG_PER_RAD = 180.0 / math.pi


def _build(check: _Checker, factory: Any, names: Mapping[str, str], /, **kwargs: Any) -> Any:
    """``factory(**kwargs)``; its ValueError/TypeError re-raised naming the user's keys. Warnings are
    left to the ordinary reader, which sees the resulting tables."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return factory(**kwargs)
    except (ValueError, TypeError) as exc:
        raise check.error(rename_keys(str(exc), names)) from None


def _keys(check: _Checker, table: Mapping[str, Any], where: str, allowed: tuple[str, ...],
          required: tuple[str, ...], what: str, kind: str) -> None:
    for key in table:
        if key not in allowed:
            from .._table_checks import _did_you_mean

            lengths = ", lengths also as KEY_mm or KEY_um" if "backlash" in allowed and kind != "spline" else ""
            stem = str(key).rsplit("_", 1)[0]
            if lengths and stem in ("backlash", "base_radii") and stem in allowed:  # a length in another unit
                raise check.error(
                    f"`{where}.{key}` is not a known key: `{stem}` is a length in metres (lengths also as KEY_mm or "
                    f"KEY_um); write it in m as `{stem}`, in millimetres as `{stem}_mm` or in micrometres as `{stem}_um`")
            raise check.error(
                f"`{where}.{key}` is not a known key: {what} allows only {', '.join(allowed)} (angles also as "
                f"KEY_deg{lengths}); {_did_you_mean(str(key), allowed)}remove it or correct its spelling"
            )
    for key in required:
        if key not in table:
            raise check.error(f"`{where}.{key}` is missing: {what} requires {', '.join(required)}; write e.g. "
                              f"{_EXAMPLE[kind]}")


def _per_degree(check: _Checker, table: dict[str, Any], where: str, key: str) -> None:
    """``KEY_per_deg`` (N m/deg) → ``KEY`` (N m/rad) in ``table``."""
    deg = f"{key}_per_deg"
    if deg not in table:
        return
    if key in table:
        raise check.error(f"`{where}.{key}` and `{where}.{deg}` are both given: one stiffness in N m/rad and in "
                          "N m/deg; keep one of them")
    values = table.pop(deg)
    check.array(values, f"{where}.{deg}")
    for i, v in enumerate(values):
        if not v > 0:
            raise check.error(f"`{where}.{deg}[{i}]` must be > 0 N m/deg (a stage stiffness), got {_show(v)}")
    table[key] = [float(v) * _DEG_PER_RAD for v in values]
    check.user_keys[f"{where}.{key}"] = (f"{where}.{deg}", "N m/rad")  # messages name the key written


def _damper(check: _Checker, t: Mapping[str, Any], where: str) -> dict[str, Any]:
    t = dict(t)
    for key in ("drive_stiffness", "coast_stiffness"):
        _per_degree(check, t, where, key)
    t = _in_base_units(check, t, where, _DAMPER_KEYS, angles=("drive_angles", "coast_angles", "free_play"))
    _keys(check, t, where, _DAMPER_KEYS, ("between", "drive_stiffness", "coast_stiffness"),
          'type = "damper" ([[model.elements]])', "damper")
    for key in ("drive_stiffness", "drive_angles", "coast_stiffness", "coast_angles"):
        if key in t:
            check.array(t[key], f"{where}.{key}")
    if "free_play" in t:
        check.number(t["free_play"], f"{where}.free_play")
    names = {k: f"{where}.{k}" for k in _DAMPER_KEYS}
    element = _build(check, clutch_damper, names, drive_stiffness=t["drive_stiffness"],
                     drive_angles=t.get("drive_angles", []), coast_stiffness=t["coast_stiffness"],
                     coast_angles=t.get("coast_angles", []), free_play=t.get("free_play", 0.0))
    out = {k: t[k] for k in ("name", "between") if k in t}
    if isinstance(t.get("friction"), list):  # one level per stage: counted in the damper's own stages
        _damper_friction_count(check, t, where, len(element.law.stages.slopes))
    # friction (its values checked by the chain reader, per stage of the law built here) passes through
    return {**out, "stiffness": element.stiffness, **element.law.to_dict(),
            **({"friction": t["friction"]} if "friction" in t else {})}


def _damper_friction_count(check: _Checker, t: Mapping[str, Any], where: str, n: int) -> None:
    """A damper's ``friction`` list: one level or one per stage of its law, the stages named as the
    data sheet gives them (coast outermost first, the free play, then drive from zero outwards)."""
    kc, kd = list(t["coast_stiffness"]), list(t["drive_stiffness"])
    names = [f"coast stage {j}" for j in range(len(kc), 0, -1)]
    if float(t.get("free_play", 0.0)) > 0:
        names.append("free play")
    drive = [f"drive stage {j}" for j in range(1, len(kd) + 1)]
    if names[-1] == "coast stage 1" and float(kc[0]) == float(kd[0]):  # one stage across zero
        names[-1], drive = "coast/drive stage 1", drive[1:]
    names += drive
    levels = t["friction"]
    if len(levels) not in (1, n):
        stages = ", ".join(names) if len(names) == n else f"{n} stages"
        raise check.error(
            f"`{where}.friction` must hold one level (every stage) or one per stage of the damper: it has {n} "
            f"stage{'' if n == 1 else 's'} ({stages}; from the most negative twist), got {len(levels)} levels "
            f"{_show(levels)}; give {n} levels or a single number"
        )


def _spline(check: _Checker, t: Mapping[str, Any], where: str) -> dict[str, Any]:
    t = _in_base_units(check, t, where, _SPLINE_KEYS, angles=("backlash",))
    _keys(check, t, where, _SPLINE_KEYS, ("between", "stiffness", "backlash"), 'type = "spline" ([[model.elements]])', "spline")
    check.number(t["stiffness"], f"{where}.stiffness")
    check.number(t["backlash"], f"{where}.backlash")
    element = _build(check, hub_spline, {k: f"{where}.{k}" for k in _SPLINE_KEYS}, backlash=t["backlash"],
                     stiffness=t["stiffness"])
    out = {k: t[k] for k in ("name", "between") if k in t}
    return {**out, "stiffness": element.stiffness, **element.law.to_dict(),
            **({"friction": t["friction"]} if "friction" in t else {})}


def _mesh_lengths(check: _Checker, t: Mapping[str, Any], where: str, known: tuple[str, ...],
                  angles: tuple[str, ...] = ()) -> dict[str, Any]:
    """A gear table with its lengths in m (``backlash``, ``base_radii``: also as ``KEY_mm``, ``KEY_um``)
    and its angles in rad."""
    return _in_base_units(check, t, where, known, angles=angles, lengths=("backlash", "base_radii"))


def _judge_backlash(check: _Checker, where: str, backlash: float, base_radii: Any, element: str) -> None:
    """One warning, naming the key the user wrote and the likely unit, when the backlash is
    implausible for the gear geometry (:func:`~rattle.model._builders.backlash_warning`); the mesh
    element derived from it (``element``, its half-gap ``b``) is then not judged again as an angle."""
    written = check.converted_keys.get(where, {}).get("backlash", "backlash")
    unit = UNIT_SUFFIXES[written[len("backlash"):]][1] if written != "backlash" else "m"
    message = backlash_warning(backlash, base_radii, key=f"{where}.{written}", unit=unit, in_file=True)
    if message is not None:
        warnings.warn(f"{check.source_name}: {message}", UserWarning, stacklevel=5)
    check.derived_keys.add(f"{element}.b")


def _name(check: _Checker, t: Mapping[str, Any], where: str) -> str:
    """The mesh element's name (default ``"mesh"``): an identifier, it names the output columns."""
    name = t.get("name", "mesh")
    if not isinstance(name, str) or not name.isidentifier():
        raise check.error(f"`{where}.name` must be an identifier (letters, digits, underscore; it names the output "
                          f"columns NAME_rms …), got {_show(name)}; write e.g. name = \"mesh\"")
    return name


def _scale(value: Any, factor: float) -> Any:
    """A number or list of numbers × ``factor``; anything else unchanged (the reader refuses it by name)."""
    def num(v: Any) -> bool:
        return isinstance(v, (int, float)) and not isinstance(v, bool)

    if num(value):
        return value * factor
    if isinstance(value, list) and all(num(v) for v in value):
        return [v * factor for v in value]
    return value


def _whole_model(check: _Checker, model_t: Mapping[str, Any], key: str, whole: str, units: str) -> None:
    """A shape that is the whole model: [model] holds only ``units`` = "SI" and the shape's table."""
    others = [k for k in model_t if k not in ("units", key)]
    if others:
        raise check.error(f"`model.{others[0]}` cannot be given with [model.{key}]: {whole}; [model] then holds only "
                          f"units and {key}")
    if model_t.get("units") != "SI":
        raise check.error(f"[model.{key}] needs `model.units` = \"SI\" (got {_show(model_t.get('units'))}): {units}; "
                          "add units = \"SI\" to [model]")


def _gear_pair(check: _Checker, data: dict[str, Any], model_t: Mapping[str, Any]) -> dict[str, Any]:
    where = "model.gear_pair"
    _whole_model(check, model_t, "gear_pair", "the gear pair is the whole chain (its two gears are inertias 1 and 2)",
                 "its radii are in m, its mesh stiffness in N/m")
    t = check.table(model_t, "gear_pair", where)
    t = _mesh_lengths(check, t, where, _GEAR_KEYS)
    _keys(check, t, where, _GEAR_KEYS, ("base_radii", "inertias", "mesh_stiffness", "mesh_damping_ratio",
                                        "backlash"), "[model.gear_pair]", "gear_pair")
    for key in ("base_radii", "inertias"):
        check.array(t[key], f"{where}.{key}")
    for key in ("mesh_stiffness", "mesh_damping_ratio", "backlash"):
        check.number(t[key], f"{where}.{key}")
    name = _name(check, t, where)
    pair = _build(check, gear_pair, {k: f"{where}.{k}" for k in _GEAR_KEYS}, base_radii=t["base_radii"],
                  inertias=t["inertias"], mesh_stiffness=t["mesh_stiffness"],
                  mesh_damping_ratio=t["mesh_damping_ratio"], backlash=t["backlash"], name=name)
    _judge_backlash(check, where, float(t["backlash"]), pair.base_radii, "model.elements[0]")
    element = {"name": name, "between": [1, 2], "stiffness": pair.stiffness, "type": "backlash", "b": pair.half_gap}
    out = dict(data)
    out["model"] = {"units": model_t["units"], "inertias": list(pair.chain.inertias),
                    "links": [{"between": [1, 2], "damping": pair.damping}], "elements": [element]}
    # torques on gear 2 are given in N m of gear 2's shaft: on gear 1's side × r1/r2
    r = pair.ratio
    excitation = out.get("excitation")
    if isinstance(excitation, Mapping) and isinstance(excitation.get("torques"), list):
        torques = [({**tq, **{k: _scale(tq[k], r) for k in ("mean", "amplitudes") if k in tq}}
                    if isinstance(tq, Mapping) and tq.get("inertia") == 2 else tq) for tq in excitation["torques"]]
        out["excitation"] = {**excitation, "torques": torques}
    engine = out.get("engine")
    if isinstance(engine, Mapping) and engine.get("inertia") == 2:
        out["engine"] = {**engine, **{k: _scale(engine[k], r) for k in ("mean_torque", "amplitudes") if k in engine}}
    drag = out.get("drag")
    if isinstance(drag, Mapping) and drag.get("inertia") == 2 and "torque" in drag:
        out["drag"] = {**drag, "torque": _scale(drag["torque"], r)}
    return out


def _loose_gear(check: _Checker, data: dict[str, Any], model_t: Mapping[str, Any]) -> dict[str, Any]:
    where = "model.loose_gear"
    _whole_model(check, model_t, "loose_gear", "the loose gear is the whole model (one inertia in the relative "
                 "coordinate)", "its radii are in m, its speeds in rpm")
    for key in ("engine", "excitation"):
        if key in data:
            raise check.error(
                f"`{key}` cannot be given with [model.loose_gear]: the loose gear's excitation is the driving gear's "
                "motion (`model.loose_gear.speed_rpm`, `orders`, `drive_acceleration`) and its drag the constant "
                f"`drag_torque` or a [drag] table by speed; remove [{key}]"
            )
    t = dict(check.table(model_t, "loose_gear", where))
    drag_t = None
    if "drag" in data:  # the loose gear's drag by speed: in δ = (r1/r2) θ1 − θ2 it enters as + D(rpm)
        drag_t = check.table(data, "drag", "drag")
        extra = [k for k in drag_t if k not in ("speed_rpm", "torque")]
        if extra:
            raise check.error(f"`drag.{extra[0]}` is not a key of a loose gear's [drag]: it acts on the loose gear "
                              "(the model's only inertia) and the driving gear delivers it; give speed_rpm and torque")
        if "drag_torque" in t:
            raise check.error(f"`{where}.drag_torque` and [drag] are both given: give the loose gear's drag once "
                              "(a constant `drag_torque`, or [drag] by speed)")
        t["drag_torque"] = 0.0
    t = _mesh_lengths(check, t, where, _LOOSE_KEYS, angles=("drive_phases",))
    _keys(check, t, where, _LOOSE_KEYS, ("base_radii", "inertia", "mesh_stiffness", "mesh_damping_ratio",
                                         "backlash", "drag_torque", "speed_rpm", "orders", "drive_acceleration"),
          "[model.loose_gear]", "loose_gear")
    for key in ("base_radii", "drive_acceleration", "orders", "speed_rpm", "drive_phases"):
        if key in t:
            check.array(t[key], f"{where}.{key}")
    for key in ("inertia", "mesh_stiffness", "mesh_damping_ratio", "backlash", "drag_torque"):
        check.number(t[key], f"{where}.{key}")
    if len(t["drive_acceleration"]) != len(t["orders"]):
        raise check.error(f"`{where}.drive_acceleration` must have one entry per order of `{where}.orders` "
                          f"({len(t['orders'])}), got {len(t['drive_acceleration'])}")
    name = _name(check, t, where)
    gear = _build(check, loose_gear, {k: f"{where}.{k}" for k in _LOOSE_KEYS}, base_radii=t["base_radii"],
                  inertia=t["inertia"],
                  mesh_stiffness=t["mesh_stiffness"], mesh_damping_ratio=t["mesh_damping_ratio"],
                  backlash=t["backlash"], drive_acceleration=t["drive_acceleration"],
                  drive_phases=t.get("drive_phases"), drag_torque=t["drag_torque"],
                  name=name)
    _judge_backlash(check, where, float(t["backlash"]), gear.base_radii, "model.elements[0]")
    tq = gear.chain.torques[0]
    out = dict(data)
    out["model"] = {"units": "SI", "inertias": list(gear.chain.inertias),
                    "links": [{"between": [1, 0], "damping": gear.damping}],
                    "elements": [{"name": name, "between": [1, 0], "stiffness": gear.stiffness, "type": "backlash",
                                  "b": gear.half_gap}]}
    # the base excitation J2 (r1/r2) θ1''(t) and the drag, as an engine torque by order on the loose gear
    out["engine"] = {"inertia": 1, "speed_rpm": t["speed_rpm"], "orders": t["orders"], "mean_torque": tq.mean,
                     "amplitudes": list(tq.amplitudes), "phases": list(tq.phases or ())}
    if drag_t is not None:  # + D on δ, the reaction on the driving gear (ground of the relative coordinate)
        out["drag"] = {"inertia": 0, "balance": 1, **{k: drag_t[k] for k in ("speed_rpm", "torque") if k in drag_t}}
    return out


def _refuse_discontinuous_in_chain(check: _Checker, model_t: Mapping[str, Any]) -> None:
    """A preload or friction on a gear pair or loose gear is refused: the mesh is a backlash law.
    (Friction and torque jumps on a chain's ``[[model.elements]]`` are solved, and friction on the
    damper and spline shapes.)"""
    for shape in ("gear_pair", "loose_gear"):
        t = model_t.get(shape)
        if not isinstance(t, Mapping):
            continue
        key = next((f"model.{shape}.{k}" for k in ("friction", "preload") if k in t), None)
        if key is not None:
            raise check.error(
                f"`{key}`: a gear mesh takes no preload or Coulomb friction (the mesh is a backlash law); both "
                "are solved on the elements of a chain ([[model.elements]] friction, type = \"preload\"): remove "
                "it, or write the mesh as an element"
            )


def expand_subsystems(data: Mapping[str, Any], source_name: str = "<dict>",
                      check: _Checker | None = None) -> Mapping[str, Any]:
    """``data`` with every sub-system shape rewritten into ordinary tables; ``data`` itself (the same
    object) when it has none. Raises ConfigError naming the key the user wrote. ``check``: the
    reader's checker, which then remembers the keys written with a unit suffix and the keys
    derived here (for the reader's messages)."""
    model_t = data.get("model") if isinstance(data, Mapping) else None
    if not isinstance(model_t, Mapping):
        return data
    check = _Checker(source_name) if check is None else check
    _refuse_discontinuous_in_chain(check, model_t)
    elastic = model_t.get("elastic")
    if isinstance(elastic, Mapping) and elastic.get("type") in SUBSYSTEM_TYPES:
        raise check.error(
            f"`model.elastic.type` = {_show(elastic['type'])} is a sub-system of a chain: give it as a "
            f"[[model.elements]] table of a chain ([model] inertias = [...]), e.g. "
            f"{_EXAMPLE[elastic['type']]}"
        )
    out: Any = data
    if "gear_pair" in model_t and "loose_gear" in model_t:
        raise check.error("`model.gear_pair` and `model.loose_gear` are both given: a file describes one of them")
    if "gear_pair" in model_t:
        return _gear_pair(check, dict(data), model_t)
    if "loose_gear" in model_t:
        return _loose_gear(check, dict(data), model_t)
    elements = model_t.get("elements")
    for k, t in enumerate(elements if isinstance(elements, list) else []):
        kind = t.get("type") if isinstance(t, Mapping) else None
        if isinstance(kind, str) and kind not in ELASTIC_LAWS and kind != "preload" and kind not in SUBSYSTEM_TYPES:
            from .._table_checks import _did_you_mean

            types = [*ELASTIC_LAWS, "preload", *SUBSYSTEM_TYPES]
            hint = _did_you_mean(kind, types).replace("`", '"')
            raise check.error(
                f"`model.elements[{k}].type` must be one of {', '.join(_show(x) for x in types)}, got {_show(kind)}; "
                f"{hint}use one of these names (\"damper\" and \"spline\" take a data sheet's values)"
            )
    if isinstance(elements, list) and any(isinstance(t, Mapping) and t.get("type") in SUBSYSTEM_TYPES
                                          for t in elements):
        new = []
        for k, t in enumerate(elements):
            where = f"model.elements[{k}]"
            if isinstance(t, Mapping) and t.get("type") == "damper":
                new.append(_damper(check, t, where))
            elif isinstance(t, Mapping) and t.get("type") == "spline":
                new.append(_spline(check, t, where))
            else:
                new.append(t)
        out = {**data, "model": {**model_t, "elements": new}}
    return out
