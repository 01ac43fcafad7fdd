"""Checking configuration tables: the checker every table reader uses, and its message helpers.

:class:`_Checker` validates the structure and the TOML types of one configuration (unknown and
missing keys with the nearest known key, numbers, arrays, integers, sub-tables) and re-raises the
model dataclasses' errors with the key the user wrote (:func:`rename_keys`); :func:`_in_base_units`
turns the unit-suffixed keys (``KEY_deg``, and ``KEY_mm``/``KEY_um`` for lengths) into rad and m once,
remembering what the user wrote. The readers of the
model tables (:mod:`._tables`, SPEC §2, §5, §6), of the data-sheet shapes (:mod:`._table_shapes`)
and of the ``[analysis]`` table (:mod:`rattle.io`) share it; it knows no table of its own except
the hint lines ``_EXAMPLES`` they extend.
"""

from __future__ import annotations

import datetime as _dt
import difflib
import json
import math
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

from .errors import ConfigError

_T = TypeVar("_T")

#: Keys holding angles (rad) that may be given in degrees as ``KEY_deg``: in ``[model.elastic]``
#: and every ``[[model.elements]]``.
ANGLE_KEYS = ("b", "breakpoints", "gap")

#: The unit suffixes a key may carry (:func:`_in_base_units`): suffix → (the base unit of the key
#: without it, the suffix's unit, the factor dividing the written value; 0 for degrees, converted by
#: ``math.radians``). Angles as ``KEY_deg``; lengths, where a table has them (a gear pair's
#: ``backlash`` and ``base_radii``), as ``KEY_mm`` or ``KEY_um``.
UNIT_SUFFIXES = {"_deg": ("rad", "degrees", 0.0), "_mm": ("m", "mm", 1e3), "_um": ("m", "µm", 1e6)}

# Example lines for "add e.g. ..." hints: the SPEC §2 example file.
_EXAMPLES = {
    "model": "[model] with inertia = 1.0, damping = 0.05, stiffness = 1.0",
    "model.inertia": "inertia = 1.0",
    "model.damping": "damping = 0.05",
    "model.stiffness": "stiffness = 1.0",
    "model.elastic": '[model.elastic] with type = "clutch", alpha = 0.25, b = 0.174533',
    "model.elastic.type": 'type = "clutch"',
    "model.elastic.alpha": "alpha = 0.25",
    "model.elastic.b": "b = 0.174533",
    "model.elastic.breakpoints": "breakpoints = [-0.3, -0.1, 0.05, 0.2]",
    "model.elastic.slopes": "slopes = [1.0, 0.3, 0.05, 0.3, 1.0]",
    "model.elastic.gap": "gap = 0.01",
    "model.elastic.side": 'side = "positive"',
    "excitation": "[excitation] with mean = 0.05, amplitudes = [0.03]",
    "excitation.mean": "mean = 0.05",
    "excitation.amplitudes": "amplitudes = [0.03]",
    "excitation.phases": "phases = [0.0]",
}


def _example(key: str) -> str:
    return _EXAMPLES.get(key, f"{key.rsplit('.', 1)[-1]} = ...")


# --------------------------------------------------------------------------------------------
# Message helpers
# --------------------------------------------------------------------------------------------
def _show(value: Any) -> str:
    """A value as it would be written in TOML."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    return str(value)


def _kind(value: Any) -> str:
    """The TOML type name of a value, with its article."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, np.integer)):
        return "an integer"
    if isinstance(value, (float, np.floating)):
        return "a float"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, (list, tuple)):
        return "an array"
    if isinstance(value, (_dt.datetime, _dt.date, _dt.time)):
        return "a date/time"
    return f"a {type(value).__name__}"


def _join(names: Sequence[str]) -> str:
    return ", ".join(names) if names else "(none)"


def _did_you_mean(word: str, choices: Sequence[str]) -> str:
    lowered = {c.lower(): c for c in choices}
    match = difflib.get_close_matches(word.lower(), list(lowered), n=1, cutoff=0.6)
    return f"did you mean `{lowered[match[0]]}`? " if match else ""


