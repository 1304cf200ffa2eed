"""Numeric layer: compiled callables generated once from the symbolic model."""

from .compiled import CompiledModel, compiled_model

__all__ = ["CompiledModel", "compiled_model"]
