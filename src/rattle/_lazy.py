"""Names of a package loaded on first use (PEP 562), for the packages whose import must stay light.

``__getattr__, __dir__ = lazy_exports(__name__, globals(), _LAZY, __all__)`` in a package's
``__init__``: ``_LAZY`` maps every public name to the (relative) module that defines it; a name is
imported when first asked for and then kept in the package's namespace, so later look-ups do not
come back here. ``moved`` names (old home → new module) still answer, with a DeprecationWarning.
"""

from __future__ import annotations

import importlib
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


__all__ = ["lazy_exports"]
