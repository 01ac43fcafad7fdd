"""The ``rattle`` command line; see :mod:`rattle.cli.main`."""

from .main import cli, main

__all__ = ["cli", "main"]