_BACKTICKED = re.compile(r"`([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)`")

#: A position written after a key as Python indexes it, from 0 (``elements[0]``, ``slopes[2]``).
_POSITION = re.compile(r"(?<=[A-Za-z0-9_])\[(\d+)\]")


def positions_from_one(message: str) -> str:
    """``message`` with every list position after a key counted from 1 and written as the
    dotted keys of ``rattle map --vary`` write it (SPEC §7): ``model.elements[0].b`` becomes
    ``model.elements.1.b``, ``slopes[2]`` becomes ``slopes.3``.

    The configuration readers build their keys with Python's positions (from 0); every message
    about a case file goes through this once (:meth:`_Checker.error`, the warnings of
    :meth:`_Checker.build`), so that an element, a link, a torque or an array entry has the same
    number in every message as in the map's keys and in ``between`` (inertias from 1)."""
    return _POSITION.sub(lambda m: f".{int(m.group(1)) + 1}", message)


def rename_keys(message: str, names: Mapping[str, str]) -> str:
    """Replace backticked field names in ``message`` by the names the user wrote.

    ```inertia``` becomes ```model.inertia```, ```slopes[2]``` becomes
    ```model.elastic.slopes[2]```: the dataclasses name their fields, the configuration
    file and the command line name keys and options.

    Parameters
    ----------
    message : str
        An error message from a dataclass ``__post_init__``.
    names : mapping of str to str
        Field name -> user-facing key or option.

    Returns
    -------
    str
        The message with every known backticked name replaced.
    """

    def repl(m: re.Match[str]) -> str:
        name, index = m.group(1), m.group(2)
        return f"`{names[name]}{index}`" if name in names else m.group(0)

    return _BACKTICKED.sub(repl, message)


