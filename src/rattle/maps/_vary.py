"""The varied parameters of a response map (SPEC §7): names, grids, and the models they give.

A parameter is named by a dotted key of the configuration tables or by a short name:

==============  =================================  ==========================================
short name      single equation (SPEC §2)          chain (SPEC §5): resolved when unambiguous
==============  =================================  ==========================================
``alpha``       ``model.elastic.alpha``            the one element with an ``alpha``
``b``           ``model.elastic.b``                the one element with a ``b``
``damping``     ``model.damping``                  the one link with a damping (the one > 0)
``mean``        ``excitation.mean``                the one torque with a mean ≠ 0
``amplitude``   ``excitation.amplitudes.1``        the one torque with a first harmonic ≠ 0
``preload``     ``model.elastic.preload``          the one element with a ``preload``
``friction``    ``model.elastic.friction.1``       the one element with a ``friction`` level
==============  =================================  ==========================================

``friction`` names the friction level of a law that has one (``friction = 0.02``); a law with a
level per stage is varied level by level (``model.elastic.friction.2``). The stage angles of a
piecewise law are its ``model.elastic.breakpoints.K``.

In a dotted key, list positions count from 1 (``excitation.amplitudes.1`` is F_p1, the first
harmonic; ``model.elements.2.b`` the second element's clearance), and an element may be named
by its ``name`` (``model.elements.clutch.alpha``). Keys are resolved to their canonical form
(numbers, not names).

The grid of one parameter is ``NAME=START:STOP:COUNT`` (COUNT equally spaced values, START
alone when COUNT is 1) or an explicit list ``NAME=v1,v2,v3``. Every combination's model is
built and validated (:func:`build_all`) before any work, so that a value the model refuses is
refused at once, naming the parameter, the value and the model's rule.

Every refusal is a :class:`~rattle.errors.ConfigError` naming ```--vary```.
"""

from __future__ import annotations

import copy
import difflib
import itertools
import math
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence, Set
from numbers import Real
from typing import Any

import numpy as np

from ..errors import ConfigError
from ._result import Parameter

__all__ = [
    "SHORT_NAMES", "MAX_VALUES", "MAX_COMBINATIONS", "parse_vary", "parse_all", "resolve", "numeric_keys",
    "get_value", "apply", "parameters", "combinations", "build_all", "given_in_degrees", "mark_degrees",
]

#: Short names and the dotted key they mean for a single-equation configuration (SPEC §7).
SHORT_NAMES: dict[str, str] = {
    "alpha": "model.elastic.alpha",
    "b": "model.elastic.b",
    "damping": "model.damping",
    "mean": "excitation.mean",
    "amplitude": "excitation.amplitudes.1",
    "preload": "model.elastic.preload",
    "friction": "model.elastic.friction",
}
#: Values one parameter may take (a grid of more is a typo: 1e6 values would be 1e6 frequency
#: responses).
MAX_VALUES = 10_000
#: Combinations a map may have (each is a frequency response with its attractor search).
MAX_COMBINATIONS = 100_000

#: Keys that are numbers but not quantities a map can vary: indices of inertias, the
#: analysis settings (the map's own axes and options).
_NOT_PARAMETERS = {
    "inertia": "it is the number of the inertia the torque acts on, not a quantity",
    "between": "it numbers the inertias joined, not a quantity",
    "harmonics": "it is a setting of the computation; give --harmonics instead",
    "omega": "the frequency is the map's own axis; give --omega-min / --omega-max instead",
    "speed_order": "it is the engine order of the forcing frequency (what turns Ω into rpm), not a design quantity",
}

_OPTION = "`--vary`"


def _not_parameter(path: Sequence[str]) -> str | None:
    """Why the key at ``path`` cannot be varied (its field's entry in ``_NOT_PARAMETERS``), or None.
    ``inertia`` is an index only in a torque (``model.inertia`` of SPEC §2 is a quantity)."""
    for k, part in enumerate(path):
        if part in _NOT_PARAMETERS and not (part == "inertia" and "torques" not in path[:k]):
            return part
    return None


