"""Deprecated alias (kept for one release): parameter sets and presets live in :mod:`brakesqueal.model`.

Every name here is a re-export of :mod:`brakesqueal.model` (``Parameters``,
``Preset``, ``ParameterSpace``, ``get_preset``, ``parse_sets``,
``parameters_to_toml``, ``resolve_parameters``); new code should import
them from there.
"""

from __future__ import annotations

from typing import Any

from collections.abc import Sequence

from .model.io import load_parameter_file, parameters_to_toml
from .model.library import get_preset
from .model.parameters import ParameterSpace, Parameters, Preset, Value, parse_sets

__all__ = ["Parameters", "Preset", "ParameterSpace", "Value", "get_preset", "parse_sets", "parameters_to_toml",
           "load_parameter_file", "resolve_parameters", "PRESETS"]


def resolve_parameters(preset: str | None = None, params_file: str | None = None, sets: Sequence[str] = (), *,
                       model: Any = None) -> Parameters:
    """The earlier ``(preset, params_file, sets)`` form of :func:`brakesqueal.model.resolve_parameters`.

    Parameters
    ----------
    preset, params_file, sets, model
        ``--preset``, ``--params``, ``--set`` and ``--model`` (see
        :func:`brakesqueal.model.resolve_space`).

    Returns
    -------
    Parameters
    """
    from .model.options import resolve_parameters as _resolve

    return _resolve(model, preset, params_file, list(sets))


def __getattr__(name: str) -> Any:
    if name == "PRESETS":
        from .model.library import PRESETS

        return PRESETS
    raise AttributeError(f"module 'brakesqueal.parameters' has no attribute {name!r}")
