"""Names of a package loaded on first use (PEP 562), for the packages whose import must stay light;
heavy third-party modules loaded on first use (:func:`lazy_module`).

``__getattr__, __dir__ = lazy_exports(__name__, globals(), _LAZY, __all__)`` in a package's
``__init__``: ``_LAZY`` maps every public name to the (relative) module that defines it; a name is
imported when first asked for and then kept in the package's namespace, so later look-ups do not
come back here. ``moved`` names (old home → new module) still answer, with a DeprecationWarning.
"""

from __future__ import annotations

import importlib
import signal
import sys
import types
import warnings
from collections.abc import Callable, Mapping, MutableMapping, Sequence
from typing import Any


def lazy_exports(package: str, namespace: MutableMapping[str, Any], names: Mapping[str, str],
                 exported: Sequence[str], moved: Mapping[str, str] | None = None,
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package`` (module docstring)."""
    moved = dict(moved or {})

    def __getattr__(name: str) -> Any:
        if name in moved:
            warnings.warn(f"`{package}.{name}` is deprecated; import it from {moved[name]}", DeprecationWarning,
                          stacklevel=2)
            return getattr(importlib.import_module(moved[name]), name)
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module, package), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(exported))

    return __getattr__, __dir__


#: The signals that stop a command: held while a lazily loaded module is imported.
_HELD = frozenset(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


def import_held(name: str) -> types.ModuleType:
    """``importlib.import_module(name)`` with SIGINT, SIGTERM and SIGHUP held until it returns.

    A module imported in the middle of a computation (the first friction chain needs
    ``scipy.optimize``'s ``minimize_scalar``) must not be cut in half by an interruption: the
    signal stays pending during the import and its handler runs right after, at a point where the module is whole (a stop raised
    inside another package's import machinery can be turned into a different error there, and
    the stop lost). Where signal masks do not exist (Windows) it is a plain import."""
    module = sys.modules.get(name)
    if module is not None:
        return module
    return call_held(importlib.import_module, name)


def call_held(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` with SIGINT, SIGTERM and SIGHUP held until it returns (:func:`import_held`'s
    rule for any call that must not be cut in half: the first call of a compiled kernel, which
    loads its cached code — or compiles it on a fresh install — in numba's machinery, where a
    stop raised half-way can be swallowed and the run go on). Where signal masks do not exist
    (Windows) it is a plain call."""
    if not _HELD or not hasattr(signal, "pthread_sigmask"):
        return fn(*args)
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
    try:
        return fn(*args)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


class LazyModule:
    """A module imported (by :func:`import_held`) the first time one of its attributes is read:
    ``optimize = lazy_module("scipy.optimize")`` at module level, ``optimize.minimize_scalar(…)``
    where it is needed.
    The command line's start and the computations that never need the module do not pay for
    its import (``scipy.integrate`` with ``scipy.optimize``: some 0.17 s of CPU)."""

    __slots__ = ("_name", "_module")

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: types.ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        module = self._module
        if module is None:
            module = self._module = import_held(self._name)
        return getattr(module, attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name!r}{' (loaded)' if self._module is not None else ''}>"


def lazy_module(name: str) -> Any:
    """A :class:`LazyModule` for ``name`` (typed ``Any``: used as the module itself)."""
    return LazyModule(name)


__all__ = ["LazyModule", "call_held", "import_held", "lazy_exports", "lazy_module"]
