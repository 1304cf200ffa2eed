"""Stability maps, crossings and critical speeds of built models (batched eigenvalues).

Built models have no closed-form quartic, so the verdict comes from the
eigenvalues of the ``2n × 2n`` state matrix with a condition-number error
bound (:func:`~brakesqueal.analysis.robust.matrix_verdicts`: certified Routh
on the interval quartic for ``n = 2``, eigenvalues for any ``n``); points it
cannot decide get status 5 (undecided) and are never stable.  Where the zero
state is the silent motion (checked point by point from the residuals),
``M, D, K`` are evaluated for a whole batch at once with the generated code
bound to NumPy; other points use :func:`~.numeric.linearize_model` one by one.
Crossings along a path are bracketed on a grid of the certified verdict and
refined with Brent's method on the largest real part (``xtol`` 1e-12
relative): unlike the 2-DOF Hurwitz route this is not an exact root
isolation, so two crossings closer than the grid spacing can be missed
(results carry ``exhaustive=False``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from ..errors import ParameterError, SilentMotionError
from .components import ModelSpec
from .library import get_model
from .numeric import compile_model, linearize_model, model_values

__all__ = ["ModelSpace", "model_stability_map", "model_crossings", "model_critical_speeds"]

# status codes shared with brakesqueal.results.StabilityMap
OK, NONTRIVIAL, NO_SILENT, CONTACT_LOSS, INVALID, UNDECIDED_STATUS = 0, 1, 2, 3, 4, 5


@dataclass
class ModelSpace:
    """A built model with fixed parameter overrides; axes vary the remaining names."""

    spec: ModelSpec
    overrides: dict[str, Any] = field(default_factory=dict)
    tied: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        model_values(self.spec, self.overrides)

    @property
    def label(self) -> str:
        """Name used in result metadata."""
        return f"model {self.spec.name}"

    def definitions(self) -> dict[str, Any]:
        """All parameter values (defaults with overrides)."""
        return {**self.spec.parameters, **self.overrides}

    def check_axis(self, name: str) -> None:
        """Raise :class:`ParameterError` if ``name`` is not a parameter of the model."""
        if name not in self.spec.parameters:
            raise ParameterError(f"axis '{name}' is not a parameter of model '{self.spec.name}'; "
                                 f"valid names: {', '.join(self.spec.parameters)}")  # fmt: skip


def _vectorized(cm: Any) -> Any:
    from ..numeric.compiled import _load

    mod = _load(cm.source, "numpy")
    mod.__dict__["exp"] = np.exp
    return mod


def _invalid(spec: ModelSpec, arrays: Mapping[str, np.ndarray]) -> np.ndarray:
    """Vectorized form of the range checks of :func:`~.numeric.model_values` for the axis parameters."""
    from .numeric import _POSITIVE_FIELDS, _roles

    roles = _roles(spec)
    bad = np.zeros(next(iter(arrays.values())).shape, bool)
    for k, v in arrays.items():
        role = roles.get(k, "")
        inf_ok = role in ("k_ip", "radius")
        bad |= np.isnan(v) | (np.isinf(v) & ~(inf_ok & (v > 0)))
        if role in _POSITIVE_FIELDS or role == "k_ip":
            bad |= v <= 0
        elif role in ("k", "d", "k_t", "d_t", "d_ip", "d_c", "k_n", "d_n", "mu", "mu_s"):
            bad |= v < 0
    return bad


def _params(space: ModelSpace, cm: Any, grid: Mapping[str, np.ndarray], size: int) -> list[Any]:
    """Parameter vector (compliances for tangential stiffnesses) for ``size`` points."""
    base = model_values(space.spec, space.overrides)
    vals = {k: np.broadcast_to(np.asarray(grid[k], float), (size,)) if k in grid else v for k, v in base.items()}
    kip = space.spec.stiffness_names()
    with np.errstate(divide="ignore", invalid="ignore"):
        return [np.where(np.isinf(vals[k]), 0.0, 1.0 / np.asarray(vals[k], float)) if k in kip else vals[k]
                for k in cm.param_names]  # fmt: skip


def _matrices_at_zero(space: ModelSpace, cm: Any, vec: Any, p: list[Any], size: int) -> tuple[np.ndarray, ...]:
    """Batched ``M, D, K`` about the zero state (quasi-static pads eliminated) and the residuals there."""
    n, m = cm.n, cm.m
    x0 = [0.0] * (3 * n + m)
    res = np.stack([np.broadcast_to(r, (size,)) for r in vec.residuals(x0, p)], axis=-1)
    jac = np.stack([np.broadcast_to(np.asarray(j, float), (size,)) for j in vec.jacobians(x0, p)], axis=-1)
    jac = jac.reshape(size, n + m, 3 * n + m)
    M, D, K = jac[:, :n, 2 * n:3 * n], jac[:, :n, n:2 * n], jac[:, :n, :n]
    if m:
        with np.errstate(all="ignore"):
            P = np.linalg.solve(np.swapaxes(jac[:, n:, 3 * n:], 1, 2), np.swapaxes(jac[:, :n, 3 * n:], 1, 2))
        P = np.swapaxes(P, 1, 2)
        D = D - P @ jac[:, n:, n:2 * n]
        K = K - P @ jac[:, n:, :n]
    scale = np.abs(jac).max(axis=2) + 1e-300
    return M, D, K, res, scale


def _batch(space: ModelSpace, grid: Mapping[str, np.ndarray], shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Certified ``stable``, ``max_real``, ``frequency``, ``status`` for every point of a grid (broadcastable arrays)."""
    from ..analysis.robust import STABLE, UNDECIDED, matrix_verdicts

    spec = space.spec
    cm = compile_model(spec)
    vec = _vectorized(cm)
    size = int(np.prod(shape))
    flat = {k: np.broadcast_to(np.asarray(v, float), shape).ravel() for k, v in grid.items()}
    status = np.zeros(size, np.int8)
    status[_invalid(spec, flat)] = INVALID
    p = _params(space, cm, flat, size)
    M, D, K, res, scale = _matrices_at_zero(space, cm, vec, p, size)
    trivial = np.all(np.abs(res) <= 1e-12 * scale, axis=1) & (status == OK)
    vals = flat
    max_real = np.full(size, np.nan)
    freq = np.full(size, np.nan)
    stable = np.zeros(size, bool)
    idx = np.flatnonzero(trivial)
    if idx.size:
        codes, mr, fr = matrix_verdicts(M[idx], D[idx], K[idx])
        max_real[idx], freq[idx] = mr, fr
        stable[idx] = codes == STABLE
        status[idx[codes == UNDECIDED]] = UNDECIDED_STATUS
    for i in np.flatnonzero(~trivial & (status == OK)):
        try:
            lm = linearize_model(spec, {**space.overrides, **{k: float(vals[k][i]) for k in grid}})
        except SilentMotionError as exc:
            status[i] = CONTACT_LOSS if "loses contact" in str(exc) else NO_SILENT
            continue
        c, mr, fr = matrix_verdicts(lm.M, lm.D, lm.K)
        max_real[i], freq[i] = mr[0], fr[0]
        stable[i] = c[0] == STABLE
        status[i] = UNDECIDED_STATUS if c[0] == UNDECIDED else NONTRIVIAL
    return {"max_real": max_real.reshape(shape), "frequency": freq.reshape(shape), "status": status.reshape(shape),
            "stable": stable.reshape(shape)}


