"""What a model is: components, built-in models, parameters, presets, files (no computer algebra here).

Data flows one way from this package: a :class:`ModelSpec` (components and
default values) and a :class:`Parameters` set (validated by one table of
roles, :mod:`.roles`) are the inputs of the symbolic assembly
(:mod:`brakesqueal.symbolic`) and of every analysis.
"""

from .components import Caliper, Disk, FrictionLaw, ModelSpec, Pad
from .io import load_model, model_to_toml, spec_from_dict, spec_to_dict
from .library import MODELS, get_model, get_preset, preset_names, resolve_model
from .options import resolve_parameters, resolve_space
from .parameters import ParameterSpace, Parameters, Preset, parse_sets

__all__ = [
    "Caliper", "Disk", "FrictionLaw", "ModelSpec", "Pad", "load_model", "model_to_toml", "spec_from_dict",
    "spec_to_dict", "MODELS", "get_model", "get_preset", "preset_names", "resolve_model", "resolve_parameters",
    "resolve_space", "ParameterSpace", "Parameters", "Preset", "parse_sets",
]  # fmt: skip
