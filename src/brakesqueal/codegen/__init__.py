"""Code generation: one engine per model (:func:`build`), one printer, one cache and loader.

Everything compiled or generated from a model (its equations, the batched silent-motion kernel, the stability
kernels of a parameter space, the simulation kernels) is reached through the model's :class:`Engine`, built once
at an entry point (the public API, the command line, the explorer) and passed down as a value.
"""

from .compiled import CONTACT_FIELDS, CompiledModel, compile_model, model_key
from .engine import Capabilities, Engine, build

__all__ = ["CONTACT_FIELDS", "Capabilities", "CompiledModel", "Engine", "build", "compile_model", "model_key"]