def _err(message: str) -> ConfigError:
    return ConfigError(f"{_OPTION} {message}")


def _fmt(x: float) -> str:
    return f"{x:.10g}"


# --------------------------------------------------------------------------------------------
# NAME=START:STOP:COUNT
# --------------------------------------------------------------------------------------------
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*(\.[A-Za-z0-9_\-]+)*$")


def _number(text: str, what: str, whole: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise _err(f"{whole!r}: {what} must be a number, got {text!r}; write e.g. alpha=0.1:0.4:7") from None
    if not math.isfinite(value):
        raise _err(f"{whole!r}: {what} must be finite, got {text!r}; write e.g. alpha=0.1:0.4:7")
    return value


def parse_vary(text: str) -> tuple[str, tuple[float, ...]]:
    """One ``--vary`` argument: ``NAME=START:STOP:COUNT`` or ``NAME=v1,v2,…``.

    Parameters
    ----------
    text : str

    Returns
    -------
    (name, values)
        ``values``: COUNT equally spaced values from START to STOP (both included; START alone
        when COUNT is 1; rounded to 15 significant digits, so that 0:0.5:11 gives 0.3, not
        0.30000000000000004), or the listed values in the order given.

    Raises
    ------
    ConfigError
        Naming ``--vary``: no ``=``, an empty or malformed NAME, a START, STOP or value that is
        not a finite number, a COUNT that is not an integer >= 1 (or above :data:`MAX_VALUES`),
        a value given twice.
    """
    if not isinstance(text, str):
        raise _err(f"must be a string NAME=START:STOP:COUNT, got {text!r} ({type(text).__name__})")
    whole = text.strip()
    name, eq, spec = whole.partition("=")
    name, spec = name.strip(), spec.strip()
    if not eq:
        raise _err(f"{whole!r} has no `=`: write NAME=START:STOP:COUNT (e.g. alpha=0.1:0.4:7) or "
                   "NAME=v1,v2,v3 (e.g. alpha=0.1,0.25)")
    if not name or not _NAME.match(name):
        raise _err(f"{whole!r}: NAME must be a short name ({', '.join(SHORT_NAMES)}) or a dotted key of the "
                   f"configuration such as model.elastic.alpha, got {name!r}")
    if not spec:
        raise _err(f"{whole!r} gives no values after `=`: write {name}=START:STOP:COUNT (e.g. {name}=0.1:0.4:7)")
    if ":" in spec:
        parts = [p.strip() for p in spec.split(":")]
        if len(parts) != 3:
            raise _err(f"{whole!r}: the range must be START:STOP:COUNT (three parts), got {len(parts)} "
                       f"part(s); write e.g. {name}=0.1:0.4:7")
        start = _number(parts[0], "START", whole)
        stop = _number(parts[1], "STOP", whole)
        try:
            count_f = float(parts[2])
        except ValueError:
            raise _err(f"{whole!r}: COUNT must be an integer >= 1, got {parts[2]!r}; write e.g. "
                       f"{name}={parts[0]}:{parts[1]}:7") from None
        if not math.isfinite(count_f) or count_f != int(count_f) or not re.fullmatch(r"[+]?\d+", parts[2]):
            raise _err(f"{whole!r}: COUNT must be an integer >= 1 (the number of values), got {parts[2]!r}; "
                       f"write e.g. {name}={parts[0]}:{parts[1]}:7")
        count = int(count_f)
        if count < 1:
            raise _err(f"{whole!r}: COUNT must be an integer >= 1 (the number of values), got {count}; "
                       f"write e.g. {name}={parts[0]}:{parts[1]}:7, or {name}={parts[0]}:{parts[0]}:1 for one value")
        if count > MAX_VALUES:
            raise _err(f"{whole!r}: COUNT must be <= {MAX_VALUES}, got {count}: every value is a frequency "
                       "response per combination; use fewer values")
        if count > 1 and start == stop:
            raise _err(f"{whole!r}: START and STOP are equal ({_fmt(start)}) with COUNT {count}: the values would "
                       f"repeat; give COUNT 1 or a STOP different from START")
        # 15 significant digits: the decimal values meant (0.3, not linspace's 0.30000000000000004)
        values = tuple(float(f"{v:.15g}") for v in np.linspace(start, stop, count)) if count > 1 else (start,)
    else:
        parts = [p.strip() for p in spec.split(",")]
        if any(not p for p in parts):
            raise _err(f"{whole!r}: the list of values has an empty entry; write e.g. {name}=0.1,0.25,0.4")
        if len(parts) > MAX_VALUES:
            raise _err(f"{whole!r}: at most {MAX_VALUES} values, got {len(parts)}")
        values = tuple(_number(p, "every value", whole) for p in parts)
        seen: set[float] = set()
        for v in values:
            if v in seen:
                raise _err(f"{whole!r}: the value {_fmt(v)} is given twice; list every value once")
            seen.add(v)
    return name, values


def parse_all(texts: Iterable[str]) -> list[tuple[str, tuple[float, ...]]]:
    """Every ``--vary`` argument (:func:`parse_vary`); at least one, each NAME once."""
    out: list[tuple[str, tuple[float, ...]]] = []
    for text in texts:
        name, values = parse_vary(text)
        if any(name == n for n, _ in out):
            raise _err(f"gives {name!r} twice; give every parameter once (NAME=START:STOP:COUNT, or NAME=v1,v2,…)")
        out.append((name, values))
    if not out:
        raise _err("is required: give at least one parameter, e.g. --vary alpha=0.1:0.4:7")
    return out


# --------------------------------------------------------------------------------------------
# Keys of the configuration tables
# --------------------------------------------------------------------------------------------
def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def numeric_keys(tables: Mapping[str, Any]) -> list[str]:
    """Every dotted key (positions from 1) of ``tables`` whose value is a number a map may vary."""
    out: list[str] = []

    def walk(value: Any, path: list[str]) -> None:
        if isinstance(value, Mapping):
            for k, v in value.items():
                if _not_parameter([*path, str(k)]) or (not path and str(k) == "analysis"):
                    continue
                walk(v, [*path, str(k)])
        elif isinstance(value, (list, tuple)):
            for i, v in enumerate(value):
                walk(v, [*path, str(i + 1)])
        elif _is_number(value):
            out.append(".".join(path))

    walk(tables, [])
    return out


def _nearest(name: str, tables: Mapping[str, Any]) -> str:
    keys = numeric_keys(tables)
    if "." not in name:  # a misspelt short name: compare with the short names and the keys' last parts
        short = [f"{n} ({SHORT_NAMES[n]})" for n in difflib.get_close_matches(name, list(SHORT_NAMES), n=2, cutoff=0.6)
                 if SHORT_NAMES[n] in keys]
        tails = {k.rsplit(".", 1)[-1]: k for k in reversed(keys)}
        near = [tails[t] for t in difflib.get_close_matches(name, list(tails), n=4, cutoff=0.6)
                if not any(s.endswith(f"({tails[t]})") for s in short)]
        if short or near:
            return ", ".join(dict.fromkeys([*short, *near]))
    close = difflib.get_close_matches(name, keys, n=4, cutoff=0.5)
    if not close:
        tail = name.rsplit(".", 1)[-1]
        close = [k for k in keys if k.rsplit(".", 1)[-1] == tail][:4] or keys[:6]
    return ", ".join(close) if close else "(none)"


def _walk(tables: Mapping[str, Any], key: str, name: str) -> tuple[list[str], Any]:
    """Follow ``key`` through the tables: (canonical path, value); refusals name ``name``."""
    node: Any = tables
    path: list[str] = []
    shown = f"{name!r}" if name == key else f"{name!r} (key {key})"
    for part in key.split("."):
        here = ".".join(path) or "the configuration"
        if isinstance(node, Mapping):
            if part not in node:
                raise _err(f"{shown}: {here} has no key {part!r}; the nearest keys a map can vary are: "
                           f"{_nearest(key, tables)}")
            node = node[part]
            path.append(part)
        elif isinstance(node, (list, tuple)):
            if re.fullmatch(r"[+-]?\d+", part):
                i = int(part)
                if not 1 <= i <= len(node):
                    if len(node) == 0:
                        rule = f"{here} is empty"
                    else:
                        entries = "entry" if len(node) == 1 else "entries"
                        rule = f"{here} has {len(node)} {entries} (positions 1 … {len(node)})"
                    extra = ""
                    if i < 1:
                        extra = "; positions count from 1"
                    elif path and path[-1] in ("amplitudes", "phases"):
                        extra = ("; a map does not add harmonics: write the harmonic into the configuration "
                                 "file (e.g. amplitudes = [0.03, 0.0]) and vary it there")
                    raise _err(f"{shown}: position {i} is out of range: {rule}{extra}")
                node = node[i - 1]
                path.append(str(i))
            else:
                named = [j for j, t in enumerate(node) if isinstance(t, Mapping) and t.get("name") == part]
                if len(named) != 1:
                    names = [str(t.get("name")) for t in node if isinstance(t, Mapping) and "name" in t]
                    known = f"its names are {', '.join(names)}" if names else "its entries have no names"
                    raise _err(f"{shown}: {here} is a list: give a position 1 … {len(node)}, or an entry's name "
                               f"({known}), got {part!r}")
                node = node[named[0]]
                path.append(str(named[0] + 1))
        else:
            raise _err(f"{shown}: {here} is a number, it has no key {part!r}; the nearest keys a map can vary "
                       f"are: {_nearest(key, tables)}")
    return path, node


def _short_on_chain(tables: Mapping[str, Any], name: str) -> str:
    """A short name on a chain: the one table that holds that quantity, or a refusal listing the
    dotted keys to use."""
    model = tables.get("model", {})
    excitation = tables.get("excitation", {})
    elements = list(model.get("elements", []) or [])
    links = list(model.get("links", []) or [])
    torques = list(excitation.get("torques", []) or [])
    if name in ("alpha", "b"):
        cands = [f"model.elements.{i + 1}.{name}" for i, e in enumerate(elements) if _is_number(e.get(name))]
        what, probe = f"elements with `{name}`", f"model.elements.1.{name}"
    elif name == "damping":
        cands = [f"model.links.{i + 1}.damping" for i, t in enumerate(links) if _is_number(t.get("damping"))]
        if len(cands) > 1:
            nonzero = [c for c, t in zip(cands, [t for t in links if _is_number(t.get("damping"))])
                       if float(t["damping"]) != 0.0]
            cands = nonzero if nonzero else cands
        what, probe = "links with a damping", "model.links.1.damping"
    elif name == "mean":
        cands = [f"excitation.torques.{i + 1}.mean" for i, t in enumerate(torques)
                 if _is_number(t.get("mean")) and float(t["mean"]) != 0.0]
        what, probe = "torques with a mean ≠ 0", "excitation.torques.1.mean"
    elif name in ("preload", "friction"):
        cands = [f"model.elements.{i + 1}.{name}" for i, e in enumerate(elements) if e.get(name) is not None]
        what, probe = f"elements with a `{name}`", f"model.elements.1.{name}"
    else:  # amplitude
        cands = [f"excitation.torques.{i + 1}.amplitudes.1" for i, t in enumerate(torques)
                 if t.get("amplitudes") and _is_number(t["amplitudes"][0]) and float(t["amplitudes"][0]) != 0.0]
        what, probe = "torques with a first harmonic ≠ 0", "excitation.torques.1.amplitudes.1"
    if len(cands) == 1:
        return cands[0]
    if not cands:
        raise _err(f"{name!r}: this chain has no {what}; give a dotted key instead, e.g. one of: "
                   f"{_nearest(probe, tables)}")
    hint = ""
    if name == "mean":
        hint = " (the mean torques of a free chain must sum to zero: varying one alone is refused)"
    raise _err(f"{name!r} is ambiguous on this chain, which has {len(cands)} {what}; give the dotted key of the "
               f"one to vary: {', '.join(cands)}{hint}")


def resolve(tables: Mapping[str, Any], name: str) -> str:
    """The canonical dotted key (positions from 1) that ``name`` sets in ``tables``.

    Parameters
    ----------
    tables : mapping
        The configuration tables (a parsed TOML file, or :func:`rattle.io.model_to_toml_dict`).
    name : str
        A short name (:data:`SHORT_NAMES`) or a dotted key; an angle field may be written in
        degrees as in the case file (``model.elastic.b_deg``, ``model.elements.1.breakpoints_deg.4``):
        its key is the field in rad (:func:`parameters` converts the values).

    Raises
    ------
    ConfigError
        Naming ``--vary``: an unknown key (with the nearest valid keys), a key whose value is not
        a number (a table, a list, the elastic ``type``), a position out of range, a short name
        that is ambiguous on a chain (with the dotted keys to use), an analysis setting.
    """
    if not isinstance(name, str) or not name:
        raise _err(f"NAME must be a non-empty string, got {name!r}")
    chain = "inertias" in tables.get("model", {}) if isinstance(tables.get("model"), Mapping) else False
    if name in SHORT_NAMES:
        key = _short_on_chain(tables, name) if chain else SHORT_NAMES[name]
    else:
        key = _radian_key(name)  # an angle written in degrees (FIELD_deg): the field in rad
    if key.split(".")[0] == "analysis":
        raise _err(f"{name!r}: the analysis settings are not design parameters: "
                   f"{_NOT_PARAMETERS['omega']}, and --harmonics for the harmonics")
    path, value = _walk(tables, key, name)
    if name in SHORT_NAMES and isinstance(value, (list, tuple)) and len(value) == 1:
        path, value = [*path, "1"], value[0]  # `friction`: the one level of a law that has one
    field = _not_parameter(path)
    if field is not None:
        raise _err(f"{name!r}: `{'.'.join(path)}` cannot be varied: {_NOT_PARAMETERS[field]}")
    if not _is_number(value):
        if isinstance(value, Mapping):
            inner = [k for k in numeric_keys({"x": value}) if k.count(".") == 1]
            opts = ", ".join(".".join(path) + k[1:] for k in inner) or _nearest(key, tables)
            raise _err(f"{name!r}: `{'.'.join(path)}` is a table, not a number; vary one of its numbers: {opts}")
        if isinstance(value, (list, tuple)):
            n = len(value)
            raise _err(f"{name!r}: `{'.'.join(path)}` is a list, not a number; vary one entry by its position "
                       f"(from 1), e.g. {'.'.join(path)}.1" + (f" … {'.'.join(path)}.{n}" if n > 1 else ""))
        raise _err(f"{name!r}: `{'.'.join(path)}` is {value!r} ({type(value).__name__}), not a number; a map varies "
                   f"numbers only, e.g. {_nearest(key, tables)}")
    return ".".join(path)


def get_value(tables: Mapping[str, Any], key: str) -> float:
    """The number at the canonical dotted ``key`` (from :func:`resolve`)."""
    _, value = _walk(tables, key, key)
    return float(value)


def apply(tables: Mapping[str, Any], values: Mapping[str, float]) -> dict[str, Any]:
    """A deep copy of ``tables`` with every dotted key in ``values`` set to its value.

    Keys are resolved as by :func:`resolve` (short names included). Nothing is ever added: a
    position beyond a list's end is refused (``excitation.amplitudes.2`` on a one-harmonic
    excitation: write the harmonic into the file first), so that a map never changes the
    structure of the configuration it was given. An angle named in degrees (``FIELD_deg``, as the
    case file writes it) sets the field in rad, value · π/180.
    """
    out = copy.deepcopy(dict(tables))
    for name, value in values.items():
        key = resolve(out, name)
        if name not in SHORT_NAMES and _radian_key(name) != name:
            value = math.radians(float(value))
        parts = key.split(".")
        node: Any = out
        for part in parts[:-1]:
            node = node[int(part) - 1] if isinstance(node, list) else node[part]
        last = parts[-1]
        if isinstance(node, tuple):  # pragma: no cover - parsed TOML has lists
            raise _err(f"{name!r}: `{key}` sits in a tuple; give the tables as parsed TOML (lists)")
        if isinstance(node, list):
            node[int(last) - 1] = float(value)
        else:
            node[last] = float(value)
    return out


# --------------------------------------------------------------------------------------------
# Parameters, combinations and their models
# --------------------------------------------------------------------------------------------
def _grid_values(name: str, values: Any) -> tuple[float, ...]:
    """One parameter's values from Python: a real number or a one-dimensional sequence (or array)
    of real numbers — strings, booleans, None, sets (unordered) and mappings are refused naming
    ``vary[NAME]`` and showing the value (TypeError); non-finite or repeated values as ConfigError."""
    where = f"`vary[{name!r}]`"
    if isinstance(values, (str, bytes, Set, Mapping)) or values is None or _is_bool(values):
        raise TypeError(f"{where} must be a number or a sequence of numbers (the grid of {name!r}), got {values!r} "
                        f"({type(values).__name__}); write e.g. {{{name!r}: [0.1, 0.2, 0.3]}}")
    if isinstance(values, np.ndarray):
        if values.dtype.kind not in "iuf" or values.ndim > 1:
            raise TypeError(f"{where} must be a one-dimensional array of real numbers, got an array of dtype "
                            f"{values.dtype} and shape {values.shape}")
        items: list[Any] = list(values.ravel())
    elif isinstance(values, Real):
        items = [values]
    else:
        try:
            items = list(values)
        except TypeError:
            raise TypeError(f"{where} must be a number or a sequence of numbers, got {values!r} "
                            f"({type(values).__name__})") from None
    for v in items:
        if _is_bool(v) or not isinstance(v, Real):
            raise TypeError(f"{where} must hold real numbers, got {v!r} ({type(v).__name__}) in {values!r}; "
                            "strings, booleans and None are not numbers here")
    try:
        return tuple(float(v) for v in items)
    except OverflowError:  # an int beyond the float range
        raise _err(f"{name!r}: every value must be finite, got a number beyond the floating-point range") from None


def _is_bool(value: Any) -> bool:
    return isinstance(value, (bool, np.bool_))


def parameters(tables: Mapping[str, Any], vary: Mapping[str, Sequence[float]] | Sequence[Any]) -> tuple[Parameter, ...]:
    """The :class:`Parameter` objects of ``vary`` (``{NAME: values}``, a sequence of
    ``(NAME, values)`` or of Parameter), each NAME resolved in ``tables``; two NAMEs setting the
    same key are refused, and so is a map of more than :data:`MAX_COMBINATIONS` combinations.

    An angle NAME written in degrees as the case file writes it (``model.elastic.b_deg``,
    ``model.elements.1.breakpoints_deg.4``) takes its values in degrees: they are converted as the
    file converts them, x_rad = x_deg · π/180, and the parameter is the field in rad (its NAME
    without ``_deg``, the files in rad) with ``degrees`` set (reports show degrees).

    Raises
    ------
    TypeError
        ``vary`` is not such a mapping or sequence, a NAME is not a string, or values are not
        real numbers (a string, a boolean, None, a set), naming ``vary`` and showing the value.
    ConfigError
        A rule of the grid or of the names (``--vary …``).
    """
    items: list[tuple[str, Sequence[float]]] = []
    in_degrees: set[str] = set()  # Parameter objects given keep their unit of display
    given: set[str] = set()  # the NAMEs of Parameter objects (their values in rad already)
    typed: dict[str, str] = {}  # NAME → as typed (an angle in degrees: FIELD_deg), for the refusals
    if isinstance(vary, Mapping):
        pairs: list[Any] = list(vary.items())
    elif isinstance(vary, (str, bytes, Set)) or vary is None or not isinstance(vary, Iterable):
        raise TypeError(f"`vary` must be a mapping {{NAME: values}} (or a sequence of (NAME, values) pairs), got "
                        f"{vary!r} ({type(vary).__name__}); write e.g. vary={{'alpha': [0.1, 0.2, 0.3]}}")
    else:
        pairs = []
        for item in vary:
            if isinstance(item, Parameter):
                pairs.append((item.name, item.values))
                given.add(item.name)
                if item.degrees:
                    in_degrees.add(item.name)
            elif isinstance(item, (tuple, list)) and len(item) == 2:
                pairs.append(tuple(item))
            else:
                raise TypeError(f"`vary` must hold (NAME, values) pairs or Parameter objects, got {item!r} "
                                f"({type(item).__name__})")
    for n, v in pairs:
        if not isinstance(n, str):
            raise TypeError(f"`vary` names must be strings (a short name or a dotted key such as 'alpha'), got {n!r} "
                            f"({type(n).__name__})")
        vals = _grid_values(n, v)
        typed[_radian_key(n) if n not in SHORT_NAMES else n] = n
        if n not in SHORT_NAMES and _radian_key(n) != n:
            # an angle in degrees (FIELD_deg, as the case file writes it): converted as the file
            # converts it, to the field in rad (its NAME, its values), shown in degrees
            if n not in given:  # a Parameter holds rad already
                vals = tuple(math.radians(x) for x in vals)
            n = _radian_key(n)
            in_degrees.add(n)
        items.append((n, vals))
    if not items:
        raise _err("is required: give at least one parameter, e.g. --vary alpha=0.1:0.4:7")
    out: list[Parameter] = []
    for name, vals in items:
        if not vals:
            raise _err(f"{name!r}: give at least one value")
        bad = [v for v in vals if not math.isfinite(v)]
        if bad:
            raise _err(f"{name!r}: every value must be finite, got {bad[0]!r}")
        if len(set(vals)) != len(vals):
            raise _err(f"{name!r}: a value is given twice ({vals}); give every value once")
        key = resolve(tables, typed.get(name, name))
        for p in out:
            if p.name == name:
                raise _err(f"gives {name!r} twice; give every parameter once")
            if p.key == key:
                raise _err(f"{p.name!r} and {name!r} both set `{key}`; give it once")
        out.append(Parameter(name=name, key=key, values=vals, degrees=name in in_degrees))
    total = math.prod(len(p.values) for p in out)
    if total > MAX_COMBINATIONS:
        raise _err(f"gives {total} combinations ({' × '.join(str(len(p.values)) for p in out)}), more than "
                   f"{MAX_COMBINATIONS}: each is a frequency response; use fewer values")
    return tuple(out)


#: The angle fields of a law (rad; ``KEY_deg`` in degrees) and the keys of a damper's data sheet
#: that give its breakpoints in degrees.
_ANGLE_FIELDS = ("b", "breakpoints", "gap", "clearance")


def _radian_key(name: str) -> str:
    """``name`` with an angle field written in degrees as the case file writes it (``FIELD_deg``,
    FIELD one of :data:`_ANGLE_FIELDS`: ``model.elements.1.breakpoints_deg.4``) put back to the
    field in rad (``model.elements.1.breakpoints.4``); any other name unchanged. A map varies
    such a key in degrees: its values are converted once, x_rad = x_deg · π/180, and shown in
    degrees."""
    parts = name.split(".")
    out = [p[: -len("_deg")] if p.endswith("_deg") and p[: -len("_deg")] in _ANGLE_FIELDS and k >= 2 else p
           for k, p in enumerate(parts)]
    return ".".join(out) if parts[0] == "model" else name
_DAMPER_DEGREE_KEYS = ("drive_angles_deg", "coast_angles_deg", "free_play_deg")


def given_in_degrees(source: Mapping[str, Any], key: str) -> bool:
    """Whether the angle that the canonical dotted ``key`` sets (``model.elastic.b``,
    ``model.elements.2.breakpoints.3``) was written in degrees in the case file ``source`` (the
    tables as written): its table has ``FIELD_deg``, or it is a damper whose stage angles are in
    degrees. False for every other key."""
    parts = key.split(".")
    if len(parts) < 3 or parts[0] != "model":
        return False
    model = source.get("model") if isinstance(source, Mapping) else None
    if not isinstance(model, Mapping):
        return False
    if parts[1] == "elastic":
        table, field = model.get("elastic"), parts[2]
    elif parts[1] == "elements" and len(parts) >= 4 and parts[2].isdigit():
        elements, i = model.get("elements"), int(parts[2]) - 1
        table = elements[i] if isinstance(elements, list) and 0 <= i < len(elements) else None
        field = parts[3]
    else:
        return False
    if field not in _ANGLE_FIELDS or not isinstance(table, Mapping):
        return False
    if f"{field}_deg" in table:
        return True
    return field == "breakpoints" and table.get("type") == "damper" and any(k in table for k in _DAMPER_DEGREE_KEYS)


def mark_degrees(params: Sequence[Parameter], source: Mapping[str, Any]) -> tuple[Parameter, ...]:
    """``params`` with ``degrees`` set on every angle the case file ``source`` gave in degrees
    (:func:`given_in_degrees`): the report shows those in degrees."""
    import dataclasses

    return tuple(dataclasses.replace(p, degrees=p.degrees or given_in_degrees(source, p.key)) for p in params)


def combinations(params: Sequence[Parameter]) -> Iterator[dict[str, float]]:
    """``{key: value}`` of every combination, in C order (the last parameter varies fastest:
    the order of :meth:`ResponseMap.combinations <rattle.maps.ResponseMap.combinations>`)."""
    for values in itertools.product(*(p.values for p in params)):
        yield {p.key: v for p, v in zip(params, values)}


def _build(tables: Mapping[str, Any], setting: Mapping[str, float], shown: str) -> Any:
    from ..io import config_from_dict  # the configuration reader: numpy and the model

    try:
        return config_from_dict(apply(tables, setting), source_name="<map>").model
    except ConfigError as exc:
        reason = str(exc)
        if reason.startswith("<map>: "):
            reason = reason[len("<map>: "):]
        raise _err(f"{shown}: the model refuses this value: {reason}") from None


#: Most corner combinations :func:`build_all` tries before every combination (2^k for k parameters).
_MAX_CORNERS = 1024


def build_all(tables: Mapping[str, Any], params: Sequence[Parameter]) -> list[Any]:
    """The model of every combination (C order), all built and validated before any work.

    A refused map answers without building every combination's model (up to
    :data:`MAX_COMBINATIONS`, ~0.3 ms each): the rules are checked per axis where they allow it.

    1. Each parameter's smallest and largest value alone (the others at the configuration's
       values): a bound breaks there if anywhere. A refused value is named alone, the first one
       refused in the grid's order.
    2. The corners of the grid (every parameter at its smallest or largest value): a rule that
       joins parameters linearly — breakpoints strictly increasing, a sum, an ordering — breaks
       at some grid point only if it breaks at a corner, since a linear function over a box
       takes its extremes at the corners.
    3. Every value of each parameter alone, then every combination (rules of any other form).

    Raises
    ------
    ConfigError
        ``--vary NAME = VALUE (key): the model refuses this value: <the model's rule>``, or the
        same with every parameter's value of the combination refused.
    """
    built: dict[tuple[tuple[str, float], ...], Any] = {}

    def alone(p: Parameter, v: float) -> Any:
        key = ((p.key, v),)
        if key not in built:
            built[key] = _build(tables, {p.key: v}, f"{p.name} = {_fmt(v)} (`{p.key}`)")
        return built[key]

    def shown(setting: Mapping[str, float]) -> str:
        return " with ".join(f"{p.name} = {_fmt(setting[p.key])}" for p in params)

    for p in params:  # the extremes first: a bound breaks there if anywhere
        try:
            for v in dict.fromkeys((min(p.values), max(p.values))):
                alone(p, v)
        except ConfigError:
            for v in p.values:  # name the first value refused in the grid's order
                alone(p, v)
            raise
    if 1 < len(params) and 2 ** len(params) <= _MAX_CORNERS:
        for corner in itertools.product(*(tuple(dict.fromkeys((min(p.values), max(p.values)))) for p in params)):
            setting = {p.key: v for p, v in zip(params, corner)}
            _build(tables, setting, shown(setting))
    for p in params:
        for v in p.values:
            alone(p, v)
    if len(params) == 1:
        return [built[((params[0].key, v),)] for v in params[0].values]
    return [_build(tables, setting, shown(setting)) for setting in combinations(params)]
