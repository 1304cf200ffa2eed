r"""Mode-coupling diagrams: every mode's frequency and real part along a parameter path, tracked by continuity.

Brake squeal is read from how two modes' frequencies merge while their real
parts split (the flutter type of mode coupling).  :func:`modes_along`
linearizes a model at every value of a path, computes the eigenvalues and
eigenvectors of the first-order state matrix and *tracks* the modes from one
value to the next: modes are matched by solving an assignment problem
(:func:`scipy.optimize.linear_sum_assignment`) whose cost combines the loss of
eigenvector correlation (``1 - MAC``, the modal assurance criterion) and the
eigenvalue jump relative to the spectrum's scale.  One mode of each complex
conjugate pair is kept (``Im lambda >= 0``), every real eigenvalue is its own
track: where a pair splits into two real eigenvalues a track opens, where two
merge into a pair one closes (``NaN`` where a track does not exist), so no
eigenvalue is ever dropped.

Marked on the result:

* **coalescences** — two tracked modes whose frequencies meet (to the
  relative tolerance ``rtol``), located on the path grid and refined by
  bisection to the exceptional point, where the frequency gap and the gap of
  the real parts exchange roles;
* **crossings** — values where a mode's real part becomes positive or stops
  being positive (a stability change; ``Re lambda > 1e-12 |lambda|`` counts as
  positive, so undamped modes at rounding level are not crossings; refined by
  bisection).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["ModeTracks", "track_modes", "modes_along"]


@dataclass(frozen=True)
class ModeTracks:
    """Modes tracked along a parameter path.

    Attributes
    ----------
    parameter : str
        The path parameter.
    values : ndarray, shape (n_points,)
        Path values (SI unit of the parameter).
    eigenvalues : ndarray of complex, shape (n_points, n_modes)
        Tracked eigenvalues [1/s]; column ``k`` is one mode along the path.
    continuity : ndarray, shape (n_points, n_modes)
        Modal assurance criterion between consecutive points (1 = same shape).
    coalescences : list of dict
        ``{"value", "modes": (a, b), "frequency_hz"}`` where two modes' frequencies meet.
    crossings : list of dict
        ``{"value", "mode", "direction"}`` where a mode's real part changes sign
        (``"destabilizing"`` or ``"stabilizing"`` in the direction of increasing values).
    log : bool
        Whether the path is logarithmic (for plots).
    model : str
        Model name.
    units : str
        SI unit of the parameter.
    """

    parameter: str
    values: np.ndarray
    eigenvalues: np.ndarray
    continuity: np.ndarray
    coalescences: list[dict[str, Any]] = field(default_factory=list)
    crossings: list[dict[str, Any]] = field(default_factory=list)
    log: bool = False
    model: str = ""
    units: str = ""

    @property
    def frequencies(self) -> np.ndarray:
        """``|Im lambda| / 2 pi`` [Hz], shape (n_points, n_modes)."""
        return np.abs(self.eigenvalues.imag) / (2 * math.pi)

    @property
    def damping_ratios(self) -> np.ndarray:
        """``-Re lambda / |lambda|``."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return -self.eigenvalues.real / np.abs(self.eigenvalues)

    def to_xarray(self) -> Any:
        """Dataset with dims ``(parameter, mode)``: ``real``, ``frequency``, ``damping_ratio``, ``continuity``."""
        import json

        import xarray as xr

        p = self.parameter
        return xr.Dataset(
            {"real": ((p, "mode"), self.eigenvalues.real, {"units": "1/s", "long_name": "Re lambda"}),
             "frequency": ((p, "mode"), self.frequencies, {"units": "Hz", "long_name": "|Im lambda| / 2 pi"}),
             "damping_ratio": ((p, "mode"), self.damping_ratios, {"long_name": "-Re lambda / |lambda|"}),
             "continuity": ((p, "mode"), self.continuity, {"long_name": "MAC with the previous point"})},
            coords={p: (p, self.values, {"units": self.units, "scale": "log" if self.log else "linear"}),
                    "mode": np.arange(self.eigenvalues.shape[1])},
            attrs={"model": self.model, "coalescences": json.dumps(self.coalescences),
                   "crossings": json.dumps(self.crossings)})

    def plot(self, fig: Any = None) -> Any:
        """Mode-coupling diagram: frequency and real part of every mode vs the parameter; returns the figure."""
        from ..plotting import plot_modes

        return plot_modes(self, fig=fig)


