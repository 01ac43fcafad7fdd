"""Result objects."""

from ._frequency_response import (
    FRF_COLUMNS, FrequencyResponse, LinearResponse, SpecialPoint, linear_frequency_response,
)

__all__ = ["FrequencyResponse", "SpecialPoint", "LinearResponse", "linear_frequency_response", "FRF_COLUMNS"]
