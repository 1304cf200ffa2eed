"""Model builder: wobbling-disk models from components (disk, pads, calipers, friction laws)."""

from .assemble import BuiltEquations, build_equations
from .closed import model_closed_form, resolve_model
from .components import Caliper, Disk, FrictionLaw, ModelSpec, Pad
from .library import MODELS, get_model
from .numeric import BuiltLinearModel, CompiledBuiltModel, compile_model, linearize_model, model_values
from .toml_io import load_model, model_to_toml, spec_from_dict, spec_to_dict

__all__ = [
    "BuiltEquations", "build_equations", "Caliper", "Disk", "FrictionLaw", "ModelSpec", "Pad", "MODELS",
    "get_model", "BuiltLinearModel", "CompiledBuiltModel", "compile_model", "linearize_model", "model_values",
    "load_model", "model_to_toml", "spec_from_dict", "spec_to_dict", "model_closed_form", "resolve_model",
]  # fmt: skip