def _first_order(lm: Any) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and right eigenvectors of a linear model (or an ``(M, D, K)`` triple)."""
    import scipy.linalg

    if isinstance(lm, tuple):
        from .linear import state_matrix

        A = state_matrix(*lm)
    else:
        A = lm.A
    w, v = scipy.linalg.eig(A)
    keep = w.imag >= -1e-12 * np.maximum(np.abs(w), 1.0)
    # one of each conjugate pair; real eigenvalues are all kept
    w, v = w[keep], v[:, keep]
    order = np.argsort(np.abs(w.imag) + 1e-9 * w.real)
    return w[order], v[:, order]


def _mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    return num / np.where(den > 0, den, 1.0)


class _Ticker:
    """Reports the completed fraction (monotone, at most every 0.1 s, and 1.0 at the end) to a callback."""

    def __init__(self, callback: Callable[[float], None] | None) -> None:
        import time

        self.callback, self.clock, self.frac, self.last = callback, time.monotonic, 0.0, -math.inf

    def __call__(self, frac: float, *, force: bool = False) -> None:
        if self.callback is None:
            return
        self.frac = max(self.frac, min(max(float(frac), 0.0), 1.0))
        now = self.clock()
        if force or now - self.last >= 0.1:
            self.last = now
            self.callback(self.frac)


def track_modes(values: Sequence[float] | np.ndarray, linear: Callable[[float], Any], *, parameter: str = "p",
                log: bool = False, model: str = "", units: str = "", rtol: float = 1e-3,
                progress: Callable[[float], None] | None = None) -> ModeTracks:
    """Track every mode along a path (the core of :func:`modes_along`).

    Parameters
    ----------
    values : sequence of float
        Path values, monotone.
    linear : callable
        ``linear(value)`` → a :class:`~brakesqueal.analysis.linear.LinearModel` or ``(M, D, K)``.
    parameter, model, units : str
        Labels.
    log : bool
        Logarithmic path (bisection midpoints are geometric).
    rtol : float
        Relative frequency gap below which two modes count as coalesced.
    progress : callable, optional
        Called with the completed fraction in [0, 1] (at most every 0.1 s, and with 1.0 at the end): the
        points of the path, then the bisections that locate crossings and coalescences.

    Returns
    -------
    ModeTracks
    """
    from scipy.optimize import linear_sum_assignment

    tick = _Ticker(progress)
    vals = np.asarray(values, dtype=float)
    w0, v0 = _first_order(linear(float(vals[0])))
    # at most every eigenvalue real: 2n columns; a complex pair that splits into two real eigenvalues opens a
    # track, two real eigenvalues that merge into a pair close one (NaN where a track does not exist)
    width = 2 * w0.size
    lam = np.full((vals.size, width), complex(np.nan, np.nan), dtype=complex)
    cont = np.full((vals.size, width), np.nan)
    lam[0, :w0.size] = w0
    cont[0, :w0.size] = 1.0
    active = list(range(w0.size))  # column of each eigenvalue of the previous point
    prev_w, prev_v = w0, v0
    for i in range(1, vals.size):
        tick(i / (vals.size + 1))  # the bisections after the path take the rest
        w, v = _first_order(linear(float(vals[i])))
        scale = max(float(np.abs(prev_w).max()), float(np.abs(w).max()), 1e-300)
        # the pads' states come and go along a path (kept where the silent motion tilts, not at a point where it
        # is trivial): compare the mechanical part [q, qdot] of the vectors, which both forms share
        rows_common = min(prev_v.shape[0], v.shape[0])
        prev_v, v = prev_v[:rows_common], v[:rows_common]
        cost = (1.0 - _mac(prev_v, v)) + np.abs(prev_w[:, None] - w[None, :]) / scale
        rows, cols = linear_sum_assignment(cost)
        col_of = np.full(w.size, -1)
        col_of[cols] = np.asarray(active)[rows]
        free = [c for c in range(width) if c not in set(col_of[col_of >= 0].tolist())
                and np.all(np.isnan(lam[:i, c]))]
        for j in np.flatnonzero(col_of < 0):  # new tracks (a pair split) in unused columns
            col_of[j] = free.pop(0)
        lam[i, col_of] = w
        mac = _mac(prev_v, v)
        for r, c in zip(rows, cols):
            cont[i, col_of[c]] = mac[r, c]
        active = col_of.tolist()
        prev_w, prev_v = w, v
    used = ~np.all(np.isnan(lam), axis=0)
    lam, cont = lam[:, used], cont[:, used]
    n_modes = lam.shape[1]

    def mid(a: float, b: float) -> float:
        return math.sqrt(a * b) if log and a > 0 and b > 0 else 0.5 * (a + b)

    crossings = []
    tol = 1e-12

    def unstable(z: complex) -> bool:
        return z.real > tol * abs(z)

    f = np.abs(lam.imag)
    flags = [np.array([unstable(z) for z in lam[:, k]]) for k in range(n_modes)]
    jobs = sum(40 * int(np.count_nonzero((fl[1:] != fl[:-1]) & ~np.isnan(lam[1:, k]) & ~np.isnan(lam[:-1, k])))
               for k, fl in enumerate(flags))
    for a_ in range(n_modes):
        for b_ in range(a_ + 1, n_modes):
            gap = np.abs(f[:, a_] - f[:, b_]) / np.maximum(np.maximum(f[:, a_], f[:, b_]), 1e-300)
            with np.errstate(invalid="ignore"):
                close = (gap <= rtol) & (f[:, a_] > 0)
            jobs += 30 * int(np.count_nonzero(close[1:] != close[:-1]))
    done = 0

    def bisected() -> None:
        nonlocal done
        done += 1
        tick((vals.size + done) / (vals.size + jobs + 1))

    for k in range(n_modes):
        flag = flags[k]
        exists = ~np.isnan(lam[:, k])
        for i in (int(j) for j in np.flatnonzero((flag[1:] != flag[:-1]) & exists[1:] & exists[:-1])):
            a, b = float(vals[i]), float(vals[i + 1])
            for _ in range(40):
                bisected()
                c = mid(a, b)
                wc, _ = _first_order(linear(c))
                if unstable(wc[np.argmin(np.abs(wc - lam[i, k]))]) == flag[i]:
                    a = c
                else:
                    b = c
            crossings.append({"value": 0.5 * (a + b), "mode": int(k),
                              "direction": "stabilizing" if flag[i] else "destabilizing"})
    coal = []

    def merged_at(c: float, ka: int, kb: int, i: int) -> bool:
        """Past the exceptional point: the frequency gap is smaller than the real-part gap."""
        wc, _ = _first_order(linear(c))
        ia, ib = np.argmin(np.abs(wc - lam[i, ka])), np.argmin(np.abs(wc - lam[i, kb]))
        if ia == ib:
            return True
        za, zb = wc[ia], wc[ib]
        return abs(abs(za.imag) - abs(zb.imag)) < abs(za.real - zb.real)

    for a_ in range(n_modes):
        for b_ in range(a_ + 1, n_modes):
            gap = np.abs(f[:, a_] - f[:, b_]) / np.maximum(np.maximum(f[:, a_], f[:, b_]), 1e-300)
            with np.errstate(invalid="ignore"):
                close = (gap <= rtol) & (f[:, a_] > 0)
            for i in (int(j) for j in np.flatnonzero(close[1:] != close[:-1])):
                lo, hi = float(vals[i]), float(vals[i + 1])
                entering = bool(close[i + 1])
                for _ in range(30):
                    bisected()
                    c = mid(lo, hi)
                    if merged_at(c, a_, b_, i) == entering:
                        hi = c
                    else:
                        lo = c
                at = i + 1 if entering else i
                coal.append({"value": 0.5 * (lo + hi), "modes": (int(a_), int(b_)),
                             "frequency_hz": float(f[at, a_] / (2 * math.pi)),
                             "kind": "merge" if entering else "split"})
    tick(1.0, force=True)
    return ModeTracks(parameter=parameter, values=vals, eigenvalues=lam, continuity=cont, coalescences=coal,
                      crossings=crossings, log=log, model=model, units=units)


def modes_along(engine: Any, space: Any, name: str, start: float, stop: float, *, num: int = 200,
                log: bool = False, pad_rates: str = "kept",
                progress: Callable[[float], None] | None = None) -> ModeTracks:
    """Mode-coupling diagram of any model along one parameter of a parameter space.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides (:func:`brakesqueal.model.resolve_space`).
    name : str
        A settable name of ``space``.
    start, stop : float
        The path (SI unit of ``name``), ``start < stop``; positive for a log path.
    num : int, optional
        Number of path values (default 200, at least 3).
    log : bool, optional
        Logarithmic spacing.
    pad_rates : {"kept", "quasi-static"}
        See :func:`~brakesqueal.analysis.linear.linearize`.
    progress : callable, optional
        Called with the completed fraction in [0, 1] (:func:`track_modes`); a
        path of 100000 points of the eight-DOF model takes a few minutes.

    Returns
    -------
    ModeTracks

    Raises
    ------
    ParameterError
        Unknown or tied names, an empty or reversed range, too few points.
    SilentMotionError
        If a point of the path has no usable silent motion.
    """
    from ..errors import ParameterError
    from .linear import linearize

    space.check_axis(name)
    if not (math.isfinite(start) and math.isfinite(stop) and stop > start):
        raise ParameterError(f"path '{name}': need START < STOP (finite); got {start!r}:{stop!r}")
    if log and start <= 0:
        raise ParameterError(f"path '{name}': a log path needs START > 0; got {start!r}")
    if not 3 <= num <= 100_000:
        raise ParameterError(f"path '{name}': the number of points must be in [3, 100000]; got {num}")
    from .maps import resolution_problem

    problem = resolution_problem(start, stop, num, log)
    if problem:
        raise ParameterError(f"path '{name}': {problem}", parameter=name)
    values = np.geomspace(start, stop, num) if log else np.linspace(start, stop, num)
    return track_modes(values, lambda v: linearize(engine, space.resolve({name: v}), pad_rates=pad_rates),
                       parameter=name, log=log, model=space.model.name, units=space.preset.unit(name),
                       progress=progress)
