r"""Models defined by coefficient matrices: imported finite-element squeal models.

A finite-element complex-eigenvalue analysis of a brake gives coefficient
matrices and the law combining them along the disk speed Ω; the TU Berlin
brake of Gräbner, Mehrmann, Quraishi, Schröder & von Wagner (ZAMM 96 (2016)
1388–1405) reads

.. math::

    (\lambda^2 M + \lambda D(\Omega) + K(\Omega))\,x = 0,\quad
    D(\Omega) = D_1 + D_R\,\Omega_\mathrm{ref}/\Omega + D_G\,\Omega/\Omega_\mathrm{ref} + D_4/F_\mathrm{ref},\quad
    K(\Omega) = K_1 + K_R + K_\mathrm{Geo}\,(\Omega/\Omega_\mathrm{ref})^2,

the same speed structure as the paper's eq. (54) (friction damping ∝ 1/Ω,
gyroscopic ∝ Ω, geometric stiffness ∝ Ω²).  A :class:`MatrixSpec` holds
named matrices (dense or ``scipy.sparse``), the three coefficients ``M``,
``D``, ``K`` as sums of matrix terms whose scalar factors are expressions of
the safe grammar (:mod:`.expressions`) over the model's parameters, the
parameters' default values and allowed ranges, and presets.  Its silent
motion is ``x = 0`` for every parameter set (the matrices are already the
linearization); every linear analysis applies, no nonlinear one does.

Model file (``brakesqueal import`` writes one)::

    name = "disk_brake100"
    description = "NLEVP disk_brake100"
    [matrices]
    file = "disk_brake100.mat"          # relative to the model file
    format = "mat"                      # optional (from the extension)
    variables = ["M", "D1", "DR", "DG", "K1", "KR"]   # optional: all of the file
    [coefficients]
    M = "M"
    D = "D1 + DR/Omega + Omega*DG"
    K = "s*(K1 + KR)"
    [parameters]
    Omega = 6.283185307179586           # a number, or {value, min, max, unit, description}
    s = { value = 1, min = 0, description = "friction scale" }

Several files: ``[[matrices]]`` tables, one per file.  The spin is the
parameter named ``Omega`` (``spin = "w"`` at the top level names another).
"""

from __future__ import annotations

import ast
import hashlib
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError
from .expressions import RESERVED_NAMES, _checked_tree, evaluate, evaluate_array, names_in
from .parameters import Preset

__all__ = ["MatrixSpec", "Term", "COEFFICIENTS", "parse_coefficient", "matrix_spec_from_dict",
           "is_matrix_model_data", "matrix_spec_to_dict", "matrix_model_toml", "import_matrices", "write_matrix_model",
           "require_equations"]

#: The coefficients of ``λ² M + λ D + K``.
COEFFICIENTS = ("M", "D", "K")


def require_equations(spec: Any, what: str) -> None:
    """A one-line :class:`~brakesqueal.errors.ParameterError` where ``spec`` is a model given by coefficient
    matrices (a linear model: no nonlinear terms are known) and ``what`` needs its nonlinear equations."""
    if isinstance(spec, MatrixSpec):
        raise ParameterError(f"{what}: model '{spec.name}' is given by coefficient matrices, a linear model with no "
                             "known nonlinear terms; use linearize, eigen, map, crossings, critical-speed, modes, "
                             "sweep, box or reduce")


@dataclass(frozen=True)
class Term:
    """One term ``factor * matrix`` of a coefficient (``factor`` an expression over the parameters)."""

    factor: str
    matrix: str


def _scalar(d: dict[str, str]) -> str | None:
    """The scalar part of a decomposed expression with no matrix term, else ``None``."""
    return d.get("") if set(d) <= {""} else None


