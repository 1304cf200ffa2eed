"""Deprecated alias (kept for one release): the model builder lives in :mod:`brakesqueal.model`.

Models are described in :mod:`brakesqueal.model` (components, built-in
models, TOML files), assembled by :mod:`brakesqueal.symbolic`, compiled by
:mod:`brakesqueal.codegen` and analysed by :mod:`brakesqueal.analysis` like
every other model; this package only re-exports those names.
"""

from __future__ import annotations

from typing import Any, Mapping

from ..codegen import compile_model
from ..model import (
    MODELS, Caliper, Disk, FrictionLaw, ModelSpec, Pad, get_model, load_model, model_to_toml, resolve_model,
    spec_from_dict, spec_to_dict,
)
from ..symbolic.assemble import build_equations
from ..symbolic.linearize import model_closed_form

__all__ = [
    "build_equations", "Caliper", "Disk", "FrictionLaw", "ModelSpec", "Pad", "MODELS", "get_model", "compile_model",
    "linearize_model", "load_model", "model_to_toml", "spec_from_dict", "spec_to_dict", "model_closed_form",
    "resolve_model",
]  # fmt: skip


def linearize_model(spec: ModelSpec, overrides: Mapping[str, Any] | None = None, *, use_cache: bool = True) -> Any:
    """Deprecated alias: the linear model of ``spec`` at its default values with ``overrides``.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    overrides : Mapping[str, float or str], optional
        Parameter values replacing the model's defaults.
    use_cache : bool, optional
        Use the on-disk code cache.

    Returns
    -------
    LinearModel
        ``brakesqueal.linearize(spec.get_preset().resolve(overrides))``.
    """
    from ..analysis.linear import linearize

    return linearize(spec.get_preset(None).resolve(dict(overrides or {})), use_cache=use_cache)