class _Checker:
    """Validation of one configuration, with its source name for the messages."""

    def __init__(self, source_name: str) -> None:
        self.source_name = source_name
        #: full key in its base unit -> (the suffixed key the user wrote, the base unit)
        #: (``model.elastic.b`` -> (``model.elastic.b_deg``, ``rad``)), :func:`_in_base_units`
        self.user_keys: dict[str, tuple[str, str]] = {}
        #: table -> {key in its base unit: the suffixed key written there}
        self.converted_keys: dict[str, dict[str, str]] = {}
        #: keys a reader derived from others it has judged itself (a gear pair's mesh element): the
        #: model dataclasses' plausibility warnings about them are not repeated (:meth:`build`)
        self.derived_keys: set[str] = set()

    def error(self, message: str) -> ConfigError:
        return ConfigError(f"{self.source_name}: {self.as_written(message)}")

    def as_written(self, message: str) -> str:
        """``message`` naming every key as the user wrote it: a converted key by its suffixed
        form (``b`` → ``b_deg``, with the unit its value is shown in), positions counted from 1
        (:func:`positions_from_one`)."""
        for key, (written, unit) in self.user_keys.items():  # name the key the user wrote
            message = message.replace(f"`{key}`", f"`{written}` (converted to {unit})")
            message = re.sub(re.escape(f"`{key}[") + r"(\d+)\]`",
                             lambda m: f"`{written}[{m.group(1)}]` (converted to {unit})", message)
            message = message.replace(f"`{key}[", f"`{written}[")
            # the bare field name in the same message (a dataclass's rule naming its other fields)
            field, user_field = key.rsplit(".", 1)[-1], written.rsplit(".", 1)[-1]
            table = key.rsplit(".", 1)[0]
            if field != user_field and (f"`{table}." in message or f"`{written}" in message):
                message = re.sub(rf"(?<![\w.`]){re.escape(field)}(?=\[|\b)(?!_)", user_field, message)
        return positions_from_one(message)

    # --- structure ---------------------------------------------------------------------------
    def table(self, parent: Mapping[str, Any], key: str, full: str) -> Mapping[str, Any]:
        value = parent[key]
        if not isinstance(value, Mapping):
            raise self.error(
                f"`{full}` must be a table, got {_show(value)} ({_kind(value)}); "
                f"write it as a section, e.g. {_example(full)}"
            )
        return value

    def keys(
        self,
        table: Mapping[str, Any],
        where: str,
        allowed: Sequence[str],
        required: Sequence[str],
    ) -> None:
        """Refuse unknown keys, then missing required ones."""
        prefix = f"{where}." if where else ""
        place = f"[{where}]" if where else "the top level"
        for key in table:
            if key not in allowed:
                raise self.error(
                    f"`{prefix}{key}` is not a known key: {place} allows only "
                    f"{_join(allowed)}; {_did_you_mean(str(key), allowed)}"
                    "remove it or correct its spelling"
                )
        for key in required:
            if key not in table:
                raise self.error(
                    f"`{prefix}{key}` is missing: {place} requires {_join(required)}; "
                    f"add e.g. {_example(prefix + key)}"
                )

    # --- TOML value types ----------------------------------------------------------------------
    def number(self, value: Any, key: str) -> None:
        """Check that ``value`` is a TOML number (not a boolean, string, array or table)."""
        example = _example(key.split("[")[0])
        if isinstance(value, bool):
            fix = "booleans are not numbers; write a number"
        elif isinstance(value, (int, np.integer)):
            return  # the range is the dataclasses' rule
        elif isinstance(value, (float, np.floating)):
            if math.isfinite(value):
                return
            # TOML has nan/inf literals; no physical quantity or setting may take them.
            raise self.error(
                f"`{key}` must be a finite number, got {_show(float(value))} (TOML's "
                f"{'not-a-number' if math.isnan(value) else 'infinity'} literal); "
                f"write a finite value, e.g. {example}"
            )
        elif isinstance(value, str):
            fix = "remove the quotes"
        elif isinstance(value, (list, tuple)):
            fix = "give a single number, not an array"
        else:
            fix = "give a number"
        raise self.error(f"`{key}` must be a number, got {_show(value)} ({_kind(value)}); {fix}, e.g. {example}")

    def array(self, value: Any, key: str) -> None:
        """Check that ``value`` is a TOML array of numbers."""
        if not isinstance(value, (list, tuple)):
            raise self.error(
                f"`{key}` must be an array of numbers, got {_show(value)} ({_kind(value)}); "
                f"write it in brackets, e.g. {_example(key)}"
            )
        for i, item in enumerate(value):
            self.number(item, f"{key}[{i}]")

    def string(self, value: Any, key: str) -> None:
        """Check that ``value`` is a TOML string (its choices are the dataclass's rule)."""
        if not isinstance(value, str):
            raise self.error(f"`{key}` must be a string, got {_show(value)} ({_kind(value)}); write it in quotes, "
                             f"e.g. {_example(key)}")

    def value(self, kind: str, value: Any, key: str) -> None:
        """Check ``value`` as a law parameter of ``kind`` "number", "array" or "string"."""
        {"array": self.array, "string": self.string}.get(kind, self.number)(value, key)

    def integer(self, value: Any, key: str) -> None:
        """Check that ``value`` is a TOML integer."""
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise self.error(
                f"`{key}` must be an integer, got {_show(value)} ({_kind(value)}); "
                f"write a whole number without quotes or decimal point, e.g. {_example(key)}"
            )

    # --- construction --------------------------------------------------------------------------
    def build(self, factory: Callable[..., _T], names: Mapping[str, str], /, **kwargs: Any) -> _T:
        """Call ``factory(**kwargs)``; re-raise its ValueError/TypeError with the full key names."""
        try:
            # Warnings of the dataclasses (a clearance that looks like degrees) name their field:
            # re-issue them with the full key, as the errors below.
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                result = factory(**kwargs)
            for w in caught:
                text = rename_keys(str(w.message), names)
                if any(f"`{key}`" in text or f"`{key}[" in text for key in self.derived_keys):
                    continue  # judged by the reader that derived it, naming the user's key
                warnings.warn(f"{self.source_name}: {self.as_written(text)}", w.category, stacklevel=3)
            return result
        except (ValueError, TypeError) as exc:
            message = str(exc)
            renamed = rename_keys(message, names)
            if renamed == message:  # no field named: say which table it came from
                renamed = f"`{next(iter(names.values())).rsplit('.', 1)[0]}`: {message}"
            raise self.error(renamed) from exc


