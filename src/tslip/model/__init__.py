"""The TSLIP model: parameters, controllers, states, terrain, units, equations."""

from .controllers import ConstantTorque, Controller, GlobalPD, LocalVelocity, Passive
from .parameters import PARAMETER_TABLE, Params, preset, presets
from .state import TouchdownState
from .terrain import Terrain

__all__ = [
    "ConstantTorque", "Controller", "GlobalPD", "LocalVelocity", "Passive",
    "PARAMETER_TABLE", "Params", "preset", "presets", "TouchdownState", "Terrain",
]
