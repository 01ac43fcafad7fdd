"""The console entry point ``rattle`` (pyproject's script ``rattle.cli.main:main``) and
``python -m rattle``.

The command line is split by job:

- :mod:`rattle.cli.app` — the command group: parsing, dispatch, exit statuses, signals;
- :mod:`rattle.cli.checks` — the options' checks at the boundary, before any computation;
- :mod:`rattle.cli.output` — output sets written atomically, figures, metadata, what is printed;
- :mod:`rattle.cli.commands` — one function per command: ``frf``, ``sweep``, ``orbit``,
  ``compare``, ``demo`` (the last runs :mod:`rattle.demo`).
"""

from __future__ import annotations

from .app import EXIT_BAD_INPUT, EXIT_NUMERICAL, EXIT_OK, cli, main
from .commands import DEFAULT_OUTPUT

__all__ = ["cli", "main", "EXIT_OK", "EXIT_NUMERICAL", "EXIT_BAD_INPUT", "DEFAULT_OUTPUT"]


if __name__ == "__main__":  # pragma: no cover
    main()