def model_stability_map(space: ModelSpace, x: Any, y: Any, *, eigen: bool = True, chunk_points: int = 20000,
                        progress: Callable[[float], None] | None = None) -> Any:
    """Stability map of a built model over two of its parameters.

    Parameters
    ----------
    space : ModelSpace
        The model and its fixed parameter overrides.
    x, y : brakesqueal.analysis.maps.Axis
        Horizontal (inner) and vertical (outer) axes, each a parameter of the model.
    eigen : bool
        ``True``: batched eigenvalues give ``max_real`` and ``frequency`` too.
        ``False``: only the verdict, from the eigenvalue-free certified Routh
        classification of :mod:`.fastmap` where the silent motion is trivial
        (``max_real`` and ``frequency`` are NaN there; points it cannot certify
        use eigenvalues); falls back to eigenvalues everywhere when the
        characteristic polynomial has no low-degree structure in the axes or
        the Routh test cannot decide most points of a probe grid (lightly
        damped models with more than two DOF).
    chunk_points : int
        Points per batch of the eigenvalue path.
    progress : callable, optional
        Called with the completed fraction.

    Returns
    -------
    brakesqueal.results.StabilityMap
        Dimensions ``(y.name, x.name)``; points that are not ``status == 0/1``
        are never stable (5: undecided); for status 0/1 with eigenvalues,
        ``stable`` ⇔ ``max_real < 0``.
    """
    from ..results import StabilityMap

    for ax in (x, y):
        space.check_axis(ax.name)
    xs, ys = x.values(), y.values()
    shape = (ys.size, xs.size)
    out = {"max_real": np.full(shape, np.nan), "frequency": np.full(shape, np.nan),
           "status": np.zeros(shape, np.int8)}  # fmt: skip
    stable = np.zeros(shape, bool)
    fast = None if eigen else _fast_classify(space, x, y, xs, ys)
    method = "batched eigenvalues with condition-number bounds (built model)"
    if fast is not None:
        stable, todo = fast
        method = "certified Routh test on the interpolated characteristic polynomial (built model)"
    else:
        todo = np.ones(shape, bool)
    rows = max(1, chunk_points // xs.size)
    for j0 in range(0, ys.size, rows):
        sl = slice(j0, j0 + rows)
        if todo[sl].any():
            yy = ys[sl]
            r = _batch(space, {x.name: xs[None, :], y.name: yy[:, None]}, (yy.size, xs.size))
            mask = todo[sl]
            for k in out:
                out[k][sl][mask] = r[k][mask]
            stable[sl][mask] = r["stable"][mask] & (r["status"][mask] <= NONTRIVIAL)
        if progress:
            progress(min(1.0, (j0 + rows) / ys.size))
    if fast is not None:
        out["status"][~todo] = OK
    sm = StabilityMap.from_arrays(space, y, x, stable=stable, status=out["status"], max_real=out["max_real"],
                                  frequency=out["frequency"], method=method)  # fmt: skip
    sm.data.attrs["criterion"] = ("certified Routh test of det(lambda^2 M + lambda D + K)" if fast is not None
                                  else "eigenvalues of the state matrix with condition-number error bounds")  # fmt: skip
    sm.data.attrs["model"] = json.dumps(space.spec.name)
    return sm


def _fast_classify(space: ModelSpace, x: Any, y: Any, xs: np.ndarray, ys: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray] | None:
    """Routh verdicts where the silent motion is trivial; ``todo`` marks the points left to the eigen path."""
    from . import fastmap

    cm = compile_model(space.spec)
    vec = _vectorized(cm)
    shape = (ys.size, xs.size)
    X, Y = np.broadcast_arrays(xs[None, :], ys[:, None])
    flat = {x.name: X.ravel(), y.name: Y.ravel()}
    size = X.size
    bad = _invalid(space.spec, flat)
    p = _params(space, cm, flat, size)
    x0 = [0.0] * (3 * cm.n + cm.m)
    res = np.stack([np.broadcast_to(r, (size,)) for r in vec.residuals(x0, p)], axis=-1)
    trivial = (np.abs(res).max(axis=1) == 0.0) & ~bad
    todo = ~trivial.reshape(shape)
    if not trivial.any():
        return None

    def mats(xv: np.ndarray, yv: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        pp = _params(space, cm, {x.name: xv, y.name: yv}, xv.size)
        M, D, K, _, _ = _matrices_at_zero(space, cm, vec, pp, xv.size)
        return M, D, K

    # probe: the certified Routh test of a degree-2n polynomial loses about (n - 1) log10(|λ| / |Re λ|)
    # digits for lightly damped modes (Orlando's formula); if it cannot decide most points, use eigenvalues
    px, py = xs[:: max(1, xs.size // 12)], ys[:: max(1, ys.size // 12)]
    probe = fastmap.classify(mats, px, py, x_log=x.log, y_log=y.log)
    if probe is None or np.mean(probe == 2) > 0.25:
        return None
    codes = fastmap.classify(mats, xs, ys, x_log=x.log, y_log=y.log)
    if codes is None:
        return None
    todo |= codes == 2
    return (codes == 1) & ~todo, todo


def _verdicts_along(space: ModelSpace, name: str, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(max_real, stable, decided)`` along a path (NaN / undecided where no silent motion or no verdict)."""
    r = _batch(space, {name: values}, values.shape)
    mr = r["max_real"].copy()
    mr[np.isin(r["status"], (NO_SILENT, CONTACT_LOSS, INVALID))] = np.nan
    ok = r["status"] <= NONTRIVIAL
    return mr, r["stable"] & ok, ok


def _path_crossings(space: ModelSpace, name: str, lo: float, hi: float, log: bool, samples: int,
                    cls: type) -> Any:
    from scipy.optimize import brentq

    space.check_axis(name)
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo) or (log and lo <= 0):
        raise ParameterError(f"path '{name}': need 0 < START < STOP for a log path, START < STOP otherwise")
    grid = np.geomspace(lo, hi, samples) if log else np.linspace(lo, hi, samples)
    r = _batch(space, {name: grid}, grid.shape)
    ok = r["status"] <= NONTRIVIAL
    mr = r["max_real"]
    st = r["stable"] & ok
    if np.any(np.isin(r["status"], (NO_SILENT, CONTACT_LOSS, INVALID))):
        bad = grid[np.isin(r["status"], (NO_SILENT, CONTACT_LOSS, INVALID))][0]
        raise SilentMotionError(f"no valid silent motion at {name} = {bad:g} on the path")
    f = lambda v: float(_verdicts_along(space, name, np.array([v]))[0][0])  # noqa: E731
    found = []
    undecided = []
    for k in range(samples):
        if not ok[k]:
            undecided.append((float(grid[max(k - 1, 0)]), float(grid[min(k + 1, samples - 1)])))
    for k in range(samples - 1):
        a, b = grid[k], grid[k + 1]
        if not (ok[k] and ok[k + 1]) or st[k] == st[k + 1]:
            continue
        root = a
        if mr[k] * mr[k + 1] < 0:
            root = brentq(f, a, b, xtol=1e-14 * abs(b), rtol=1e-12)
        found.append((float(root), "destabilizing" if st[k] else "stabilizing"))
    merged: list[tuple[float, float]] = []
    for a, b in undecided:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    method = f"grid bracketing ({samples} points, certified verdicts) + Brent on max Re(lambda), built model"
    return cls(name, lo, hi, log, bool(st[0]), tuple(found), method, undecided_ranges=tuple(merged),
               exhaustive=False)


def model_crossings(space: ModelSpace, axis: Any, *, samples: int = 400) -> Any:
    """Where the stability of a built model changes along ``axis`` (bracketed, then Brent)."""
    from ..results import CrossingResult

    return _path_crossings(space, axis.name, axis.start, axis.stop, axis.log, samples, CrossingResult)


def model_critical_speeds(space: ModelSpace, lo: float, hi: float, *, samples: int = 400) -> Any:
    """Crossings of a built model along ``Omega`` (the disk's spin parameter)."""
    from ..results import CriticalSpeedResult

    name = space.spec.disk.Omega
    if not isinstance(name, str):
        raise ParameterError(f"model '{space.spec.name}': the disk's Omega is a fixed number, not a parameter")
    return _path_crossings(space, name, lo, hi, True, samples, CriticalSpeedResult)


def bench_model_map(model: str = "eight-dof", size: int = 1000) -> list[Any]:
    """Throughput of built-model maps vs. batched ``numpy.linalg.eigvals``, measured in one run.

    Two paths are timed on a ``size × size`` map over two axes that keep the
    silent motion trivial: the eigenvalue-free Routh classification
    (``eigen=False``) and the batched-eigenvalue Dataset path (on a smaller
    map).  The baseline is one batched ``numpy.linalg.eigvals`` call on as many
    random ``2n × 2n`` matrices.

    Parameters
    ----------
    model : str
        Built-in model name.
    size : int
        The classification map is ``size × size`` points.

    Returns
    -------
    list of BenchResult
    """
    import time

    from ..analysis.maps import Axis
    from ..bench import BenchResult

    spec = get_model(model)
    space = ModelSpace(spec)
    names = [k for k in ("k_c", "k_cn", "k_ip1", "k1") if k in spec.parameters][:2]

    def axes(num: int) -> tuple[Any, Any]:
        a, b = (spec.parameters[k] for k in names)
        return Axis(names[0], a / 10, a * 10, num, log=True), Axis(names[1], b / 10, b * 10, num, log=True)

    model_stability_map(space, *axes(8), eigen=False)  # compile and warm up
    t0 = time.perf_counter()
    fast = model_stability_map(space, *axes(size), eigen=False)
    t_fast = time.perf_counter() - t0
    small = max(2, size // 5)
    t0 = time.perf_counter()
    eig = model_stability_map(space, *axes(small), eigen=True)
    t_eig_map = time.perf_counter() - t0
    n2 = 2 * compile_model(spec).n
    nb = min(small * small, 40000)
    A = np.random.default_rng(0).normal(size=(nb, n2, n2))
    t0 = time.perf_counter()
    np.linalg.eigvals(A)
    base = nb / (time.perf_counter() - t0)
    rate_fast, rate_eig = size * size / t_fast, small * small / t_eig_map
    return [
        BenchResult(f"built-model map ({model}, {n2}x{n2} state matrix), Routh classification", rate_fast,
                    "points/s", base, rate_fast / base,
                    {"points": size * size, "axes": " x ".join(names), "method": fast.data.attrs["method"],
                     "baseline": "one batched numpy.linalg.eigvals call on random matrices of the same size"}),
        BenchResult(f"built-model map ({model}), batched-eigenvalue Dataset path", rate_eig, "points/s", base,
                    rate_eig / base, {"points": small * small, "method": eig.data.attrs["method"]}),
    ]  # fmt: skip
