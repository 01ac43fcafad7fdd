"""Plots (the only matplotlib importer); every function returns (figure, axes)."""

from ._frf import frequency_response_plot

__all__ = ["frequency_response_plot"]
