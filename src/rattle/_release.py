"""rattle's version, from the package metadata (one place for ``rattle.__version__`` and the
``version`` of every metadata file)."""

from __future__ import annotations

__all__ = ["version"]


def version() -> str:
    """The installed rattle version; ``"0.1.0"`` when running from a source tree that is not installed."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as package_version  # ~50 ms: only when asked

    try:
        return package_version("rattle")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0.1.0"
