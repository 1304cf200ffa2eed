r"""Large models given by coefficient matrices: eigenvalues in a box, and parametric model reduction.

For models of thousands of DOF a dense QZ of the ``2n`` pencil takes minutes
per point (:data:`~brakesqueal.codegen.matrices.MAX_DENSE_DOF`).  Two routes
take such a model to squeal verdicts:

* :func:`box_analysis` — the eigenvalues in a user box (Re range × frequency
  range) by shift-and-invert Arnoldi with residual error bounds
  (:mod:`.sparse_box`): "k unstable modes in [f1, f2] Hz", "stable in box", or
  "undecided" naming what was not resolved;
* :func:`reduce_model` — the published parametric reduction (Gräbner,
  Mehrmann, Quraishi, Schröder & von Wagner, ZAMM 96 (2016) 1388–1405): a
  real basis from the POD of the box eigenvectors sampled along Ω
  (:mod:`.reduction`), every coefficient matrix projected, the coefficient
  law kept; the small model then runs every analysis (maps, crossings,
  critical speeds, sweeps) at dense speed, its error against the full model
  reported at speeds between the samples.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.matrices import MatrixSpec
    from ..model.parameters import Parameters, ParameterSpace
    from .sparse_box import BoxResult

__all__ = ["box_analysis", "reduce_model", "Reduction"]


def _require_matrices(engine: Engine, what: str) -> Any:
    if engine.caps.kind != "matrices":
        raise ParameterError(f"{what} needs a model given by coefficient matrices (brakesqueal import); model "
                             f"'{engine.spec.name}' is a model of disk and pads: use linearize or map")
    return engine


def box_analysis(engine: Engine, params: Parameters, *, re: tuple[float, float], freq: tuple[float, float],
                 max_shifts: int = 40, progress: Callable[[int, int], Any] | None = None) -> BoxResult:
    """Eigenvalues of a matrix model in the box ``re`` × ``freq`` at one parameter set, with error bounds.

    Parameters
    ----------
    engine : Engine
        A matrix model's engine.
    params : Parameters
        The parameter set.
    re : (float, float)
        Range of Re λ [1/s] (e.g. ``(-50, inf)``).
    freq : (float, float)
        Frequency range [Hz], ``0 <= f_lo < f_hi``.
    max_shifts : int
        Most shift-and-invert runs before the box is declared not covered (verdict undecided).
    progress : callable, optional
        ``progress(done, total)`` per shift.

    Returns
    -------
    BoxResult
        See :class:`~.sparse_box.BoxResult` (``verdict`` in words; ``complete`` whether every eigenvalue of
        the box is found).
    """
    from .sparse_box import box_eigenvalues

    _require_matrices(engine, "the box analysis")
    M, D, K = engine.linear_at(params)  # type: ignore[attr-defined]
    return box_eigenvalues(M, D, K, re=re, freq=freq, max_shifts=max_shifts, progress=progress)


@dataclass(frozen=True)
class Reduction:
    """A reduced matrix model and its measured error.

    Attributes
    ----------
    spec : MatrixSpec
        The reduced model: every matrix projected, ``V^T X V``; the same coefficient law and parameters.
    samples : ndarray
        The spin values the basis was sampled at.
    singular_values : ndarray
        Of the snapshot matrix (the kept ones first).
    checks : tuple of dict
        Per check speed (midway between samples): ``Omega``, ``count_full``, ``count_reduced`` (box
        eigenvalues), ``max_rel_error`` and ``max_re_error`` (of every full box eigenvalue against the nearest
        reduced one: relative, and the absolute error of its real part), ``min_abs_re`` (the smallest
        ``|Re λ|`` of the full box: the margin a verdict needs).
    basis : str
        What the POD basis was made of: ``"right and left eigenvectors"`` or ``"right eigenvectors"``.
    """

    spec: MatrixSpec
    samples: np.ndarray
    singular_values: np.ndarray
    checks: tuple[dict[str, float], ...]
    basis: str = "right and left eigenvectors"

    @property
    def reliable(self) -> bool:
        """Whether every check's real-part error is below the smallest ``|Re λ|`` there: the reduced model's
        verdicts then say what the full model's do in the box (``False`` without checks)."""
        return bool(self.checks) and all(c["max_re_error"] < c["min_abs_re"] and c["count_full"] == c["count_reduced"]
                                         for c in self.checks)

    @property
    def max_rel_error(self) -> float:
        """The largest relative eigenvalue error over the checks (NaN without checks)."""
        return max((c["max_rel_error"] for c in self.checks), default=math.nan)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {"model": self.spec.name, "dimension": self.spec.n, "samples": [float(v) for v in self.samples],
                "singular_values": [float(v) for v in self.singular_values[:self.spec.n]],
                "basis": self.basis, "checks": [dict(c) for c in self.checks],
                "max_rel_error": self.max_rel_error,
                "reliable": self.reliable}


