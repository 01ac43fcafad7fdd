"""``--html`` of ``rattle frf``, ``rattle compare`` and ``rattle map``: the option, its check and
the writer of the interactive page (``frf.html``, ``compare.html``, ``map.html``, drawn by
:mod:`rattle.plotting`'s ``*_html`` with plotly, an optional dependency: ``rattle[html]``).

The page is one member of the command's output set (:func:`rattle.cli.output.write_set`): it is
staged and moved into place with the other files, written atomically, and a page of an earlier
run is removed when a run writes none, so that no old page sits beside new data.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from ..errors import ConfigError

__all__ = ["html_option", "check_html", "html_writer"]

html_option = click.option(
    "--html", "html", is_flag=True, default=False,
    help="Also write an interactive page (one self-contained HTML file: the plot with hover values and the "
         "summary; needs plotly: pip install \"rattle[html]\").",
)


def check_html(html: bool) -> None:
    """Refuse ``--html`` without plotly (exit 2, before anything is computed or written).

    Looked up, not imported: the command's start-up pays nothing for the option."""
    if html and importlib.util.find_spec("plotly") is None:
        raise ConfigError('`--html` needs plotly, which is not installed: pip install "rattle[html]" '
                          "(or leave --html out)")


def html_writer(build: Callable[[], str]) -> Callable[[Path], Any]:
    """A writer of a page: ``build()`` (the HTML text) written to the staged path atomically."""

    def write(path: Path) -> None:
        from ..files import atomic_write_text

        atomic_write_text(path, build())

    return write
