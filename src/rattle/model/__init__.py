"""Models: elastic laws, excitation and the sub-system equation."""

from ._builders import GearPair, LooseGear, clutch_damper, gear_pair, hub_spline, loose_gear
from ._chain import Chain, Element, Link, Torque
from ._discontinuous import AbstractJumpLaw, Friction, NonsmoothLaw, NonsmoothSystem, PiecewiseJump, Preload
from ._drag import Drag, SpeedLoad
from ._friction_system import FrictionSystem
from ._engine import base_order, engine_speed, engine_torque, firing_orders, forcing_frequency
from ._elastic import ELASTIC_LAWS, AbstractElastic, Backlash, Clutch, Linear, Piecewise, Stages
from ._excitation import Excitation
from ._model import Model, check_analysable_model
from ._paths import SoundPath
from ._system import ReducedElement, System
from .library import backlash_case, reference_case

__all__ = [
    "AbstractElastic", "Linear", "Backlash", "Clutch", "Piecewise", "Stages", "ELASTIC_LAWS",
    "Excitation", "Model", "System", "ReducedElement", "Chain", "Link", "Element", "Torque", "check_analysable_model", "reference_case", "backlash_case",
    "firing_orders", "engine_speed", "forcing_frequency", "base_order", "engine_torque",
    "SoundPath", "Drag", "SpeedLoad",
    "AbstractJumpLaw", "Preload", "PiecewiseJump", "Friction", "NonsmoothLaw", "NonsmoothSystem", "FrictionSystem",
    "clutch_damper", "hub_spline", "gear_pair", "loose_gear", "GearPair", "LooseGear",
]