def reduce_model(engine: Engine, space: ParameterSpace, samples: Sequence[float], *, re: tuple[float, float],
                 freq: tuple[float, float], r: int | None = None, tol: float = 1e-10, checks: int = 2,
                 name: str | None = None, left: bool = True,
                 progress: Callable[[int, int], Any] | None = None) -> Reduction:
    """Parametric reduction of a matrix model along its spin (POD of the box eigenvectors, right and left,
    Galerkin projection: :mod:`.reduction`).

    Parameters
    ----------
    engine : Engine
        A matrix model's engine.
    space : ParameterSpace
        Its parameter space; every other parameter keeps its value there while Ω is sampled.
    samples : sequence of float
        Spin values [rad/s] the eigenvectors are sampled at (e.g. ``numpy.linspace(2π, 8π, 5)``).
    re, freq : (float, float)
        The box whose eigenvalues the reduced model keeps (:func:`box_analysis`).
    r : int, optional
        Reduced dimension (default: every singular value above ``tol`` of the largest).
    tol : float
        Relative singular-value cut-off.
    checks : int
        How many speeds midway between neighbouring samples the reduced model's box eigenvalues are compared
        with the full model's at (0: none; at most one per gap).
    name : str, optional
        The reduced model's name (default ``<model>-r<r>``).
    left : bool
        The left eigenvectors in the basis too (default; eigenvalue errors the product of the right and left
        vectors' distances from the basis, instead of first order in the right ones'; a larger basis).
    progress : callable, optional
        ``progress(done, total)`` over samples and checks.

    Returns
    -------
    Reduction
    """
    from ..model.matrices import MatrixSpec
    from .crossings import omega_name
    from .reduction import dense_qep_eigenvalues, project, reduce_qep
    from .sparse_box import box_eigenvalues

    _require_matrices(engine, "model reduction")
    spec: MatrixSpec = engine.matrix_spec  # type: ignore[attr-defined]
    spin = omega_name(space)
    w = np.asarray(sorted(float(v) for v in samples))
    if w.size < 1 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise ParameterError(f"the samples of {spin} must be positive numbers; got {list(samples)!r}",
                             parameter="samples")
    total = w.size + max(0, checks)

    def qep(v: float) -> tuple[Any, Any, Any]:
        return engine.linear_at(space.resolve({spin: v}))  # type: ignore[attr-defined, no-any-return]

    def step(done: int) -> Callable[[int, int], Any] | None:
        return None if progress is None else (lambda i, n: progress(done + i, total))

    basis = reduce_qep(qep, list(w), re=re, freq=freq, r=r, tol=tol, left=left, progress=step(0))
    mats = project(basis.V, spec.matrices)
    what = "right and left eigenvectors" if left else "right eigenvectors"
    rdim = basis.r
    red = MatrixSpec(name=name or f"{spec.name}-r{rdim}", matrices=mats, coefficients=dict(spec.coefficients),
                     parameters={k: float(v) for k, v in space.resolve({}).items()}, ranges=dict(spec.ranges),
                     units=dict(spec.units), descriptions=dict(spec.descriptions),
                     dofs=tuple(f"z{i + 1}" for i in range(rdim)), spin=spec.spin, presets=(),
                     description=f"{spec.name} reduced to {rdim} DOF: POD of the {what} in Re lambda in "
                                 f"[{re[0]:g}, {re[1]:g}] 1/s, f in [{freq[0]:g}, {freq[1]:g}] Hz at {spin} = "
                                 + ", ".join(f"{v:.6g}" for v in w),
                     reference="Graebner, Mehrmann, Quraishi, Schroeder, von Wagner, ZAMM 96(12) (2016) 1388-1405")
    rows = []
    if checks > 0:
        # speeds between the samples (the samples themselves would show only the projection's rounding)
        mids = (w[:-1] + w[1:]) / 2 if w.size > 1 else np.array([w[0] * 1.05])
        grid = mids[np.unique(np.linspace(0, mids.size - 1, min(checks, mids.size)).round().astype(int))]
        total = w.size + grid.size
        for i, v in enumerate(grid):
            full = box_eigenvalues(*qep(float(v)), re=re, freq=freq)
            Mr, Dr, Kr = red.at(space.resolve({spin: float(v)}))
            lam = dense_qep_eigenvalues(Mr, Dr, Kr)
            lo, hi, flo, fhi = full.box
            f = np.abs(lam.imag) / (2 * np.pi)
            inside = lam[(lam.real >= lo) & (lam.real <= hi) & (f >= flo) & (f <= fhi) & (lam.imag >= 0)]
            rel, dre = 0.0, 0.0
            for z in full.eigenvalues:
                if not inside.size:
                    rel = dre = math.inf
                    break
                near = inside[np.argmin(np.abs(inside - z))]
                rel, dre = max(rel, abs(near - z) / abs(z)), max(dre, abs(near.real - z.real))
            rows.append({"Omega": float(v), "count_full": int(full.eigenvalues.size),
                         "count_reduced": int(inside.size), "max_rel_error": float(rel),
                         "max_re_error": float(dre),
                         "min_abs_re": float(np.min(np.abs(full.eigenvalues.real))) if full.eigenvalues.size
                         else math.inf, "complete": bool(full.complete)})
            if progress is not None:
                progress(w.size + i + 1, total)
    return Reduction(spec=red, samples=w, singular_values=basis.singular_values, checks=tuple(rows),
                     basis=what)
