"""Front ends: one call from a model to a result."""

from ._frequency_response import assemble, frequency_response, start_solution

__all__ = ["frequency_response", "start_solution", "assemble"]
