"""Deprecated alias (kept for one release): parameter sets and presets live in :mod:`brakesqueal.model`.

Every name here is a re-export of :mod:`brakesqueal.model` (``Parameters``,
``Preset``, ``ParameterSpace``, ``get_preset``, ``parse_sets``,
``parameters_to_toml``, ``resolve_parameters``); new code should import
them from there.
"""

from __future__ import annotations

from typing import Any

from .model.io import load_parameter_file, parameters_to_toml
from .model.library import get_preset
from .model.options import resolve_parameters
from .model.parameters import ParameterSpace, Parameters, Preset, Value, parse_sets

__all__ = ["Parameters", "Preset", "ParameterSpace", "Value", "get_preset", "parse_sets", "parameters_to_toml",
           "load_parameter_file", "resolve_parameters"]


def __getattr__(name: str) -> Any:
    if name == "PRESETS":
        from .model.library import PRESETS

        return PRESETS
    raise AttributeError(f"module 'brakesqueal.parameters' has no attribute {name!r}")
