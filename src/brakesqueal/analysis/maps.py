"""Stability maps over two parameters of a preset (chunked, bounded memory).

For 2-DOF models whose silent motion is trivial on the whole map the verdict
comes from the certified compiled kernel of :mod:`.kernels` (stable /
unstable / uncertain per point, with rigorous floating-point error bounds);
uncertain points, and maps without a kernel, use the per-point robust route
:func:`~.robust.trivial_verdicts` (bounded closed-form matrices → interval
quartic → certified Routh → exact rational evaluation).  ``max_real`` and
``frequency`` come from the roots of the quartic and are reconciled with the
verdict (:func:`~.robust.reconcile`).  Points with a non-trivial silent motion
use the numeric linearization point by point (:func:`~.robust.matrix_verdicts`);
points where it does not exist, a pad loses contact, the parameters are
invalid or the verdict cannot be decided are flagged in ``status`` and never
marked stable.  No verdict depends on where an axis starts or on its sign.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SilentMotionError
from ..parameters import _BOUNDS, PARAMETER_NAMES
from .kernels import inner_exponent, kernel_segments, map_kernel, quartic_coefficients
from .robust import STABLE, STATUS_UNDECIDED, UNDECIDED, matrix_verdicts, trivial_verdicts
from .space import VECTOR_NAMES, ParameterSpace

__all__ = ["Axis", "parse_axis", "stability_map", "classify_grid", "STATUS", "MAX_POINTS", "point_verdicts"]

#: Meaning of the ``status`` codes of a map.
STATUS = {0: "ok", 1: "ok_nontrivial_silent_motion", 2: "no_silent_motion", 3: "pad_loses_contact",
          4: "invalid_parameters", 5: "undecided"}
#: Maps larger than this need ``force=True`` (``--force``).
MAX_POINTS = 10**9
_BATCH = 1 << 16


@dataclass(frozen=True)
class Axis:
    """One sweep axis: ``num`` points from ``start`` to ``stop``, linear or logarithmic.

    Parameters
    ----------
    name : str
        The parameter the axis varies: a settable name of the
        :class:`~brakesqueal.analysis.space.ParameterSpace` (a model parameter such as ``Omega`` or
        a preset's auxiliary name such as ``mu`` or ``k_ip``).
    start, stop : float
        Range of the axis in the SI unit of ``name`` (e.g. rad/s for
        ``Omega``, N/m for ``k_ip``); finite, with ``stop > start``.
    num : int, optional
        Number of grid points of a map, including both ends (default 2, at
        least 2).  Paths (:func:`~brakesqueal.analysis.crossings.crossings`) only use the range.
    log : bool, optional
        Logarithmic spacing (:func:`numpy.logspace`; needs ``start > 0``)
        instead of linear (default ``False``).

    Raises
    ------
    ParameterError
        If a bound is not finite, the range is empty or reversed, a log axis
        has ``start <= 0`` or ``num < 2``.
    """

    name: str
    start: float
    stop: float
    num: int = 2
    log: bool = False

    def __post_init__(self) -> None:
        what = f"axis '{self.name}'"
        if not (math.isfinite(self.start) and math.isfinite(self.stop)):
            raise ParameterError(f"{what}: bounds must be finite; got {self.start!r}:{self.stop!r}")
        if not self.stop > self.start:
            raise ParameterError(f"{what}: empty or reversed range {self.start!r}:{self.stop!r} "
                                 "(STOP must be greater than START)")
        if self.log and self.start <= 0:
            raise ParameterError(f"{what}: a log axis needs positive bounds; got START = {self.start!r}")
        if self.num < 2:
            raise ParameterError(f"{what}: N must be at least 2; got {self.num}")

    def values(self) -> np.ndarray:
        """The grid points."""
        if self.log:
            return np.logspace(math.log10(self.start), math.log10(self.stop), self.num)
        return np.linspace(self.start, self.stop, self.num)

    @property
    def ref(self) -> float:
        """A representative magnitude (geometric mean for log axes), used to scale polynomials."""
        if self.log:
            return math.sqrt(self.start * self.stop)
        return max(abs(self.start), abs(self.stop))


def parse_axis(text: str, *, with_num: bool = True) -> Axis:
    """Parse ``NAME=START:STOP:N[:log]`` (or ``NAME=START:STOP[:log]`` with ``with_num=False``)."""
    from ..expressions import evaluate

    name, sep, spec = text.partition("=")
    name = name.strip()
    form = "NAME=START:STOP:N[:log]" if with_num else "NAME=START:STOP[:log]"
    if not sep or not name.isidentifier():
        raise ParameterError(f"malformed axis {text!r}: expected {form}")
    parts = [p.strip() for p in spec.split(":")]
    log = bool(parts) and parts[-1].lower() in ("log", "lin", "linear")
    log_flag = log and parts[-1].lower() == "log"
    if log:
        parts = parts[:-1]
    if len(parts) != (3 if with_num else 2) or not all(parts):
        raise ParameterError(f"malformed axis {text!r}: expected {form}")
    start = evaluate(parts[0], {}, what=f"start of axis '{name}'")
    stop = evaluate(parts[1], {}, what=f"stop of axis '{name}'")
    num = 2
    if with_num:
        try:
            num = int(parts[2])
        except ValueError:
            raise ParameterError(f"axis '{name}': N must be an integer; got {parts[2]!r}") from None
    return Axis(name, start, stop, num, log_flag)


def _check_axes(space: ParameterSpace, axes: list[Axis], force: bool) -> None:
    for ax in axes:
        space.check_axis(ax.name)
    if len(axes) == 2 and axes[0].name == axes[1].name:
        raise ParameterError(f"both axes vary '{axes[0].name}'; choose two different parameters")
    n = math.prod(ax.num for ax in axes)
    if n > MAX_POINTS and not force:
        raise ParameterError(f"the map has {n:.3g} points (> {MAX_POINTS:.0e}); pass --force to compute it anyway")


def _valid(arr: dict[str, np.ndarray]) -> np.ndarray:
    """Points whose 17 model parameters satisfy the bounds of :class:`~brakesqueal.parameters.Parameters`."""
    ok = np.ones(np.shape(next(iter(arr.values()))), dtype=bool)
    with np.errstate(all="ignore"):
        for name, vname in zip(PARAMETER_NAMES, VECTOR_NAMES):
            v = arr[vname]
            if vname != name:  # compliance in [0, inf)
                ok &= (v >= 0) & np.isfinite(v)
                continue
            low, high, low_open, high_open = _BOUNDS[name]
            ok &= (v > low if low_open else v >= low) & (v < high if high_open else v <= high)
        ok &= arr["h10"] + arr["h20"] > 0
    return ok


def _trivial(arr: dict[str, np.ndarray]) -> np.ndarray:
    with np.errstate(all="ignore"):
        a, b = arr["mu1"] * arr["h10"], arr["mu2"] * arr["h20"]
        return np.abs(a - b) <= 1e-12 * np.maximum(np.abs(a), np.abs(b))


def _roots_summary(a: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """max Re λ and |Im λ|/2π of the least-stable root of the quartics (flattened inputs, floating point)."""
    from .robust import roots_summary

    A = np.stack([np.asarray(x, dtype=float).ravel() for x in a], axis=1)
    return roots_summary(A)


def _numeric_point(space: ParameterSpace, values: dict[str, float]) -> tuple[int, tuple[float, ...] | None]:
    """Status and quartic coefficients at one point via the numeric linearization."""
    code, c, _ = _numeric_linear(space, values)
    return code, c


def _numeric_linear(space: ParameterSpace, values: dict[str, float]) -> tuple[int, tuple[float, ...] | None, object]:
    from .linear import linearize

    try:
        lm = linearize(space.resolve(values))
    except ParameterError:
        return 4, None, None
    except SilentMotionError as exc:
        return (3 if "loses contact" in str(exc) else 2), None, None
    return (0 if lm.silent.trivial else 1), quartic_coefficients(lm.M, lm.D, lm.K), lm


def numeric_point_verdict(space: ParameterSpace, values: dict[str, float]) -> tuple[int, bool, float, float]:
    """``(status, stable, max_real, frequency)`` at one point via the numeric linearization (robust verdict).

    Used where the silent motion is not trivial; the verdict comes from
    :func:`~.robust.matrix_verdicts` (status 5 when undecided).
    """
    code, _, lm = _numeric_linear(space, values)
    if lm is None:
        return code, False, math.nan, math.nan
    c, mr, fr = matrix_verdicts(lm.M, lm.D, lm.K)  # type: ignore[attr-defined]
    if c[0] == UNDECIDED:
        return STATUS_UNDECIDED, False, float(mr[0]), float(fr[0])
    return code, bool(c[0] == STABLE), float(mr[0]), float(fr[0])


def point_verdicts(P: np.ndarray, *, eigen: bool, codes: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Robust verdicts of 2-DOF parameter vectors at the trivial silent motion, in bounded batches.

    ``codes`` (optional) are verdicts already certified by a kernel (2 =
    uncertain: recomputed).  Returns ``(codes, max_real, frequency)``; see
    :func:`~.robust.trivial_verdicts`.
    """
    n = P.shape[0]
    out = np.empty(n, dtype=np.uint8)
    mr = np.full(n, np.nan)
    fr = np.full(n, np.nan)
    for b0 in range(0, n, _BATCH):
        sl = slice(b0, min(n, b0 + _BATCH))
        c, m, f = trivial_verdicts(P[sl], eigen=eigen, codes=None if codes is None else codes[sl])
        out[sl], mr[sl], fr[sl] = c, m, f
    return out, mr, fr


def classify_grid(space: ParameterSpace, x: Axis, y: Axis) -> tuple[np.ndarray, str, str]:
    """Only the certified kernel's codes on the full grid (benchmarks, large maps).

    Returns ``(codes[outer, inner] uint8, outer_name, inner_name)`` with
    codes 0 unstable, 1 stable, 2 uncertain (recomputed per point by
    :func:`stability_map`); raises ParameterError if no compiled kernel applies.
    """
    kern = map_kernel(space, x.name, y.name)
    if kern is None:
        raise ParameterError("no compiled kernel for this map (non-trivial silent motion or non-rational dependence)")
    ax = {x.name: x, y.name: y}
    outer, inner = ax[kern.outer], ax[kern.inner]
    return kern.verdicts(outer.values(), inner.values()), kern.outer, kern.inner


def _kernel_usable(kern: object, iv: np.ndarray) -> tuple[int, np.ndarray] | None:
    """Inner scaling ``(e, t)`` if the kernel's Horner evaluation stays in range for these inner values."""
    if kern is None:
        return None
    e = inner_exponent(iv)
    t = np.ldexp(np.asarray(iv, dtype=float), -e)
    deg = max(kern.degrees)  # type: ignore[attr-defined]
    tmax = float(np.max(np.abs(t))) if t.size else 0.0
    if not (np.all(np.isfinite(t)) and (tmax <= 1 or deg * math.log2(tmax) < 300)):
        return None  # |a_k| < 2^300 keeps H3 finite in the kernel (no overflow, no NaN)
    return e, t


def stability_map(space: ParameterSpace, x: Axis, y: Axis, *, force: bool = False, eigen: bool = True,
                  chunk_points: int = 1 << 20, progress: Callable[[float], None] | None = None) -> object:
    """Compute a stability map over two settable parameters of ``space``.

    Parameters
    ----------
    space : ParameterSpace
        The preset / parameter set; tied names follow the axes.
    x, y : Axis
        The two axes (any ranges and signs; points with invalid parameters
        get status 4).
    force : bool
        Allow more than :data:`MAX_POINTS` points.
    eigen : bool
        Compute ``max_real`` and ``frequency`` (quartic roots, ~2e5 points/s);
        ``False`` leaves them NaN and only classifies (~1e9 points/s).
    chunk_points : int
        Points per chunk (bounds the temporary memory).
    progress : callable, optional
        Called with the completed fraction after each chunk.

    Returns
    -------
    StabilityMap
        See :class:`brakesqueal.results.StabilityMap`; ``stable`` is certified,
        ``status`` 5 marks points whose verdict could not be decided (exactly
        on a stability boundary); for status 0/1 ``stable`` ⇔ ``max_real < 0``.
    """
    from ..results import StabilityMap

    _check_axes(space, [x, y], force)
    space.resolve({})
    kern = map_kernel(space, x.name, y.name)
    ax = {x.name: x, y.name: y}
    outer, inner = (ax[kern.outer], ax[kern.inner]) if kern else (y, x)
    ov, iv = outer.values(), inner.values()
    n_o, n_i = ov.size, iv.size
    scaled = _kernel_usable(kern, iv)
    seg_T = kernel_segments(scaled[1]) if scaled is not None else None
    big = n_o * n_i > 2 * 10**7
    ftype = np.float32 if big else np.float64
    stable = np.zeros((n_o, n_i), dtype=bool)
    status = np.zeros((n_o, n_i), dtype=np.int8)
    max_real = np.full((n_o, n_i), np.nan, dtype=ftype)
    freq = np.full((n_o, n_i), np.nan, dtype=ftype)
    rows = max(1, chunk_points // n_i)
    buf = np.empty((rows, n_i), dtype=np.uint8)
    for r0 in range(0, n_o, rows):
        r1 = min(n_o, r0 + rows)
        arr = space.arrays({outer.name: ov[r0:r1, None], inner.name: iv[None, :]})
        valid = _valid(arr)
        triv = valid & _trivial(arr)
        st = status[r0:r1]
        st[~valid] = 4
        codes = buf[: r1 - r0]
        if scaled is not None and seg_T is not None:
            C, EC = kern.row_coefficients(ov[r0:r1], scaled[0])  # type: ignore[union-attr]
            kern.classify(C, EC, scaled[1], seg_T[0], seg_T[1], codes)  # type: ignore[union-attr]
        else:
            codes[...] = UNDECIDED
        flat = np.flatnonzero(triv) if eigen else np.flatnonzero(triv & (codes == UNDECIDED))
        sure = triv & (codes != UNDECIDED)
        if not eigen:
            stable[r0:r1][sure] = codes[sure] == STABLE
        if flat.size:
            ix = np.unravel_index(flat, triv.shape)
            P = np.stack([np.broadcast_to(arr[n], triv.shape)[ix] for n in VECTOR_NAMES], axis=1)
            c, mr, fr = point_verdicts(P, eigen=eigen, codes=codes[ix])
            stable[r0:r1][ix] = c == STABLE
            st[ix] = np.where(c == UNDECIDED, STATUS_UNDECIDED, st[ix])
            if eigen:
                max_real[r0:r1][ix] = mr
                freq[r0:r1][ix] = fr
        for i, j in np.argwhere(valid & ~triv):
            code, sb, mr1, fr1 = numeric_point_verdict(space, {outer.name: float(ov[r0 + i]), inner.name: float(iv[j])})
            st[i, j] = code
            stable[r0 + i, j] = sb
            if eigen:
                max_real[r0 + i, j], freq[r0 + i, j] = mr1, fr1
        if progress is not None:
            progress(r1 / n_o)
    method = "certified compiled Hurwitz kernel + robust per-point route" if scaled is not None \
        else "robust per-point route (bounded closed form, certified Routh, exact fallback)"
    return StabilityMap.from_arrays(space, outer, inner, stable=stable, status=status, max_real=max_real,
                                    frequency=freq, method=method)