def _decompose(node: ast.AST, mats: frozenset[str], expr: str, where: str) -> dict[str, str]:
    """``{matrix name: factor expression}`` (``""``: the scalar part) of a linear combination of matrices."""
    def bad(what: str) -> ParameterError:
        return ParameterError(f"{where}: {what} in {expr!r}; a coefficient is a sum of terms "
                              "factor*MATRIX (factors: expressions of the parameters)")

    if isinstance(node, ast.Constant):
        return {"": repr(float(node.value))}  # type: ignore[arg-type]  # the grammar admits numbers only
    if isinstance(node, ast.Name):
        return {node.id: "1"} if node.id in mats else {"": node.id}
    if isinstance(node, ast.UnaryOp):
        d = _decompose(node.operand, mats, expr, where)
        return d if isinstance(node.op, ast.UAdd) else {k: f"-({v})" for k, v in d.items()}
    if isinstance(node, ast.Call):
        args = [_decompose(a, mats, expr, where) for a in node.args]
        if any(_scalar(a) is None for a in args):
            raise bad(f"a function of a matrix ({ast.unparse(node)})")
        return {"": ast.unparse(node)}
    if isinstance(node, ast.BinOp):
        a = _decompose(node.left, mats, expr, where)
        b = _decompose(node.right, mats, expr, where)
        sa, sb = _scalar(a), _scalar(b)
        if isinstance(node.op, (ast.Add, ast.Sub)):
            sign = "+" if isinstance(node.op, ast.Add) else "-"
            out = dict(a)
            for k, v in b.items():
                out[k] = f"({out[k]}) {sign} ({v})" if k in out else (v if sign == "+" else f"-({v})")
            return out
        if isinstance(node.op, ast.Mult):
            if sa is None and sb is None:
                raise bad(f"a product of two matrices ({ast.unparse(node)})")
            s, other = (sa, b) if sa is not None else (sb, a)
            return {k: f"({s})*({v})" for k, v in other.items()}
        if isinstance(node.op, ast.Div):
            if sb is None:
                raise bad(f"a division by a matrix ({ast.unparse(node)})")
            return {k: f"({v})/({sb})" for k, v in a.items()}
        if sa is None or sb is None:
            raise bad(f"a power of a matrix ({ast.unparse(node)})")
        return {"": f"({sa})**({sb})"}
    raise bad(f"'{ast.unparse(node)}'")  # pragma: no cover - the grammar's checker refuses the rest first


def parse_coefficient(expr: str, matrices: Sequence[str], parameters: Sequence[str], *, where: str) -> tuple[Term, ...]:
    """The terms of a coefficient expression such as ``"D1 + DR/Omega + Omega*DG"``.

    Parameters
    ----------
    expr : str
        A linear combination of matrix names with factors over the parameters (safe grammar, :mod:`.expressions`).
    matrices, parameters : sequence of str
        The model's matrix and parameter names.
    where : str
        How error messages name the coefficient.

    Returns
    -------
    tuple of Term
        One term per matrix (factors of repeated matrices summed).

    Raises
    ------
    ParameterError
        A name that is neither a matrix nor a parameter, a product, quotient, power or function of matrices, or
        a scalar term without a matrix.
    """
    if not isinstance(expr, str) or not expr.strip():
        raise ParameterError(f"{where}: must be a non-empty expression string; got {expr!r}")
    tree, names = _checked_tree(expr, where)
    known = set(matrices) | set(parameters)
    unknown = sorted(names - known)
    if unknown:
        from ..suggest import did_you_mean

        raise ParameterError(f"{where}: unknown name '{unknown[0]}' in {expr!r}{did_you_mean(unknown[0], known)}; "
                             f"matrices: {', '.join(matrices)}; parameters: {', '.join(parameters) or '(none)'}")
    d = _decompose(tree, frozenset(matrices), expr, where)
    if "" in d:
        raise ParameterError(f"{where}: the term '{d['']}' of {expr!r} multiplies no matrix (matrices: "
                             f"{', '.join(matrices)})")
    if not d:
        raise ParameterError(f"{where}: {expr!r} has no matrix term")
    return tuple(Term(factor=v, matrix=k) for k, v in d.items())


def _is_sparse(X: Any) -> bool:
    return hasattr(X, "tocsr") and not isinstance(X, np.ndarray)


