"""Stability maps over two parameters of a preset (chunked, bounded memory).

For 2-DOF models whose silent motion is trivial on the whole map the verdict
comes from the compiled Hurwitz kernel of :mod:`.kernels`; ``max_real`` and
``frequency`` come from the roots of the quartic (batched eigenvalues of its
companion matrix).  Points with a non-trivial silent motion use the numeric
linearization point by point; points where it does not exist, a pad loses
contact or the parameters are invalid are flagged in ``status`` and never
marked stable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SilentMotionError
from ..parameters import _BOUNDS, PARAMETER_NAMES
from .kernels import hurwitz_stable, map_kernel, quartic_coefficients
from .space import VECTOR_NAMES, ParameterSpace

__all__ = ["Axis", "parse_axis", "stability_map", "classify_grid", "STATUS", "MAX_POINTS"]

#: Meaning of the ``status`` codes of a map.
STATUS = {0: "ok", 1: "ok_nontrivial_silent_motion", 2: "no_silent_motion", 3: "pad_loses_contact",
          4: "invalid_parameters"}
#: Maps larger than this need ``force=True`` (``--force``).
MAX_POINTS = 10**9


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
    a, b = arr["mu1"] * arr["h10"], arr["mu2"] * arr["h20"]
    return np.abs(a - b) <= 1e-12 * np.maximum(np.abs(a), np.abs(b))


def _roots_summary(a: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """max Re λ and |Im λ|/2π of the least-stable root of the quartics (flattened inputs)."""
    a0, a1, a2, a3, a4 = (np.asarray(x, dtype=float).ravel() for x in a)
    n = a0.size
    comp = np.zeros((n, 4, 4))
    comp[:, 0, 0], comp[:, 0, 1], comp[:, 0, 2], comp[:, 0, 3] = -a3 / a4, -a2 / a4, -a1 / a4, -a0 / a4
    comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1.0
    good = np.all(np.isfinite(comp), axis=(1, 2))
    comp[~good] = 0.0
    lam = np.linalg.eigvals(comp)
    idx = np.argmax(lam.real, axis=1)
    top = lam[np.arange(n), idx]
    mr = np.where(good, top.real, np.nan)
    fr = np.where(good, np.abs(top.imag) / (2 * np.pi), np.nan)
    return mr, fr


def _numeric_point(space: ParameterSpace, values: dict[str, float]) -> tuple[int, tuple[float, ...] | None]:
    """Status and quartic coefficients at one point via the numeric linearization."""
    from .linear import linearize

    try:
        lm = linearize(space.resolve(values))
    except ParameterError:
        return 4, None
    except SilentMotionError as exc:
        return (3 if "loses contact" in str(exc) else 2), None
    return (0 if lm.silent.trivial else 1), quartic_coefficients(lm.M, lm.D, lm.K)


def classify_grid(space: ParameterSpace, x: Axis, y: Axis) -> tuple[np.ndarray, str, str]:
    """Only the Hurwitz verdict on the full grid with the compiled kernel (benchmarks, large maps).

    Returns ``(stable[outer, inner] uint8, outer_name, inner_name)``; raises
    ParameterError if no compiled kernel applies.
    """
    kern = map_kernel(space, x.name, y.name, x.start > 0, y.start > 0)
    if kern is None:
        raise ParameterError("no compiled kernel for this map (non-trivial silent motion or non-rational dependence)")
    ax = {x.name: x, y.name: y}
    outer, inner = ax[kern.outer], ax[kern.inner]
    C, _ = kern.row_coefficients(outer.values(), inner.ref)
    out = np.empty((outer.num, inner.num), dtype=np.uint8)
    kern.classify(C, inner.values() / inner.ref, out)
    return out, kern.outer, kern.inner


def stability_map(space: ParameterSpace, x: Axis, y: Axis, *, force: bool = False, eigen: bool = True,
                  chunk_points: int = 1 << 20, progress: Callable[[float], None] | None = None) -> object:
    """Compute a stability map over two settable parameters of ``space``.

    Parameters
    ----------
    space : ParameterSpace
        The preset / parameter set; tied names follow the axes.
    x, y : Axis
        The two axes.
    force : bool
        Allow more than :data:`MAX_POINTS` points.
    eigen : bool
        Compute ``max_real`` and ``frequency`` (quartic roots, ~4e5 points/s);
        ``False`` leaves them NaN and only classifies (~1e9 points/s).
    chunk_points : int
        Points per chunk (bounds the temporary memory).
    progress : callable, optional
        Called with the completed fraction after each chunk.

    Returns
    -------
    StabilityMap
        See :class:`brakesqueal.results.StabilityMap`.
    """
    from ..results import StabilityMap

    _check_axes(space, [x, y], force)
    space.resolve({})
    kern = map_kernel(space, x.name, y.name, x.start > 0, y.start > 0)
    ax = {x.name: x, y.name: y}
    outer, inner = (ax[kern.outer], ax[kern.inner]) if kern else (y, x)
    ov, iv = outer.values(), inner.values()
    n_o, n_i = ov.size, iv.size
    big = n_o * n_i > 2 * 10**7
    ftype = np.float32 if big else np.float64
    stable = np.zeros((n_o, n_i), dtype=bool)
    status = np.zeros((n_o, n_i), dtype=np.int8)
    max_real = np.full((n_o, n_i), np.nan, dtype=ftype)
    freq = np.full((n_o, n_i), np.nan, dtype=ftype)
    rows = max(1, chunk_points // n_i)
    t_inner = iv / inner.ref
    buf = np.empty((rows, n_i), dtype=np.uint8)
    for r0 in range(0, n_o, rows):
        r1 = min(n_o, r0 + rows)
        arr = space.arrays({outer.name: ov[r0:r1, None], inner.name: iv[None, :]})
        valid = _valid(arr)
        triv = valid & _trivial(arr)
        st = status[r0:r1]
        st[~valid] = 4
        if kern is not None:
            C, sigma = kern.row_coefficients(ov[r0:r1], inner.ref)
            out = buf[: r1 - r0]
            kern.classify(C, t_inner, out)
            stable[r0:r1] = out.astype(bool) & triv
        coef = None
        if eigen or kern is None:
            from ..numeric.compiled import compiled_model

            tm = compiled_model().trivial_matrices
            p = [arr[n] for n in VECTOR_NAMES]
            with np.errstate(all="ignore"):
                ent = [np.broadcast_to(np.asarray(e, dtype=float), triv.shape) for e in tm(p)]
            M = np.stack(ent[0:4], -1).reshape(*triv.shape, 2, 2)
            D = np.stack(ent[4:8], -1).reshape(*triv.shape, 2, 2)
            K = np.stack(ent[8:12], -1).reshape(*triv.shape, 2, 2)
            coef = quartic_coefficients(M, D, K)
            if kern is None:
                stable[r0:r1] = hurwitz_stable(*coef) & triv
        if eigen and coef is not None and triv.any():
            mr, fr = _roots_summary(tuple(c[triv] for c in coef))
            max_real[r0:r1][triv] = mr
            freq[r0:r1][triv] = fr
        nontriv = np.argwhere(valid & ~triv)
        for i, j in nontriv:
            code, c = _numeric_point(space, {outer.name: float(ov[r0 + i]), inner.name: float(iv[j])})
            st[i, j] = code
            if c is not None:
                stable[r0 + i, j] = bool(hurwitz_stable(*c))
                if eigen:
                    mr, fr = _roots_summary(c)
                    max_real[r0 + i, j], freq[r0 + i, j] = mr[0], fr[0]
        if progress is not None:
            progress(r1 / n_o)
    return StabilityMap.from_arrays(space, outer, inner, stable=stable, status=status, max_real=max_real,
                                    frequency=freq, method="compiled Hurwitz kernel" if kern else "numeric")
