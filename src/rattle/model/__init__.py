"""Models: elastic and discontinuous laws, excitation, the single equation, the chain, and the
reader of their configuration tables."""

from ._analysable import check_analysable_model
from ._builders import MAX_BACKLASH_RATIO, GearPair, LooseGear, clutch_damper, gear_pair, hub_spline, loose_gear
from ._chain import Chain, Element, Link, Torque
from ._discontinuous import AbstractJumpLaw, Friction, NonsmoothLaw, PiecewiseJump, Preload
from ._drag import Drag, SpeedLoad
from ._engine import base_order, engine_speed, engine_torque, firing_orders, forcing_frequency
from ._elastic import (
    ELASTIC_LAWS, UNILATERAL_SIDES, AbstractElastic, Backlash, Clutch, Linear, Piecewise, Stages, Unilateral,
)
from ._excitation import Excitation
from ._model import Model
from ._paths import SoundPath, check_source, parse_source
from ._system import ReducedElement, System
from ._stage_matrix import StageConstants, stage_constants, stage_transition, transition_entries, transition_scalar
from ._tables import ModelTables, model_tables  # (loaded here: registers the reader of Model.from_toml and Chain.from_toml)
from .library import backlash_case, reference_case

__all__ = [
    "AbstractElastic", "Linear", "Backlash", "Clutch", "Piecewise", "Unilateral", "UNILATERAL_SIDES", "Stages",
    "ELASTIC_LAWS",
    "Excitation", "Model", "System", "ReducedElement", "Chain", "Link", "Element", "Torque", "check_analysable_model", "reference_case", "backlash_case",
    "firing_orders", "engine_speed", "forcing_frequency", "base_order", "engine_torque",
    "SoundPath", "check_source", "parse_source", "model_tables", "ModelTables", "Drag", "SpeedLoad",
    "AbstractJumpLaw", "Preload", "PiecewiseJump", "Friction", "NonsmoothLaw",
    "clutch_damper", "hub_spline", "gear_pair", "loose_gear", "GearPair", "LooseGear", "MAX_BACKLASH_RATIO",
    "StageConstants", "stage_constants", "stage_transition", "transition_entries", "transition_scalar",
]
