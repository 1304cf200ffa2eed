"""Polynomial chaos surrogates (issue 27, item 3): a regression on an orthonormal basis of the inputs'
distributions, its leave-one-out error, and the Sobol' indices read off its coefficients.

Standardisation is automatic and the only way in: every input is mapped to its *germ* by the transform its
:class:`~brakesqueal.uq.Distribution` defines, and the basis is orthonormal for the germ's law, so physical units
never enter the fit (a fit in physical units with a monomial or unscaled basis silently gives wrong indices):

============ ================================================ ======== =========================
kind         germ ``xi``                                      law      basis
============ ================================================ ======== =========================
uniform      ``(2 x - lo - hi) / (hi - lo)``                  U(-1, 1) Legendre (orthonormal)
normal       ``(x - mean) / sd``                              N(0, 1)  Hermite (probabilists')
lognormal    ``ln(x / median) / sigma``                       N(0, 1)  Hermite
truncnormal  ``2 F(x) - 1`` (isoprobabilistic, through U(0,1)) U(-1, 1) Legendre
beta         ``2 F(x) - 1``                                   U(-1, 1) Legendre
============ ================================================ ======== =========================

Inputs that cannot be draws of their distribution (outside its support, or germs more than
:data:`MAX_GERM` standard deviations out, or a sample whose germ mean / spread is far from the law's: a typical
sign of inputs given in other units than the distribution's) are refused with one line naming the input.

The basis is evaluated by the three-term recurrences in numpy (a product of univariate values per term), so a
surrogate is cheap to sample: P(squeal) from a million evaluations of a 100-term expansion takes about half a
second.  ``chaospy`` (the reference implementation the tests cross-check against: same regression, same indices)
evaluates the same basis through ``numpoly``, about 50 s per million points for an 84-term expansion.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Union

import numpy as np

from ..errors import ParameterError
from ..validation import validated
from ._distributions import Distribution
from ._indices import SobolEstimate

__all__ = ["PCESurrogate", "fit_pce", "pce_basis_size", "MAX_DEGREE", "MAX_TERMS", "MAX_GERM"]

#: Largest polynomial degree of a surrogate.
MAX_DEGREE = 20
#: Largest number of basis terms.
MAX_TERMS = 20000
#: A germ value beyond this many standard deviations of its law is refused (probability below 1e-15 for a
#: standard normal): the input is in other units than its distribution.
MAX_GERM = 8.0
_LEGENDRE = ("uniform", "truncnormal", "beta")


def _germ_kind(dist: Distribution) -> str:
    return "legendre" if dist.kind in _LEGENDRE else "hermite"


def _to_germ(dist: Distribution, x: np.ndarray) -> np.ndarray:
    """The germ values of physical values ``x`` (see the module docstring)."""
    p = dist.params
    if dist.kind == "uniform":
        return (2 * x - p[0] - p[1]) / (p[1] - p[0])
    if dist.kind == "normal":
        return (x - p[0]) / p[1]
    if dist.kind == "lognormal":
        with np.errstate(all="ignore"):
            return np.log(x / p[0]) / p[1]
    return 2 * np.asarray(dist.frozen().cdf(x), dtype=float) - 1


def _univariate(kind: str, xi: np.ndarray, degree: int) -> np.ndarray:
    """Orthonormal polynomials of degrees ``0..degree`` at ``xi``: shape ``(degree + 1, n)``."""
    out = np.empty((degree + 1, xi.size))
    out[0] = 1.0
    if degree == 0:
        return out
    out[1] = xi
    for k in range(1, degree):  # three-term recurrences of the classical (unnormalised) families
        if kind == "legendre":
            out[k + 1] = ((2 * k + 1) * xi * out[k] - k * out[k - 1]) / (k + 1)
        else:
            out[k + 1] = xi * out[k] - k * out[k - 1]
    if kind == "legendre":  # E[P_k^2] = 1 / (2k + 1) under U(-1, 1)
        out *= np.sqrt(2 * np.arange(degree + 1, dtype=float) + 1)[:, None]
    else:  # E[He_k^2] = k! under N(0, 1)
        out /= np.sqrt(np.array([float(math.factorial(j)) for j in range(degree + 1)]))[:, None]
    return out


def _multi_indices(d: int, degree: int, q: float) -> np.ndarray:
    """Multi-indices of total degree <= ``degree`` (hyperbolic q-norm <= ``degree`` for q < 1), graded order."""
    rows: list[tuple[int, ...]] = []

    def rec(prefix: tuple[int, ...], left: int) -> None:
        if len(prefix) == d:
            rows.append(prefix)
            return
        for a in range(left + 1):
            rec(prefix + (a,), left - a)

    rec((), degree)
    a = np.array(rows, dtype=np.int64).reshape(-1, d)
    if q < 1:
        norm = np.sum(a.astype(float) ** q, axis=1) ** (1 / q)
        a = a[norm <= degree * (1 + 1e-12)]
    order = np.lexsort(tuple(-a[:, i] for i in range(d - 1, -1, -1)) + (a.sum(axis=1),))
    return a[order]


@validated
def pce_basis_size(n_inputs: int, degree: int) -> int:
    """Terms of a total-degree basis: ``C(n_inputs + degree, degree)``.

    Parameters
    ----------
    n_inputs : int
        Number of inputs.
    degree : int
        Total degree.

    Returns
    -------
    int
    """
    return math.comb(n_inputs + degree, degree)


@dataclass(frozen=True)
class PCESurrogate:
    """A polynomial chaos expansion ``y ≈ sum_a c_a Psi_a(xi)`` on an orthonormal basis of the germs.

    Attributes
    ----------
    distributions : tuple of Distribution
        The inputs (their names are the inputs' names).
    degree : int
        Total degree of the candidate basis.
    indices : ndarray, shape (P, d)
        Multi-indices of the terms kept (the constant first).
    coefficients : ndarray, shape (P,)
        Their coefficients.
    n_runs : int
        Runs fitted.
    candidates : int
        Terms of the candidate basis (``P`` of them kept: all of them unless sparse).
    sparse : bool
        Terms selected by orthogonal matching pursuit (least leave-one-out error).
    loo_error : float
        Relative leave-one-out error ``mean((y_i - y_(-i)(x_i))^2) / var(y)`` (closed form through the hat
        matrix of the least-squares fit of the terms kept).
    r2 : float
        Coefficient of determination on the runs.
    """

    distributions: tuple[Distribution, ...]
    degree: int
    indices: np.ndarray
    coefficients: np.ndarray
    n_runs: int
    candidates: int
    sparse: bool
    loo_error: float
    r2: float

    @property
    def names(self) -> tuple[str, ...]:
        """The inputs' names."""
        return tuple(d.name for d in self.distributions)

    @property
    def mean(self) -> float:
        """Mean of the surrogate (its constant coefficient)."""
        const = np.all(self.indices == 0, axis=1)
        return float(self.coefficients[const].sum())

    @property
    def variance(self) -> float:
        """Variance of the surrogate: the sum of the squared non-constant coefficients."""
        const = np.all(self.indices == 0, axis=1)
        return float(np.sum(self.coefficients[~const] ** 2))

    def _share(self, mask: np.ndarray) -> np.ndarray:
        var = self.variance
        if not var > 0:
            return np.full(mask.shape[1], np.nan)
        c2 = self.coefficients**2
        return np.array([float(c2[mask[:, i]].sum()) / var for i in range(mask.shape[1])])

    @property
    def first(self) -> np.ndarray:
        """First-order Sobol' indices, shape (d,): the terms in input ``i`` alone (NaN: constant surrogate)."""
        a = self.indices > 0
        only = a & (a.sum(axis=1) == 1)[:, None]
        return self._share(only)

    @property
    def total(self) -> np.ndarray:
        """Total Sobol' indices, shape (d,): every term in which input ``i`` appears."""
        return self._share(self.indices > 0)

    def germ(self, inputs: Union[Mapping[str, Any], np.ndarray]) -> np.ndarray:
        """Germ values ``(n, d)`` of physical inputs (checked as :func:`fit_pce` checks them, without the sample
        moments)."""
        return _germs(self.distributions, inputs, "PCESurrogate", moments=False)

    def evaluate_germ(self, xi: np.ndarray) -> np.ndarray:
        """The surrogate at germ values ``xi`` of shape ``(n, d)``, in blocks of 8192 points (cache-sized)."""
        xi = np.asarray(xi, dtype=float)
        out = np.empty(xi.shape[0])
        step = 1 << 13
        for s in range(0, xi.shape[0], step):
            out[s:s + step] = self.coefficients @ _design_matrix_t(self.distributions, xi[s:s + step], self.indices)
        return out

    def __call__(self, inputs: Union[Mapping[str, Any], np.ndarray]) -> np.ndarray:
        """The surrogate at physical inputs (a mapping name -> values, or an ``(n, d)`` array in the order of
        :attr:`distributions`)."""
        return self.evaluate_germ(self.germ(inputs))

    def sample(self, n: int = 1 << 20, seed: int = 0) -> np.ndarray:
        """The surrogate at ``n`` random draws of the inputs (drawn as germs: uniform or standard normal)."""
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or not 1 <= n <= 1 << 26:
            raise ParameterError(f"PCESurrogate.sample(): n must be an integer in [1, {1 << 26}]; got {n!r}")
        rng = np.random.default_rng(seed)
        xi = np.empty((n, len(self.distributions)))
        for i, d in enumerate(self.distributions):
            xi[:, i] = rng.uniform(-1, 1, n) if _germ_kind(d) == "legendre" else rng.standard_normal(n)
        return self.evaluate_germ(xi)

    def probability(self, threshold: float = 0.0, n: int = 1 << 20, seed: int = 0) -> float:
        """``P(y > threshold)`` from ``n`` evaluations of the surrogate (P(squeal) for ``y`` = max Re λ).

        The sampling error is at most ``0.5 / sqrt(n)`` (one standard error; 0.0005 for the default ``n``); the
        surrogate's own error near ``y = threshold`` is not in it (see :attr:`loo_error`).
        """
        return float(np.mean(self.sample(n, seed) > threshold))

    def indicator_indices(self, threshold: float = 0.0, n: int = 1 << 15, seed: int = 0) -> SobolEstimate:
        """Sobol' indices of the indicator ``1{y > threshold}`` (squeal, for ``y`` = max Re λ) by a Saltelli design
        of ``(d + 2) n`` evaluations of the surrogate (:func:`~brakesqueal.uq.sobol_estimate`, with intervals).

        The indicator is not a polynomial, so its indices are not read off the expansion; the intervals are the
        sampling error only (not the surrogate's error near ``y = threshold``).
        """
        from scipy.stats import norm

        from ._design import saltelli_design
        from ._indices import sobol_estimate

        d = len(self.distributions)
        u = saltelli_design(n, d, seed).reshape(-1, d)
        xi = np.empty_like(u)
        for i, dist in enumerate(self.distributions):
            xi[:, i] = 2 * u[:, i] - 1 if _germ_kind(dist) == "legendre" else norm.ppf(u[:, i])
        y = (self.evaluate_germ(xi) > threshold).astype(float).reshape(d + 2, n)
        return sobol_estimate(y[0], y[1], y[2:], seed=seed)

    def summary(self) -> dict[str, Any]:
        """JSON form: indices keyed by input, mean, variance, leave-one-out error, basis sizes."""
        first, total = self.first, self.total

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None
        return {"method": "pce-omp" if self.sparse else "pce-ols", "degree": self.degree, "runs": self.n_runs,
                "candidates": self.candidates, "terms": int(self.indices.shape[0]),
                "loo_error": num(self.loo_error), "r2": num(self.r2), "mean": num(self.mean),
                "variance": num(self.variance),
                "first": {n: num(first[i]) for i, n in enumerate(self.names)},
                "total": {n: num(total[i]) for i, n in enumerate(self.names)}}


def _design_matrix(dists: Sequence[Distribution], xi: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """``Psi[j, a] = prod_i psi_{a_i}(xi_ji)``: shape ``(n, P)``."""
    return _design_matrix_t(dists, xi, indices).T


def _design_matrix_t(dists: Sequence[Distribution], xi: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The transposed design matrix ``(P, n)`` (contiguous by term: the cheap layout to build)."""
    n, d = xi.shape
    psi = np.ones((indices.shape[0], n))
    for i in range(d):
        deg = int(indices[:, i].max()) if indices.size else 0
        if deg == 0:
            continue
        uni = _univariate(_germ_kind(dists[i]), xi[:, i], deg)  # (deg + 1, n)
        psi *= uni[indices[:, i]]
    return psi


def _germs(dists: Sequence[Distribution], inputs: Union[Mapping[str, Any], np.ndarray], fn: str,
           moments: bool) -> np.ndarray:
    names = [d.name for d in dists]
    if isinstance(inputs, Mapping):
        missing = [n for n in names if n not in inputs]
        extra = [k for k in inputs if k not in names]
        if missing or extra:
            raise ParameterError(f"{fn}(): inputs must have exactly the distributions' names {names}; "
                                 f"missing {missing}, unknown {extra}")
        cols = [np.asarray(inputs[n], dtype=float).reshape(-1) for n in names]
        if len({c.size for c in cols}) != 1:
            raise ParameterError(f"{fn}(): every input must have the same number of values; got "
                                 f"{ {n: c.size for n, c in zip(names, cols)} }")
        x = np.column_stack(cols) if cols else np.empty((0, 0))
    else:
        x = np.asarray(inputs, dtype=float)
        if x.ndim == 1 and len(dists) == 1:
            x = x[:, None]
        if x.ndim != 2 or x.shape[1] != len(dists):
            raise ParameterError(f"{fn}(): inputs must have shape (runs, {len(dists)}) (one column per "
                                 f"distribution, {names}); got {x.shape}")
    if not np.isfinite(x).all():
        raise ParameterError(f"{fn}(): inputs must be finite numbers")
    xi = np.empty_like(x)
    for i, d in enumerate(dists):
        lo, hi, lo_open, hi_open = d.support
        col = x[:, i]
        tol = 1e-9 * max(1.0, abs(lo) if math.isfinite(lo) else 0.0, abs(hi) if math.isfinite(hi) else 0.0)
        bad = (col < lo - tol) | (col > hi + tol) | ((col <= lo) & lo_open) | ((col >= hi) & hi_open)
        where = (f"input '{d.name}' of {d.describe()}: inputs must be in the units of their distribution "
                 "(the surrogate standardises them itself)")
        if bad.any():
            v = float(col[np.flatnonzero(bad)[0]])
            raise ParameterError(f"{fn}(): {where}; got {v:g}, outside its support "
                                 f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}")
        g = np.clip(_to_germ(d, np.clip(col, lo, hi)), -1.0, 1.0) if _germ_kind(d) == "legendre" \
            else _to_germ(d, col)
        if _germ_kind(d) == "hermite" and np.abs(g).max() > MAX_GERM:
            j = int(np.argmax(np.abs(g)))
            raise ParameterError(f"{fn}(): {where}; got {col[j]:g}, {abs(g[j]):.1f} standard deviations out "
                                 f"(at most {MAX_GERM:g})")
        if moments and g.size >= 2:
            sd0 = 1 / math.sqrt(3) if _germ_kind(d) == "legendre" else 1.0
            m, s = float(np.mean(g)), float(np.std(g))
            if abs(m) > max(0.5, 4 / math.sqrt(g.size)) * sd0 or not 0.5 * sd0 <= s <= 2 * sd0:
                raise ParameterError(f"{fn}(): {where}; its {g.size} values do not look drawn from it (standardised "
                                     f"mean {m / sd0:.2f}, spread {s / sd0:.2f}; expected about 0 and 1)")
        xi[:, i] = g
    return xi


def _loo(q: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares residuals on the orthonormal columns ``q`` and the mean squared leave-one-out residual
    ``mean((r_i / (1 - h_i))^2)`` with the hat matrix's diagonal ``h = sum(q^2, axis=1)``."""
    r = y - q @ (q.T @ y)
    h = np.einsum("ij,ij->i", q, q)
    with np.errstate(all="ignore"):
        loo = float(np.mean((r / (1 - h)) ** 2)) if np.all(h < 1 - 1e-10) else math.inf
    return r, loo


def _omp(psi: np.ndarray, y: np.ndarray, max_terms: int) -> np.ndarray:
    """Orthogonal matching pursuit with leave-one-out selection: terms enter one at a time (the candidate most
    correlated with the residual, the constant first), each active set is refitted by least squares (an
    incrementally orthogonalised basis), and the active set of least leave-one-out error is returned."""
    n, p = psi.shape
    norms = np.linalg.norm(psi, axis=0)
    norms[norms == 0] = np.inf
    q = np.empty((n, 0))
    active: list[int] = []
    best, best_loo, since = [0], math.inf, 0
    r = y.copy()
    for step in range(min(max_terms, p)):
        if step == 0:
            j = 0  # the constant term
        else:
            score = np.abs(psi.T @ r) / norms
            score[active] = -1.0
            j = int(np.argmax(score))
            if score[j] <= 0:
                break
        v = psi[:, j].copy()
        for _ in range(2):  # twice is enough (Kahan, Parlett)
            v -= q @ (q.T @ v)
        nv = float(np.linalg.norm(v))
        if nv <= 1e-10 * (float(np.linalg.norm(psi[:, j])) or 1.0):  # dependent on the active set: skip it
            norms[j] = np.inf
            continue
        q = np.column_stack([q, v / nv])
        active.append(j)
        r, loo = _loo(q, y)
        if loo < best_loo * (1 - 1e-9):
            best, best_loo, since = list(active), loo, 0
        else:
            since += 1
            if since >= max(10, len(active) // 2):  # no improvement for a while: the error only grows from here
                break
    return np.array(sorted(best), dtype=np.int64)


@validated
def fit_pce(inputs: Union[Mapping[str, Any], np.ndarray], outputs: Any, distributions: Sequence[Distribution], *,
            degree: int = 3, sparse: bool = False, q: float = 1.0) -> PCESurrogate:
    """Fit a polynomial chaos surrogate to runs of an expensive quantity.

    The inputs are standardised by their distributions (module docstring): the basis is orthonormal for the
    inputs' laws, so the Sobol' indices are read off the coefficients (``first``: the terms in one input alone;
    ``total``: every term in which it appears), and the same runs given in physical units or as germs give the
    same surrogate.  The runs must be draws of the distributions (a QMC or Latin hypercube design through the
    inverse CDFs is best), in the distributions' units.

    Parameters
    ----------
    inputs : mapping or ndarray
        Physical input values: ``{name: values}`` with the distributions' names, or an array ``(runs, d)`` in
        the order of ``distributions``.
    outputs : array_like, shape (runs,)
        The quantity at the runs (finite).
    distributions : sequence of Distribution
        The inputs' distributions (:class:`~brakesqueal.uq.Distribution`, e.g. a study's ``[distributions]``).
    degree : int
        Total degree of the basis, in ``[1, MAX_DEGREE]``.
    sparse : bool
        Select terms by orthogonal matching pursuit with leave-one-out model selection (the candidate basis may
        then have more terms than runs; at most half as many terms as runs are kept); default: least squares on
        every term (needs at least twice as many runs as terms).
    q : float
        Hyperbolic truncation in ``(0, 1]`` (``q < 1`` drops high-order interactions; 1: total degree).

    Returns
    -------
    PCESurrogate

    Raises
    ------
    ParameterError
        One line naming the argument: a degree outside ``[1, MAX_DEGREE]``, too few runs for the basis, inputs
        outside their distributions' support or not drawn from them (inputs in other units), non-finite values,
        mismatched shapes.
    """
    dists = tuple(distributions)
    if not dists:
        raise ParameterError("fit_pce(): distributions must name at least one input")
    if len({d.name for d in dists}) != len(dists):
        raise ParameterError(f"fit_pce(): distributions must have distinct names; got {[d.name for d in dists]}")
    if not 1 <= degree <= MAX_DEGREE:
        raise ParameterError(f"fit_pce(): degree must be an integer in [1, {MAX_DEGREE}]; got {degree}")
    if not 0 < q <= 1:
        raise ParameterError(f"fit_pce(): q must be in (0, 1]; got {q!r}")
    d = len(dists)
    size = pce_basis_size(d, degree)
    if size > MAX_TERMS:
        raise ParameterError(f"fit_pce(): degree {degree} in {d} inputs has {size} basis terms, more than "
                             f"{MAX_TERMS}; lower the degree or set q < 1")
    y = np.asarray(outputs, dtype=float).reshape(-1) if np.ndim(outputs) else np.asarray([outputs], dtype=float)
    if not np.isfinite(y).all():
        raise ParameterError("fit_pce(): outputs must be finite (leave out the runs without a value)")
    xi = _germs(dists, inputs, "fit_pce", moments=True)
    n = xi.shape[0]
    if y.size != n:
        raise ParameterError(f"fit_pce(): outputs must have one value per run ({n}); got {y.size}")
    idx = _multi_indices(d, degree, q)
    p = idx.shape[0]
    if sparse:
        if n < max(10, d + 2):
            raise ParameterError(f"fit_pce(): runs: {n} are too few for a sparse fit in {d} inputs; give at least "
                                 f"{max(10, d + 2)}")
    elif n < 2 * p:
        raise ParameterError(f"fit_pce(): runs: {n} are too few for degree {degree} in {d} inputs ({p} basis terms): "
                             f"least squares needs at least 2 x {p} = {2 * p}; give more runs, a lower degree, "
                             "or sparse=True")
    psi = _design_matrix(dists, xi, idx)
    keep = _omp(psi, y, max(1, n // 2)) if sparse else np.arange(p)
    a = psi[:, keep]
    qm, rm = np.linalg.qr(a)
    diag = np.abs(np.diag(rm))
    if diag.min() <= 1e-10 * diag.max():
        raise ParameterError(f"fit_pce(): runs: the {n} runs do not determine the {keep.size} basis terms (repeated "
                             "or degenerate inputs); give distinct runs drawn from the distributions")
    coef = np.linalg.solve(rm, qm.T @ y)
    r, loo = _loo(qm, y)
    var = float(np.var(y))
    rel = loo / var if var > 0 else (0.0 if loo == 0 else math.inf)
    r2 = 1 - float(np.mean(r**2)) / var if var > 0 else 1.0
    return PCESurrogate(dists, degree, idx[keep], coef, n, p, sparse, rel, r2)
