"""Parameter spaces for sweeps: a preset (or a full parameter set) with axes.

A :class:`ParameterSpace` is what ``--preset``, ``--params`` and ``--set``
describe, seen as a function of the names a sweep varies: the settable
(free or fixed) names of the preset, with tied names following them, e.g.
``N0 = 1800/mu`` in ``paper-fig2``.  It resolves numeric points
(:meth:`ParameterSpace.resolve`), vectorized points
(:meth:`ParameterSpace.arrays`) and symbolic ones (:meth:`ParameterSpace.symbolic`)
for the code generators of :mod:`brakesqueal.analysis.kernels`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..expressions import dependency_order
from ..parameters import (
    PARAMETER_NAMES, Parameters, Preset, Value, get_preset, load_parameters, parse_sets,
)

__all__ = ["ParameterSpace", "COMPLIANCE_NAMES", "VECTOR_NAMES"]

#: Names of the compiled parameter vector (``k_ip`` replaced by compliances ``c_ip = 1/k_ip``).
VECTOR_NAMES: tuple[str, ...] = tuple("c_ip1" if n == "k_ip1" else "c_ip2" if n == "k_ip2" else n
                                      for n in PARAMETER_NAMES)
COMPLIANCE_NAMES = {"k_ip1": "c_ip1", "k_ip2": "c_ip2"}


def _float(value: Value) -> float:
    from ..expressions import evaluate

    return evaluate(value, {}, what="value") if isinstance(value, str) else float(value)


@dataclass(frozen=True, eq=False)
class ParameterSpace:
    """A preset (or a complete parameter set) with its values, seen as a function of its settable names.

    Attributes
    ----------
    label : str
        The preset's name, or ``"parameters"`` for a complete parameter set.
    preset : Preset or None
        The preset, if any.
    values : Mapping[str, float or str]
        Overrides of the preset's settable names, or all 17 model parameters.
    """

    label: str
    preset: Preset | None
    values: Mapping[str, Value] = field(default_factory=dict)

    def __hash__(self) -> int:
        return hash(self.key())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ParameterSpace) and self.key() == other.key()

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_preset(cls, name: str = "paper-fig2", overrides: Mapping[str, Value] | None = None
                    ) -> ParameterSpace:
        """A preset with optional overrides (validated)."""
        preset = get_preset(name)
        space = cls(preset.name, preset, dict(overrides or {}))
        space.resolve({})
        return space

    @classmethod
    def from_parameters(cls, params: Parameters) -> ParameterSpace:
        """All 17 model parameters fixed at ``params`` (any of them may be an axis)."""
        return cls("parameters", None, dict(params.as_dict()))

    @classmethod
    def from_options(cls, preset: str | None, params_file: str | None, sets: Sequence[str]
                     ) -> ParameterSpace:
        """Combine ``--preset``, ``--params FILE`` and ``--set NAME=VALUE`` like the other commands."""
        overrides = parse_sets(sets)
        if params_file is None:
            return cls.from_preset(preset or "paper-fig2", overrides)
        file_preset, entries = load_parameters(params_file)
        if preset is not None and file_preset is not None and file_preset.name != preset:
            raise ParameterError(f"parameter file '{params_file}': key 'preset' = "
                                 f"'{file_preset.name}' conflicts with --preset '{preset}'")
        chosen = file_preset or (None if preset is None else get_preset(preset))
        if chosen is None:
            params = Parameters.from_dict({**entries, **overrides}, source=f"parameter file '{params_file}'")
            return cls.from_parameters(params)
        return cls.from_preset(chosen.name, {**entries, **overrides})

    # ---------------------------------------------------------------- queries
    @property
    def tied(self) -> Mapping[str, str]:
        """Tied expressions (empty without a preset)."""
        return {} if self.preset is None else self.preset.tied

    def settable(self) -> tuple[str, ...]:
        """Names an axis may vary: free then fixed names of the preset, or the 17 model names."""
        return PARAMETER_NAMES if self.preset is None else self.preset.settable_names()

    def definitions(self) -> dict[str, Value]:
        """Values of every settable name (defaults with the overrides applied)."""
        if self.preset is None:
            return dict(self.values)
        return {**self.preset.fixed, **self.preset.free, **self.values}

    def value(self, name: str) -> float:
        """Current value of a settable name."""
        self.check_axis(name)
        return _float(self.definitions()[name])

    def check_axis(self, name: str) -> None:
        """Raise ParameterError (one line) unless ``name`` can be swept in this space."""
        if name in self.tied:
            raise ParameterError(
                f"cannot sweep '{name}': it is tied in preset '{self.label}' ({name} = {self.tied[name]}); "
                "sweep one of: " + ", ".join(self.settable()))
        if name not in self.settable():
            raise ParameterError(f"unknown parameter '{name}' for {self._where()}; "
                                 "settable names: " + ", ".join(self.settable()))

    def _where(self) -> str:
        return f"preset '{self.label}'" if self.preset is not None else "the parameter set"

    def resolve(self, changes: Mapping[str, float]) -> Parameters:
        """Validated parameter set with some settable names changed."""
        if self.preset is None:
            return Parameters.from_dict({**self.values, **changes})
        return self.preset.resolve({**self.values, **changes})

    def key(self) -> str:
        """A string identifying the space (for caches)."""
        items = sorted((k, str(v)) for k, v in self.definitions().items())
        return repr((self.label, items, sorted(self.tied.items())))

    # ---------------------------------------------------------------- symbolic / vectorized
    def symbolic(self, axes: Mapping[str, Any]) -> dict[str, Any]:
        """SymPy expressions of the 17 model parameters with ``axes`` (name → symbol) free.

        ``k_ip1``, ``k_ip2`` are returned as compliances under the keys ``c_ip1``,
        ``c_ip2`` (``1/inf`` = 0); numbers are exact rationals of the floats.
        """
        import sympy as sp

        defs = self.definitions()
        names = [*defs, *self.tied]
        loc: dict[str, Any] = {n: sp.Symbol(n) for n in names}
        loc.update(pi=sp.pi, inf=sp.oo, abs=sp.Abs)

        def conv(v: Value) -> Any:
            if isinstance(v, str):
                return sp.sympify(v, locals=loc)
            x = float(v)
            return sp.oo if math.isinf(x) else sp.Rational(x)

        vals: dict[Any, Any] = {}
        for n, v in defs.items():
            vals[n] = axes[n] if n in axes else conv(v)
        for n in dependency_order(dict(self.tied), what=self._where()):
            expr = conv(self.tied[n])
            vals[n] = expr.xreplace({loc[k]: vals[k] for k in vals})
        for n, v in list(vals.items()):
            if isinstance(v, sp.Basic) and v.free_symbols & {loc[k] for k in names}:
                vals[n] = v.xreplace({loc[k]: vals[k] for k in vals})
        out = {}
        for n in PARAMETER_NAMES:
            out[COMPLIANCE_NAMES.get(n, n)] = (1 / vals[n]) if n in COMPLIANCE_NAMES else vals[n]
        return out

    def arrays(self, axes: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The 17 model parameters (compliances for ``k_ip``) evaluated on broadcastable axis arrays."""
        fns = _lambdified(self, tuple(axes))
        shape = np.broadcast_shapes(*(np.shape(a) for a in axes.values())) if axes else ()
        out = {}
        with np.errstate(all="ignore"):
            for n, f in fns.items():
                out[n] = np.broadcast_to(np.asarray(f(*axes.values()), dtype=float), shape)
        return out


@lru_cache(maxsize=64)
def _lambdified(space: ParameterSpace, names: tuple[str, ...]) -> dict[str, Any]:
    import sympy as sp

    syms = {n: sp.Symbol(f"_ax_{n}", real=True) for n in names}
    exprs = space.symbolic(syms)
    args = [syms[n] for n in names]
    return {n: sp.lambdify(args, e, modules="numpy") for n, e in exprs.items()}
