"""Models: elastic laws, excitation and the sub-system equation."""

from ._elastic import ELASTIC_LAWS, AbstractElastic, Backlash, Clutch, Linear, Piecewise, Stages
from ._excitation import Excitation
from ._model import Model
from .library import backlash_case, reference_case

__all__ = [
    "AbstractElastic", "Linear", "Backlash", "Clutch", "Piecewise", "Stages", "ELASTIC_LAWS",
    "Excitation", "Model", "reference_case", "backlash_case",
]