@dataclass(frozen=True, eq=False)
class MatrixSpec:
    """A linear model given by coefficient matrices (see the module docstring).

    Parameters
    ----------
    name : str
        Model name.
    matrices : Mapping[str, ndarray or scipy.sparse matrix]
        Square real matrices of one size ``n``, by name.
    coefficients : Mapping[str, str]
        ``M``, ``D`` and ``K`` as expressions (``"D1 + DR/Omega + Omega*DG"``).
    parameters : dict
        Default value of every parameter, in canonical order.
    ranges : Mapping[str, tuple of float]
        Allowed closed interval ``(low, high)`` per parameter (default: the spin ``(0, inf)`` open at 0,
        others any finite value).
    units, descriptions : Mapping[str, str]
        SI unit and one-line description per parameter.
    dofs : tuple of str
        Labels of the ``n`` coordinates (default ``x1 .. xn``).
    spin : str
        The parameter that is the disk speed Ω [rad/s] (critical speeds), ``""`` for none.
    presets : tuple of Preset
        Named templates (every model also has its own name as a preset with every parameter free).
    description, reference : str
        Documentation.
    sources : tuple of dict
        Where the matrices were read (``file``, ``format``, ``variables``), for writing the model file back.

    Raises
    ------
    ParameterError
        Matrices of different sizes, non-square, non-finite, unknown names in the coefficients, defaults outside
        their ranges.
    """

    name: str
    matrices: Mapping[str, Any]
    coefficients: Mapping[str, str]
    parameters: dict[str, float] = field(default_factory=dict)
    ranges: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    units: Mapping[str, str] = field(default_factory=dict)
    descriptions: Mapping[str, str] = field(default_factory=dict)
    dofs: tuple[str, ...] = ()
    spin: str = "Omega"
    presets: tuple[Preset, ...] = ()
    description: str = ""
    reference: str = ""
    sources: tuple[Mapping[str, Any], ...] = ()
    _terms: dict[str, tuple[Term, ...]] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        where = f"model '{self.name}'"
        if not self.matrices:
            raise ParameterError(f"{where}: has no matrices")
        n = None
        for k, X in self.matrices.items():
            if not k.isidentifier() or k in RESERVED_NAMES:
                raise ParameterError(f"{where}: matrix name '{k}' must be an identifier and not one of "
                                     f"{', '.join(sorted(RESERVED_NAMES))}")
            shape = getattr(X, "shape", None)
            if shape is None or len(shape) != 2 or shape[0] != shape[1]:
                raise ParameterError(f"{where}: matrix '{k}' must be square; got shape {shape}")
            if n is None:
                n = int(shape[0])
            elif shape[0] != n:
                raise ParameterError(f"{where}: matrix '{k}' is {shape[0]}x{shape[1]}, the others {n}x{n}")
            data = X.data if _is_sparse(X) else np.asarray(X)
            if not np.all(np.isfinite(data)):
                raise ParameterError(f"{where}: matrix '{k}' has NaN or infinite entries")
        assert n is not None
        if n == 0:
            raise ParameterError(f"{where}: the matrices are empty")
        clash = sorted(set(self.matrices) & set(self.parameters))
        if clash:
            raise ParameterError(f"{where}: '{clash[0]}' is both a matrix and a parameter")
        for p in self.parameters:
            if not p.isidentifier() or p in RESERVED_NAMES:
                raise ParameterError(f"{where}: invalid or reserved parameter name '{p}'")
        object.__setattr__(self, "dofs", tuple(self.dofs) if self.dofs else tuple(f"x{i + 1}" for i in range(n)))
        if len(self.dofs) != n:
            raise ParameterError(f"{where}: {len(self.dofs)} DOF labels for {n} coordinates")
        missing = [c for c in COEFFICIENTS if c not in self.coefficients]
        extra = sorted(set(self.coefficients) - set(COEFFICIENTS))
        if missing or extra:
            raise ParameterError(f"{where}: coefficients must be exactly M, D, K; "
                                 + (f"missing {', '.join(missing)}" if missing else f"unknown '{extra[0]}'"))
        used: set[str] = set()
        for c in COEFFICIENTS:
            terms = parse_coefficient(self.coefficients[c], list(self.matrices), list(self.parameters),
                                      where=f"{where}: coefficient {c}")
            self._terms[c] = terms
            for t in terms:
                used |= names_in(t.factor)
        if self.spin and self.spin not in self.parameters:
            object.__setattr__(self, "spin", "")
        object.__setattr__(self, "presets", tuple(self.presets))
        for name, v in self.parameters.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ParameterError(f"{where}: default value of parameter '{name}' must be a number; got {v!r}")
        from .roles import problems

        bad = problems(self.roles(), {k: float(v) for k, v in self.parameters.items()})
        if bad:
            raise ParameterError(f"{where}: default values: {bad[0][1]}", parameter=bad[0][0])
        seen = {self.name}
        for pr in self.presets:
            if pr.name in seen:
                raise ParameterError(f"{where}: duplicate preset name '{pr.name}'")
            seen.add(pr.name)
            pr.check(self)  # type: ignore[arg-type]  # the parameter interface of a model

    # ---------------------------------------------------------------- structure
    @property
    def n(self) -> int:
        """Number of coordinates."""
        return int(next(iter(self.matrices.values())).shape[0])

    @property
    def sparse(self) -> bool:
        """Whether some matrix is sparse."""
        return any(_is_sparse(X) for X in self.matrices.values())

    @property
    def terms(self) -> Mapping[str, tuple[Term, ...]]:
        """The terms of ``M``, ``D`` and ``K``."""
        return self._terms

    def key(self) -> str:
        """A hash of the matrices, coefficients and parameters (the engine's cache key)."""
        h = hashlib.sha256()
        for k in sorted(self.matrices):
            X = self.matrices[k]
            h.update(k.encode())
            if _is_sparse(X):
                C = X.tocsr()
                C.sort_indices()
                for a in (C.indptr, C.indices, C.data):
                    h.update(np.ascontiguousarray(a).tobytes())
            else:
                h.update(np.ascontiguousarray(X, dtype=float).tobytes())
        h.update(repr((sorted(self.coefficients.items()), list(self.parameters), self.spin)).encode())
        return "mat-" + h.hexdigest()[:20]

    # ---------------------------------------------------------------- the parameter interface of a model
    def parameter_names(self) -> list[str]:
        """Parameter names in canonical order."""
        return list(self.parameters)

    def stiffness_names(self) -> set[str]:
        """No tangential stiffnesses (no compliance packing)."""
        return set()

    def _range(self, name: str) -> tuple[float, float, bool, bool]:
        if name in self.ranges:
            lo, hi = self.ranges[name]
            return float(lo), float(hi), False, False
        if name == self.spin:
            return 0.0, math.inf, True, True
        return -math.inf, math.inf, True, True

    def roles(self) -> Any:
        """:class:`~.roles.ParameterRoles` of the parameters (their ranges and units)."""
        from .roles import ParameterRoles, Role

        uses = {}
        for k in self.parameters:
            lo, hi, lo_open, hi_open = self._range(k)
            role = Role(unit=self.units.get(k, "rad/s" if k == self.spin else ""),
                        description=self.descriptions.get(k, "disk speed" if k == self.spin else "model parameter"),
                        low=lo, high=hi, low_open=lo_open, high_open=hi_open or math.isinf(hi), key=f"matrices.{k}")
            uses[k] = ((role, f"model '{self.name}'"),)
        return ParameterRoles(uses=uses, fixed=(), thickness=(1.0, 1.0), pad_radii=(), disk_radius=math.inf,
                              caliper_dofs=())

    def get_preset(self, name: str | None = None) -> Preset:
        """A preset bound to this model (``None`` or the model's name: every parameter free)."""
        if name is None or name == self.name:
            return Preset(name=self.name, description=f"every parameter of model '{self.name}' free",
                          reference=self.reference, fixed={}, free=dict(self.parameters),
                          tied={}).bind(self)  # type: ignore[arg-type]
        for pr in self.presets:
            if pr.name == name:
                return pr.bind(self)  # type: ignore[arg-type]
        names = ", ".join(self.preset_names())
        raise ParameterError(f"model '{self.name}' has no preset '{name}'; its presets: {names}")

    def preset_names(self) -> list[str]:
        """The model's presets, its own name first."""
        return [self.name, *(p.name for p in self.presets)]

    def describe_parameter(self, name: str) -> str:
        """One-line description of a parameter."""
        return self.descriptions.get(name, "disk speed" if name == self.spin else "model parameter")

    def unit(self, name: str) -> str:
        """SI unit of a parameter."""
        return self.units.get(name, "rad/s" if name == self.spin else "")

    # ---------------------------------------------------------------- evaluation
    def factors(self, arrays: Mapping[str, Any]) -> dict[str, list[tuple[np.ndarray, str]]]:
        """Per coefficient, ``(factor values, matrix name)`` of every term on broadcast parameter arrays."""
        out: dict[str, list[tuple[np.ndarray, str]]] = {}
        env = {k: np.asarray(arrays[k], dtype=float) for k in self.parameters}
        for c in COEFFICIENTS:
            lst = []
            for t in self._terms[c]:
                with np.errstate(all="ignore"):
                    f = evaluate_array(t.factor, env, what=f"coefficient {c}") if names_in(t.factor) else \
                        np.asarray(evaluate(t.factor, {}, what=f"coefficient {c}"))
                lst.append((np.asarray(f, dtype=float), t.matrix))
            out[c] = lst
        return out

    def at(self, values: Mapping[str, float]) -> tuple[Any, Any, Any]:
        """``M, D, K`` at one parameter set (sparse CSR where a term is sparse, else dense)."""
        fs = self.factors({k: float(values[k]) for k in self.parameters})
        out = []
        for c in COEFFICIENTS:
            acc: Any = None
            for f, name in fs[c]:
                X = self.matrices[name]
                term = X * float(f) if _is_sparse(X) else float(f) * np.asarray(X, dtype=float)
                acc = term if acc is None else acc + term
            out.append(acc.tocsr() if _is_sparse(acc) else np.asarray(acc, dtype=float))
        return out[0], out[1], out[2]

    def dense_batch(self, arrays: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Dense ``M, D, K`` of shape ``(N, n, n)`` at ``N`` points (``arrays``: 1-D parameter arrays)."""
        n = self.n
        N = int(np.broadcast_shapes(*(np.shape(arrays[k]) for k in self.parameters))[0]) if self.parameters else 1
        fs = self.factors(arrays)
        dense = {k: (X.toarray() if _is_sparse(X) else np.asarray(X, dtype=float)) for k, X in self.matrices.items()}
        out = []
        for c in COEFFICIENTS:
            acc = np.zeros((N, n, n))
            for f, name in fs[c]:
                acc += np.broadcast_to(f, (N,))[:, None, None] * dense[name]
            out.append(acc)
        return out[0], out[1], out[2]


# ---------------------------------------------------------------- files
def is_matrix_model_data(data: Mapping[str, Any]) -> bool:
    """Whether a model file's table describes a matrix model (it has ``matrices``)."""
    return isinstance(data, Mapping) and "matrices" in data


_TOP = ("name", "description", "reference", "spin", "matrices", "coefficients", "parameters", "presets", "dofs",
        "checksum")
_SOURCE_KEYS = ("file", "format", "variables")


def _parameter_table(raw: Mapping[str, Any], source: str) -> tuple[dict[str, float], dict[str, tuple[float, float]],
                                                                    dict[str, str], dict[str, str]]:
    values: dict[str, float] = {}
    ranges: dict[str, tuple[float, float]] = {}
    units: dict[str, str] = {}
    descs: dict[str, str] = {}
    for k, v in raw.items():
        where = f"{source}: parameters.{k}"
        if isinstance(v, dict):
            unknown = sorted(set(v) - {"value", "min", "max", "unit", "description"})
            if unknown:
                raise ParameterError(f"{where}: unknown key '{unknown[0]}'; valid keys: value, min, max, unit, "
                                     "description")
            if "value" not in v:
                raise ParameterError(f"{where}: needs a value")
            lo = v.get("min", -math.inf)
            hi = v.get("max", math.inf)
            for key, x in (("min", lo), ("max", hi)):
                if isinstance(x, bool) or not isinstance(x, (int, float, str)):
                    raise ParameterError(f"{where}.{key} must be a number; got {x!r}")
            lo_f = evaluate(lo, {}, what=f"{where}.min") if isinstance(lo, str) else float(lo)
            hi_f = evaluate(hi, {}, what=f"{where}.max") if isinstance(hi, str) else float(hi)
            if not lo_f < hi_f:
                raise ParameterError(f"{where}: min {lo_f!r} must be below max {hi_f!r}")
            if "min" in v or "max" in v:
                ranges[k] = (lo_f, hi_f)
            if "unit" in v:
                units[k] = str(v["unit"])
            if "description" in v:
                descs[k] = str(v["description"])
            v = v["value"]
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise ParameterError(f"{where} must be a number or an expression string; got {v!r}")
        values[k] = float(v) if not isinstance(v, str) else evaluate(v, {}, what=where)
    return values, ranges, units, descs


def _read_sources(raw: Any, source: str, base: str) -> tuple[dict[str, Any], tuple[str, ...] | None,
                                                             tuple[dict[str, Any], ...]]:
    from .matrix_files import read_matrix_file

    tables = raw if isinstance(raw, list) else [raw]
    mats: dict[str, Any] = {}
    dofs: tuple[str, ...] | None = None
    kept = []
    for i, t in enumerate(tables):
        where = f"{source}: matrices" + (f"[{i}]" if isinstance(raw, list) else "")
        if not isinstance(t, dict):
            raise ParameterError(f"{where}: must be a table with file, format, variables")
        unknown = sorted(set(t) - set(_SOURCE_KEYS))
        if unknown:
            raise ParameterError(f"{where}: unknown key '{unknown[0]}'; valid keys: {', '.join(_SOURCE_KEYS)}")
        if not isinstance(t.get("file"), str):
            raise ParameterError(f"{where}: needs file = \"PATH\"")
        fmt = t.get("format")
        names = t.get("variables")
        if fmt is not None and not isinstance(fmt, str):
            raise ParameterError(f"{where}: format must be a string")
        if names is not None and not (isinstance(names, list) and all(isinstance(x, str) for x in names)):
            raise ParameterError(f"{where}: variables must be a list of names")
        path = t["file"] if os.path.isabs(t["file"]) else os.path.join(base, t["file"])
        mf = read_matrix_file(path, fmt, names)
        for k, X in mf.matrices.items():
            if k in mats:
                raise ParameterError(f"{where}: matrix '{k}' is read twice (from {t['file']} and before)")
            mats[k] = X
        if mf.dofs is not None:
            dofs = dofs or tuple(mf.dofs)
        kept.append({**t, "file": os.path.abspath(path)})
    return mats, dofs, tuple(kept)


def matrix_spec_from_dict(data: Mapping[str, Any], *, source: str = "model", base: str = ".") -> MatrixSpec:
    """A :class:`MatrixSpec` from a model file's table (layout in the module docstring).

    Parameters
    ----------
    data : Mapping[str, Any]
        The parsed TOML.
    source : str
        How errors name the file.
    base : str
        Folder the matrix file paths are relative to.

    Returns
    -------
    MatrixSpec

    Raises
    ------
    ParameterError
        One line naming ``source`` and the key.
    """
    from ..suggest import did_you_mean
    from .io import presets_from_dict

    unknown = sorted(set(data) - set(_TOP))
    if unknown:
        raise ParameterError(f"{source}: unknown key '{unknown[0]}'{did_you_mean(unknown[0], _TOP)}; valid keys of "
                             f"a matrix model: {', '.join(_TOP)}")
    coeffs = data.get("coefficients")
    if not isinstance(coeffs, dict):
        raise ParameterError(f"{source}: needs a [coefficients] table with M, D and K")
    params = data.get("parameters", {})
    if not isinstance(params, dict):
        raise ParameterError(f"{source}: parameters must be a table")
    values, ranges, units, descs = _parameter_table(params, source)
    mats, dofs, kept = _read_sources(data["matrices"], source, base)
    spin = data.get("spin", "Omega")
    if not isinstance(spin, str):
        raise ParameterError(f"{source}: spin must be a parameter name")
    try:
        spec = MatrixSpec(name=str(data.get("name", "model")), matrices=mats,
                          coefficients={k: v for k, v in coeffs.items()}, parameters=values, ranges=ranges,
                          units=units, descriptions=descs, dofs=dofs or (), spin=spin,
                          presets=presets_from_dict(data, source), description=str(data.get("description", "")),
                          reference=str(data.get("reference", "")), sources=kept)
    except ParameterError as exc:
        msg = str(exc)
        raise ParameterError(msg if msg.startswith(source) else f"{source}: {msg}") from None
    if "checksum" in data and data["checksum"] != spec.key():
        raise ParameterError(f"{source}: the matrix files changed since this model was recorded (checksum "
                             f"{data['checksum']}, now {spec.key()}); start anew (e.g. sweep --overwrite)")
    return spec


def matrix_spec_to_dict(spec: MatrixSpec, *, checksum: bool = False) -> dict[str, Any]:
    """The model file's table of a :class:`MatrixSpec` read from files (its ``sources``); with ``checksum`` also
    the hash of its matrices (:meth:`MatrixSpec.key`), which reading it back checks (a sweep's record)."""
    if not spec.sources:
        raise ParameterError(f"model '{spec.name}' was built in Python: write it first (write_matrix_model) so that "
                             "its matrices are in a file")
    params: dict[str, Any] = {}
    for k, v in spec.parameters.items():
        entry: dict[str, Any] = {"value": v}
        if k in spec.ranges:
            entry["min"], entry["max"] = spec.ranges[k]
        if k in spec.units:
            entry["unit"] = spec.units[k]
        if k in spec.descriptions:
            entry["description"] = spec.descriptions[k]
        params[k] = entry if len(entry) > 1 else v
    d: dict[str, Any] = {"name": spec.name}
    if spec.description:
        d["description"] = spec.description
    if spec.reference:
        d["reference"] = spec.reference
    if spec.spin != "Omega":
        d["spin"] = spec.spin
    d["matrices"] = [dict(s) for s in spec.sources]
    d["coefficients"] = dict(spec.coefficients)
    d["parameters"] = params
    if spec.presets:
        d["presets"] = {p.name: {"description": p.description, "reference": p.reference, "free": dict(p.free),
                                 "fixed": dict(p.fixed), "tied": dict(p.tied), "auxiliary": dict(p.auxiliary)}
                        for p in spec.presets}
    if checksum:
        d["checksum"] = spec.key()
    return d


def matrix_model_toml(spec: MatrixSpec, *, base: str = ".") -> str:
    """The model file of a :class:`MatrixSpec` read from files (round-trips through ``load_model``).

    Parameters
    ----------
    spec : MatrixSpec
        The model (its ``sources`` name the matrix files).
    base : str
        The folder the model file will be written to: file paths are written relative to it where they can be.

    Returns
    -------
    str
    """
    from .io import _toml_key, _toml_value

    d = matrix_spec_to_dict(spec)
    lines = ["# brakesqueal model given by coefficient matrices: (lambda^2 M + lambda D + K) x = 0",
             f"name = {_toml_value(d['name'])}"]
    for k in ("description", "reference", "spin"):
        if k in d:
            lines.append(f"{k} = {_toml_value(d[k])}")
    for src in d["matrices"]:
        path = os.path.abspath(src["file"])
        try:
            rel = os.path.relpath(path, os.path.abspath(base))
        except ValueError:  # another drive
            rel = path
        entry = {**src, "file": rel if not rel.startswith(".." + os.sep + "..") else path}
        lines += ["", "[[matrices]]"] + [f"{k} = {_toml_value(v)}" for k, v in entry.items() if v is not None]
    lines += ["", "[coefficients]"] + [f"{c} = {_toml_value(d['coefficients'][c])}" for c in COEFFICIENTS]
    lines += ["", "[parameters]"] + [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in d["parameters"].items()]
    return "\n".join(lines) + "\n"


def import_matrices(files: Sequence[str], coefficients: Mapping[str, str], *, parameters: Mapping[str, float]
                    | None = None, name: str | None = None, format: str | None = None,
                    variables: Sequence[str] | None = None, spin: str = "Omega") -> MatrixSpec:
    """A matrix model from matrix files and the coefficient law (what ``brakesqueal import`` writes).

    Parameters
    ----------
    files : sequence of str
        Matrix files (:mod:`.matrix_files`; every matrix of every file unless ``variables`` selects).
    coefficients : Mapping[str, str]
        ``M``, ``D``, ``K`` as expressions of the matrix names and parameters.
    parameters : Mapping[str, float], optional
        Default values of parameters; every other name in the coefficients that is not a matrix is a
        parameter with default 1 (the spin ``Omega`` too: give it a value with ``--set``).
    name : str, optional
        Model name (default: the first file's stem).
    format : str, optional
        Format of every file (default: from each file).
    variables : sequence of str, optional
        The matrices to keep (default all).
    spin : str
        The parameter that is the disk speed.

    Returns
    -------
    MatrixSpec
    """
    from .matrix_files import read_matrix_file

    if not files:
        raise ParameterError("import: give at least one matrix file")
    mats: dict[str, Any] = {}
    dofs: tuple[str, ...] | None = None
    sources = []
    for f in files:
        mf = read_matrix_file(f, format, None)
        keep = {k: v for k, v in mf.matrices.items() if variables is None or k in variables}
        for k in keep:
            if k in mats:
                raise ParameterError(f"matrix file '{f}': matrix '{k}' was already read from another file")
        mats.update(keep)
        if mf.dofs is not None and dofs is None:
            dofs = tuple(mf.dofs)
        sources.append({"file": os.path.abspath(f), "format": mf.format,
                        **({"variables": sorted(keep)} if variables is not None else {})})
    if variables is not None:
        missing = [v for v in variables if v not in mats]
        if missing:
            raise ParameterError(f"import: matrix '{missing[0]}' is in none of the files; they hold "
                                 f"{', '.join(sorted(mats)) or 'no matrix'}", parameter="variables")
    params = {k: float(v) for k, v in (parameters or {}).items()}
    for c, expr in coefficients.items():
        if not isinstance(expr, str):
            continue
        try:
            refs = names_in(expr, what=f"coefficient {c}")
        except ParameterError:
            continue  # MatrixSpec reports it with the coefficient's name
        for r in sorted(refs - set(mats)):
            params.setdefault(r, 1.0)
    if spin in params:  # the spin first: it is the usual axis
        params = {spin: params[spin], **{k: v for k, v in params.items() if k != spin}}
    stem = os.path.splitext(os.path.basename(files[0]))[0]
    return MatrixSpec(name=name or stem, matrices=mats, coefficients=dict(coefficients), parameters=params,
                      dofs=dofs or (), spin=spin, sources=tuple(sources),
                      description=f"imported from {', '.join(os.path.basename(f) for f in files)}")


def write_matrix_model(spec: MatrixSpec, path: str) -> MatrixSpec:
    """Write a matrix model: its matrices to ``<stem>.mat`` beside the model file ``path`` (``.toml``).

    Parameters
    ----------
    spec : MatrixSpec
        The model (e.g. built in Python, or a reduced model).
    path : str
        The model file to write (``.toml``); the matrices go to the same folder and stem with ``.mat``.

    Returns
    -------
    MatrixSpec
        The model with its ``sources`` naming the written matrix file.
    """
    import dataclasses

    from ..outputs import atomic_write, check_output
    from .matrix_files import write_matrix_file

    target = check_output(path, what="model file", suffixes=(".toml",))
    mat = str(target.with_suffix(".mat"))
    check_output(mat, what="matrix file", suffixes=(".mat",))
    write_matrix_file(mat, spec.matrices, "mat", dofs=None)
    out = dataclasses.replace(spec, sources=({"file": os.path.abspath(mat), "format": "mat"},), _terms={})
    text = matrix_model_toml(out, base=os.path.dirname(os.path.abspath(str(target))))
    with atomic_write(target, what="model file") as tmp:
        tmp.write_text(text, encoding="utf-8")
    return out
