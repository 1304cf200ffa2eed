"""One code generator, one cache and loader: symbolic equations → compiled numeric callables."""

from .compiled import CONTACT_FIELDS, CompiledModel, compile_model, model_key

__all__ = ["CONTACT_FIELDS", "CompiledModel", "compile_model", "model_key"]