def _in_base_units(check: _Checker, table: Mapping[str, Any], where: str, known: Sequence[str],
                   angles: Sequence[str] = ANGLE_KEYS, lengths: Sequence[str] = ()) -> dict[str, Any]:
    """``table`` with every unit-suffixed key (:data:`UNIT_SUFFIXES`) replaced by its twin in the
    base unit: ``KEY_deg`` (KEY one of ``angles``) by ``KEY`` in rad, ``KEY_mm`` and ``KEY_um`` (KEY
    one of ``lengths``) by ``KEY`` in m — remembering what the user wrote for the messages. A suffix
    on a key of another kind, or two forms of one key, is refused naming both."""
    out = dict(table)
    for key in table:
        suffix = next((x for x in UNIT_SUFFIXES if isinstance(key, str) and key.endswith(x)), None)
        if suffix is None:
            continue
        base, unit, factor = UNIT_SUFFIXES[suffix]
        kind, allowed = ("an angle", angles) if base == "rad" else ("a length", lengths)
        twin = key[: -len(suffix)]
        if twin not in allowed:
            why = (f"`{twin}` is not {kind}" if twin in known else f"`{where}.{twin}` is not a known key")
            same = [a + x for x, (b, _, _) in UNIT_SUFFIXES.items() if b == base for a in allowed]
            here = f" (the `{suffix}`-style keys here are {_join(same)})" if same else ""
            if base == "m" and twin in angles:  # a free play in length where the table takes an angle
                raise check.error(
                    f"`{where}.{key}` is not a known key: `{where}.{twin}` is an angle, in rad (or `{twin}_deg` in "
                    f"degrees), not a length: a free play measured as a length s at a radius r is the angle s / r "
                    f"(rad); write `{twin}` = s / r, or describe a gear mesh by [model.gear_pair], whose `backlash` "
                    "is a length (m, or `backlash_mm`, `backlash_um`)")
            raise check.error(
                f"`{where}.{key}` is not a known key: {why}, so it has no value in {unit}{here}; remove it or correct "
                "its spelling"
            )
        earlier = check.converted_keys.get(where, {}).get(twin)  # KEY_mm and KEY_um both
        if twin in table or earlier is not None:
            other, other_unit = (twin, base) if twin in table else (earlier, UNIT_SUFFIXES[earlier[len(twin):]][1])
            raise check.error(f"`{where}.{other}` and `{where}.{key}` are both given: one {kind.split()[-1]} in "
                              f"{other_unit} and in {unit}; keep one of them")
        value = table[key]
        if isinstance(value, (list, tuple)):
            check.array(value, f"{where}.{key}")
            out[twin] = [_convert(float(v), suffix, factor) for v in value]
        else:
            check.number(value, f"{where}.{key}")
            out[twin] = _convert(float(value), suffix, factor)
        del out[key]
        check.converted_keys.setdefault(where, {})[twin] = key
        check.user_keys[f"{where}.{twin}"] = (f"{where}.{key}", base)
    return out


def _convert(value: float, suffix: str, factor: float) -> float:
    """A value written with ``suffix`` in its base unit: degrees × π/180 (``math.radians``), mm and µm
    divided by 1e3, 1e6 (a correctly rounded division: 60 µm → 6e-05 exactly as written)."""
    return math.radians(value) if suffix == "_deg" else value / factor