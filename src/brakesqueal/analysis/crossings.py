r"""Exact stability changes along a 1-D path and critical speeds.

Stability changes only where the characteristic quartic has a root at 0
(``a0 = 0``), a pair on the imaginary axis (``H3 = 0``) or its degree drops
(``a4 = 0``, Orlando's formula); with ``a_i = N_i / Den`` these are real roots
of the exact polynomials ``N_0``, ``N_4``, ``H3(N)`` and ``Den`` in the path
parameter (:meth:`Engine.univariate <brakesqueal.codegen.engine.Engine.univariate>`, rational arithmetic).  Their
roots are isolated *exactly* on the requested range, whatever its width
(:func:`~.robust.isolate_real_roots`: exact integer arithmetic; constants
such as π carried with 80 significant digits), and the verdict is evaluated
exactly between consecutive roots.  Nothing is read from a grid and nothing
overflows, so ``--along k_ip=1e-100:1e100:log`` is as exact as ``1e5:1e10``.

This exact route applies to any model with a closed form (two coordinates,
rate-free pads: :func:`~.kernels.model_form`) whose silent motion is
identically trivial along the path; the closed form is generated from the
model (:func:`~brakesqueal.symbolic.linearize.model_closed_form`).  Every
other case (more coordinates, pads with first-order dynamics, non-trivial
silent motions, non-rational ties) uses the numeric route: the certified
per-point verdict of :mod:`.points` on a grid, sign changes bracketed and
polished with Brent's method on the largest real part.  It is marked
``exhaustive=False`` (two crossings closer than the grid spacing can be
missed) and points it cannot decide are reported in ``undecided_ranges``; it
never claims "stable throughout".

Every result stores the largest real part along the path (``profile``),
computed when the result is made, for its plot.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..model.expressions import names_in
from ..status import PointStatus
from .kernels import omega_entries, omega_subranges
from .maps import Axis
from .robust import isolate_real_roots

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["crossings", "critical_speeds", "critical_speeds_many", "critical_speeds_batch", "exact_crossings",
           "exact_omega_crossings", "omega_name", "PROFILE_POINTS", "NUMERIC_GRID"]

#: Points of the stored ``max_real`` profile of a path (for plots).
PROFILE_POINTS = 200
#: Grid points of the numeric route.
NUMERIC_GRID = 801

_DIGITS = 80  # significant digits of constants in inexact tables (symbolic.stability_forms.UNIVARIATE_DIGITS)


def _peval(c: list[Fraction], x: Fraction) -> tuple[Fraction, Fraction]:
    v = Fraction(0)
    a = Fraction(0)
    ax = abs(x)
    for k in range(len(c) - 1, -1, -1):
        v = v * x + c[k]
        a = a * ax + abs(c[k])
    return v, a


def _verdict(N: list[list[Fraction]], x: Fraction, exact: bool) -> int | None:
    """Exact quartic verdict (1 stable, 0 unstable) at ``x``; ``None`` if a sign is not reliable."""
    vals = []
    for c in N:
        v, a = _peval(c, x)
        if not exact and v != 0 and abs(v) < Fraction(1, 10 ** (_DIGITS - 15)) * a:
            return None
        vals.append(v)
    n0, n1, n2, n3, n4 = vals
    if n4 == 0:
        return None
    s = 1 if n4 > 0 else -1
    h = n1 * (n3 * n2 - n4 * n1) - n3 * n3 * n0
    if not exact:
        scale = abs(n1) * (abs(n3 * n2) + abs(n4 * n1)) + n3 * n3 * abs(n0)
        if h != 0 and abs(h) < Fraction(1, 10 ** (_DIGITS - 20)) * scale:
            return None
    if all(s * v > 0 for v in (n0, n1, n2, n3)) and s * h > 0:
        return 1
    return 0


def _split_point(a: Fraction, b: Fraction, log: bool, frac: float = 0.5) -> Fraction:
    if log and a > 0 and b > 4 * a:
        try:
            la, lb = math.log(a), math.log(b)
            x = Fraction(math.exp(la + frac * (lb - la)))
        except (OverflowError, ValueError):
            x = a
        if a < x < b:
            return x
    return a + (b - a) * Fraction(frac).limit_denominator(64)


def _fractions(coeffs: list[str]) -> list[Fraction]:
    return [Fraction(c) for c in coeffs]


def exact_crossings(table: dict[str, Any], lo: float, hi: float, log: bool = True,
                    valid: Any = None) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]]]:
    """All stability changes in ``(lo, hi)`` from the exact univariate quartic of a path.

    Parameters
    ----------
    table : dict
        Exact ascending coefficients of ``N_0..N_4``, ``H3(N)`` and ``Den`` in the path variable
        (:meth:`Engine.univariate <brakesqueal.codegen.engine.Engine.univariate>`; ``"p/q"`` strings) and
        whether they are exact.
    lo, hi : float
        The range (taken exactly; any magnitudes).
    log : bool
        Place test points geometrically (only where the verdict is sampled).
    valid : callable, optional
        ``valid(x: float) -> bool``; a piece between candidates is decided at
        a valid test point (the verdict is constant on the piece) and, if
        one of its test points or an end of the range (``lo``, ``hi``) was
        invalid, reported in the undecided ranges too (it holds invalid
        parameter sets); a piece without a valid test point is undecided.

    Returns
    -------
    stable_at_start : bool
        Verdict just above ``lo``.
    crossings : list of (float, str)
        Values and directions, ascending.
    undecided : list of (float, float)
        Ranges where no verdict could be established (empty in all but
        pathological cases).
    """
    exact = bool(table["exact"])
    polys = [_fractions(c) for c in table["N"]] + [_fractions(table["H"]), _fractions(table["den"])]
    N = polys[:5]
    lo_q, hi_q = Fraction(lo), Fraction(hi)
    roots = isolate_real_roots([N[0], N[4], polys[5], polys[6]], lo_q, hi_q)
    iv = [(a, b) for a, b, _ in roots if b > lo_q and a < hi_q and not (a == b == lo_q) and not (a == b == hi_q)]
    # merge isolating intervals closer than 1e-30 relative (a multiple root split by rounded constants)
    merged: list[list[Fraction]] = []
    for a, b in iv:
        tiny = Fraction(1, 10 ** 30) * max(abs(a), abs(merged[-1][1]), Fraction(1, 10 ** 300)) if merged else 0
        if merged and a - merged[-1][1] <= tiny:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    edges = [lo_q] + [x for a, b in merged for x in (a, b)] + [hi_q]
    pieces = [(edges[2 * k], edges[2 * k + 1]) for k in range(len(merged) + 1)]
    verdicts: list[int | None] = []
    partly_invalid: list[tuple[float, float]] = []
    # an end of the range outside the allowed values (e.g. |Omega| > 1e100): its piece holds invalid sets even
    # when the test points below happen to be valid
    for a, b in (pieces[0], pieces[-1]):
        if valid is not None and b > a and not (valid(float(a)) and valid(float(b))):
            partly_invalid.append((float(a), float(b)))
    for a, b in pieces:
        v = None
        if b > a:
            for frac in (0.5, 0.25, 0.75, 0.125, 0.875, 0.0625, 0.9375):
                x = _split_point(a, b, log, frac)
                if valid is not None and not valid(float(x)):
                    # the verdict is constant on the piece, but not every parameter set of it is valid
                    if not partly_invalid or partly_invalid[-1] != (float(a), float(b)):
                        partly_invalid.append((float(a), float(b)))
                    continue
                v = _verdict(N, x, exact)
                if v is not None:
                    break
        verdicts.append(v)
    found: list[tuple[float, str]] = []
    undecided: list[tuple[float, float]] = []
    prev: int | None = verdicts[0]
    start = bool(verdicts[0]) if verdicts[0] is not None else False
    if verdicts[0] is None:
        undecided.append((float(pieces[0][0]), float(pieces[0][1])))
    for k in range(1, len(pieces)):
        v = verdicts[k]
        a, b = merged[k - 1]
        if v is None:
            undecided.append((float(a), float(pieces[k][1])))
        elif prev is None:
            undecided.append((float(pieces[k - 1][1]), float(b)))
        elif v != prev:
            found.append((float((a + b) / 2), "stabilizing" if v == 1 else "destabilizing"))
        if v is not None:
            prev = v
        else:
            prev = None
    return start, found, merge_ranges(undecided + partly_invalid)


def merge_ranges(r: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The union of closed ranges, sorted, overlapping or touching ones joined (also :mod:`brakesqueal.design`)."""
    out: list[tuple[float, float]] = []
    for a, b in sorted(r):
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def _pmul(a: list[Fraction], b: list[Fraction]) -> list[Fraction]:
    out = [Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        if x:
            for j, y in enumerate(b):
                out[i + j] += x * y
    return out


def _padd(*ps: tuple[int, list[Fraction]]) -> list[Fraction]:
    out = [Fraction(0)] * max(len(p) for _, p in ps)
    for sgn, p in ps:
        for i, x in enumerate(p):
            out[i] += sgn * x
    return out


def omega_quartic(engine: Engine, p: np.ndarray) -> dict[str, Any]:
    """The exact quartic along Ω at one parameter vector (trivial silent motion), as an :func:`exact_crossings`
    table: ``Ω² a_i(Ω)`` from the Laurent coefficients of the closed form's entries in exact rational
    arithmetic (:meth:`Engine.exact_omega <brakesqueal.codegen.engine.Engine.exact_omega>`; no computer
    algebra), so ``Den = Ω²``."""
    mod = engine.exact_omega()
    c = mod.omega_entries([Fraction(float(v)) for v in p])
    e = [list(c[4 * k:4 * k + 4]) for k in range(12)]  # Ω · entry, ascending in Ω
    m11, m12, m21, m22, d11, d12, d21, d22, k11, k12, k21, k22 = e
    N = [_padd((1, _pmul(k11, k22)), (-1, _pmul(k12, k21))),
         _padd((1, _pmul(d11, k22)), (1, _pmul(k11, d22)), (-1, _pmul(d12, k21)), (-1, _pmul(k12, d21))),
         _padd((1, _pmul(m11, k22)), (1, _pmul(d11, d22)), (1, _pmul(k11, m22)), (-1, _pmul(m12, k21)),
               (-1, _pmul(d12, d21)), (-1, _pmul(k12, m21))),
         _padd((1, _pmul(m11, d22)), (1, _pmul(d11, m22)), (-1, _pmul(m12, d21)), (-1, _pmul(d12, m21))),
         _padd((1, _pmul(m11, m22)), (-1, _pmul(m12, m21)))]
    n0, n1, n2, n3, n4 = N
    H = _padd((1, _pmul(n1, _padd((1, _pmul(n3, n2)), (-1, _pmul(n4, n1))))), (-1, _pmul(_pmul(n3, n3), n0)))

    def txt(q: list[Fraction]) -> list[str]:
        return [f"{v.numerator}/{v.denominator}" for v in q]

    return {"N": [txt(q) for q in N], "H": txt(H), "den": ["0/1", "0/1", "1/1"], "exact": bool(mod.EXACT)}


def exact_omega_crossings(engine: Engine, p: np.ndarray, lo: float, hi: float
                          ) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]]]:
    """Exact stability changes along Ω in ``(lo, hi)`` for one parameter vector (trivial silent motion).

    Parameters
    ----------
    engine : Engine
        The model's engine; it needs the critical-speed kernel (a closed form with a named spin).
    p : ndarray
        Parameter vector in the model's packing order (compliances; Ω ignored).
    lo, hi : float
        The Ω range [rad/s].

    Returns
    -------
    stable_at_start, crossings, undecided
        See :func:`exact_crossings` (:func:`omega_quartic`: the parameter values taken as exact rationals, Ω
        symbolic).
    """
    return exact_crossings(omega_quartic(engine, p), lo, hi, True)


def _grid(axis: Axis, n: int) -> np.ndarray:
    """``n`` sampling points of a path (as :meth:`Axis.values`; a narrow path's samples may repeat)."""
    if axis.log:
        return np.logspace(math.log10(axis.start), math.log10(axis.stop), n)
    return np.linspace(axis.start, axis.stop, n)


def _profile(engine: Engine, space: ParameterSpace, axis: Axis, n: int = PROFILE_POINTS, modes: str = "all"
             ) -> tuple[np.ndarray, np.ndarray]:
    """``(values, max_real)`` along a path from the per-point evaluator (NaN where undecidable)."""
    from .points import evaluate

    grid = _grid(axis, n)
    r = evaluate(engine, space, {axis.name: grid}, modes=modes)
    return grid, np.where(np.isin(r.status, _DECIDED), r.max_real, np.nan)


_DECIDED = (int(PointStatus.OK), int(PointStatus.OK_NONTRIVIAL))


def _numeric(engine: Engine, space: ParameterSpace, axis: Axis, n: int = NUMERIC_GRID, modes: str = "all"
             ) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]], tuple[np.ndarray, np.ndarray], str]:
    """Certified per-point verdicts on a grid, sign changes bracketed, Brent on max Re λ; the carrier at the start."""
    from scipy.optimize import brentq

    from .points import evaluate, evaluate_point

    grid = _grid(axis, n)
    r = evaluate(engine, space, {axis.name: grid}, modes=modes)
    ok = np.isin(r.status, _DECIDED)
    st = r.stable & ok
    mr = r.max_real
    undecided: list[tuple[float, float]] = []
    for k in np.flatnonzero(~ok):
        undecided.append((float(grid[max(int(k) - 1, 0)]), float(grid[min(int(k) + 1, n - 1)])))
    out: list[tuple[float, str]] = []

    def f(v: float) -> float:
        return evaluate_point(engine, space, {axis.name: v}, modes=modes).max_real

    dec = np.flatnonzero(ok)
    for k0, k1 in zip(dec[:-1], dec[1:]):
        # consecutive decided points; undecided ones (status UNDECIDED: max Re λ at the error bound) may lie in
        # between and stay in undecided_ranges, other failures (no silent motion, invalid) separate the pieces
        if st[k0] == st[k1] or not np.all(r.status[k0 + 1:k1] == int(PointStatus.UNDECIDED)):
            continue
        a, b = float(grid[k0]), float(grid[k1])
        x = math.sqrt(a * b) if axis.log else 0.5 * (a + b)
        if math.isfinite(mr[k0]) and math.isfinite(mr[k1]) and mr[k0] * mr[k1] < 0:
            try:
                x = brentq(f, a, b, xtol=1e-300, rtol=1e-15, maxiter=200)
            except ValueError:  # the sign of max Re λ is not continuous in between (a status change)
                undecided.append((a, b))
        out.append((float(x), "stabilizing" if st[k1] else "destabilizing"))
    prof = (grid, np.where(ok, mr, np.nan))
    c0 = int(r.carrier.reshape(-1)[0])
    carrier = r.carriers[c0] if 0 <= c0 < len(r.carriers) else ""
    return bool(st[0]), out, merge_ranges(undecided), prof, carrier


def _valid_fn(space: Any, name: str) -> Any:
    def valid(x: float) -> bool:
        try:
            space.resolve({name: x})
        except (ParameterError, ValueError, ZeroDivisionError, OverflowError):
            return False
        return True

    return valid


def crossings(engine: Engine, space: ParameterSpace, axis: Axis, *, modes: str = "all") -> Any:
    """Every value of ``axis.name`` in ``(start, stop)`` where stability of the silent motion changes.

    Stability is that of the linearized equations (47) about the silent
    motion (eq. 46), with every eigenvalue of the linear model (the pads'
    own modes included where they keep first-order dynamics).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides (any model); every other settable
        name keeps its value in ``space`` and tied names follow.
    axis : Axis
        The path: ``axis.name`` must be a settable name of ``space``;
        ``start`` and ``stop`` bound it (SI unit of the parameter; any width,
        e.g. ``1e-100`` to ``1e100``).  ``log`` only selects where stability is
        sampled between candidates (geometric instead of arithmetic
        midpoints) and the spacing of the numeric route's grid; ``num`` is
        ignored.
    modes : {"all", "disk"}
        Judge every eigenvalue (default), or leave out the modes carried by a massless pad's own tangential
        rate (a model with a closed form has none: both are the same there).

    Returns
    -------
    CrossingResult
        ``stable_at_start`` (verdict just above ``start``) and the crossings
        with their direction (``"destabilizing"``: stable before, unstable
        after, in the direction of increasing parameter), in increasing order,
        ``method``, ``undecided_ranges``, ``exhaustive`` and the stored
        ``profile`` of max Re λ along the path.

    Raises
    ------
    ParameterError
        If ``axis.name`` is tied or not a settable name of ``space``, or the
        parameters are invalid at ``start``.

    Notes
    -----
    Exact route (model with a closed form, silent motion identically trivial
    along the path, rational dependence): the candidates are the real roots
    of the exact numerators of ``a0``, ``a4``, of the Hurwitz determinant
    ``H3 = a1 (a2 a3 - a1 a4) - a0 a3²`` and of the common denominator,
    isolated exactly on the whole range; the result is complete and exact
    (crossing values to ~1e-15 relative).  Sub-ranges whose parameters are
    invalid are reported in ``undecided_ranges``.  Otherwise the certified
    per-point verdict (:mod:`.points`) on a grid of :data:`NUMERIC_GRID`
    points is bracketed and polished with Brent's method on the largest
    real part (``exhaustive=False``).
    """
    from ..results import CrossingResult

    space.check_axis(axis.name)
    _check_some_valid(space, axis)
    table = engine.univariate(space, axis.name)
    carrier = ""
    if table is not None:  # a closed form: no pad keeps a rate state, every mode is judged either way
        start, found, undecided = exact_crossings(table, axis.start, axis.stop, axis.log, _valid_fn(space, axis.name))
        method, exhaustive = "exact (isolated real roots of the Hurwitz polynomials of the closed form)", True
        prof = _profile(engine, space, axis)
    else:
        start, found, undecided, prof, carrier = _numeric(engine, space, axis, modes=modes)
        method = (f"numeric (certified per-point verdicts on a {NUMERIC_GRID}-point grid + Brent on max Re lambda; "
                  "grid search)")
        exhaustive = False
    return CrossingResult(parameter=axis.name, start=axis.start, stop=axis.stop, log=axis.log,
                          stable_at_start=start, crossings=tuple(found), method=method, space=space,
                          undecided_ranges=tuple(undecided), exhaustive=exhaustive, profile=prof,
                          carrier_at_start=carrier)


def _check_some_valid(space: ParameterSpace, axis: Axis) -> None:
    """Raise the start's ParameterError unless some point of the path resolves: a range may reach past the
    allowed magnitudes (1e-100 to 1e100) at either end, those pieces are then reported undecided."""
    try:
        space.resolve({axis.name: axis.start})
        return
    except ParameterError as first:
        error = first
    for frac in (1.0, 0.5, 0.25, 0.75):
        v = float(_split_point(Fraction(axis.start), Fraction(axis.stop), axis.log, frac)) if frac < 1 else axis.stop
        try:
            space.resolve({axis.name: v})
            return
        except ParameterError:
            continue
    raise error


def omega_name(space: ParameterSpace) -> str:
    """The name of the disk's spin parameter of the space's model (a settable name of ``space``).

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.

    Returns
    -------
    str
        ``spec.spin`` (``"Omega"`` for the built-in models).

    Raises
    ------
    ParameterError
        If the spin is a fixed number of the model, or tied / not settable in ``space``.
    """
    spec = space.model
    name = spec.spin
    if isinstance(name, str) and not name:
        raise ParameterError(f"model '{spec.name}' names no spin parameter; critical speeds need one (a matrix "
                             "model's spin is its parameter 'Omega', or the one its file names with spin = ...)")
    if not isinstance(name, str):
        raise ParameterError(f"model '{spec.name}': the disk's spin Omega is the number {name!r}, not a parameter; "
                             "critical speeds need it as a parameter")
    space.check_axis(name)
    return name


def _omega_batchable(engine: Engine, space: ParameterSpace, name: str) -> bool:
    if not engine.caps.omega_kernel:
        return False
    if any(name in names_in(e) for e in space.tied.values()):
        return False
    return engine.closed_route(space, ())


def critical_speeds(engine: Engine, space: ParameterSpace, lo: float = 1.0, hi: float = 1e5, *,
                    modes: str = "all") -> Any:
    """All onsets and re-stabilisations of squeal along the spin rate Ω in ``(lo, hi)`` [rad/s].

    Uses the certified compiled Laurent-polynomial kernel when the model has
    a closed form, the silent motion is trivial (exactly, for every Ω) and
    no tied name depends on Ω (sets it cannot certify are recomputed by exact
    root isolation; at most 16 crossings reported), otherwise
    :func:`crossings` along a logarithmic Ω axis (exact or numeric).  The
    smallest destabilizing Ω is the critical speed ``Omega_crit`` of the
    paper's Fig. 3.  Any range ``0 < lo < hi`` is handled (split into
    sub-ranges internally); a range reaching past Ω's allowed values goes
    through :func:`crossings`, which lists the piece holding invalid
    parameter sets in ``undecided_ranges``.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides (any model); the disk's spin
        (:func:`omega_name`) must be one of its settable names (not tied).
    lo, hi : float, optional
        The Ω range [rad/s], ``0 < lo < hi`` (default ``1.0`` to ``1e5``).
    modes : {"all", "disk"}
        Judge every eigenvalue (default), or leave out the modes carried by a massless pad's own tangential
        rate (:func:`crossings`).

    Returns
    -------
    CriticalSpeedResult
        Crossings along Ω (``log=True``); its ``Omega_crit`` is the first
        destabilizing one, or ``None``; ``Omega_crit_certain``,
        ``undecided_ranges`` and ``exhaustive`` state what is established.

    Raises
    ------
    ParameterError
        If Ω is fixed, tied or not settable in ``space``, the range is empty,
        reversed or not positive, or the parameters are invalid.
    """
    from ..results import CriticalSpeedResult

    name = omega_name(space)
    axis = Axis(name, lo, hi, 2, True)
    if not (0 < lo):
        raise ParameterError(f"the Omega range needs 0 < START < STOP; got {lo!r}:{hi!r}")
    _check_some_valid(space, axis)
    # a range reaching past the allowed values of Omega (1e-100 <= |Omega| <= 1e100) goes the way of `crossings`,
    # which reports the part holding invalid parameter sets as undecided (the kernel would claim a verdict there)
    valid = _valid_fn(space, name)
    if _omega_batchable(engine, space, name) and valid(hi) and valid(lo):
        from .equilibrium import parameter_vector

        p = np.array([parameter_vector(space.resolve({}))])
        roots, dirs, counts, start, status = critical_speeds_batch(engine, p, lo, hi, max_crossings=16,
                                                                   return_status=True)
        found = tuple((float(roots[0, k]), "stabilizing" if dirs[0, k] > 0 else "destabilizing")
                      for k in range(min(int(counts[0]), 16)))
        undecided: tuple[tuple[float, float], ...] = ()
        if status[0] != 0:
            _, _, und = exact_omega_crossings(engine, p[0], lo, hi)
            undecided = tuple(und) or ((lo, hi),)
        return CriticalSpeedResult(parameter=name, start=lo, stop=hi, log=True, stable_at_start=bool(start[0]),
                                   crossings=found, method="exact (certified compiled Laurent-polynomial Hurwitz "
                                   "kernel, exact rational fallback)", space=space, undecided_ranges=undecided,
                                   profile=_profile(engine, space, axis))
    r = crossings(engine, space, axis, modes=modes)
    return CriticalSpeedResult(parameter=name, start=lo, stop=hi, log=True, stable_at_start=r.stable_at_start,
                               crossings=r.crossings, method=r.method, space=space,
                               undecided_ranges=r.undecided_ranges, exhaustive=r.exhaustive, profile=r.profile,
                               carrier_at_start=r.carrier_at_start)


def critical_speeds_many(engine: Engine, space: ParameterSpace, changes: dict[str, np.ndarray], lo: float = 1.0,
                         hi: float = 1e5, max_crossings: int = 8, *, return_status: bool = False
                         ) -> tuple[np.ndarray, ...]:
    """Critical speeds for many parameter sets (arrays of settable values), batched where possible.

    Each of the ``n`` points sets ``space``'s names to the values of
    ``changes`` at that index.  Points whose silent motion is trivial, of a
    model with a closed form and no tie depending on Ω, go through the
    certified compiled kernel of
    :func:`~brakesqueal.analysis.kernels.critical_speeds_batch` (every
    stability change in ``(lo, hi)``, exact fallback per set); every other
    point through :func:`critical_speeds` one by one (exact or numeric).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides (any model).
    changes : dict of str to array_like
        Settable names of ``space`` → values in their SI units; scalars and
        1-D arrays, broadcast to a common length ``n`` (an empty dict gives
        one point: ``space`` itself).
    lo, hi : float, optional
        The Ω range [rad/s], ``0 < lo < hi`` (default ``1.0`` to ``1e5``).
    max_crossings : int, optional
        Columns of the output arrays (default 8); further crossings are only
        counted.
    return_status : bool, optional
        Also return a per-set status (``PointStatus.OK``: complete and
        exhaustive; ``PointStatus.UNDECIDED``: a part of the range is
        undecided or the search was not exhaustive, so an onset may be
        missing).

    Returns
    -------
    crossings : ndarray, shape (n, max_crossings)
        Ω values [rad/s] where stability changes, ascending, NaN-padded.
    directions : ndarray of int8, shape (n, max_crossings)
        ``-1`` destabilizing (stable below, unstable above), ``+1`` stabilizing.
    counts : ndarray of int64, shape (n,)
        Number of crossings found (may exceed ``max_crossings``).
    stable_at_start : ndarray of bool, shape (n,)
        Verdict just above ``lo``.
    status : ndarray of int8, shape (n,), only with ``return_status``

    Raises
    ------
    ParameterError
        If a name is tied or not settable, Ω is not a settable parameter, the
        range is not ``0 < lo < hi``, or a point has invalid parameters.
    """
    from .equilibrium import trivial_rows
    from .points import valid_points

    name = omega_name(space)
    Axis(name, lo, hi, 2, True)
    names = list(changes)
    for n in names:
        space.check_axis(n)
    n_pts = np.broadcast(*changes.values()).size if changes else 1
    cols = {k: np.broadcast_to(np.asarray(v, dtype=float), (n_pts,)) for k, v in changes.items()}
    if cols:
        arr = space.arrays(cols)
        valid = np.broadcast_to(valid_points(space, arr), (n_pts,))
        if not valid.all():
            i = int(np.flatnonzero(~valid)[0])
            space.resolve({k: float(v[i]) for k, v in cols.items()})  # raises the one-line message
            raise ParameterError(f"invalid parameters at point {i} of critical_speeds_many")
    else:
        space.resolve({})
        arr = space.arrays({})
    vecs = space.vectors(arr)
    P = np.stack([np.broadcast_to(np.asarray(v, dtype=float), (n_pts,)) for v in vecs], axis=1)
    roots = np.full((n_pts, max_crossings), np.nan)
    dirs = np.zeros((n_pts, max_crossings), dtype=np.int8)
    counts = np.zeros(n_pts, dtype=np.int64)
    start = np.zeros(n_pts, dtype=bool)
    status = np.zeros(n_pts, dtype=np.int8)
    fast = np.zeros(n_pts, dtype=bool)
    if (engine.caps.omega_kernel and not any(name in names_in(e) for e in space.tied.values())
            and _valid_fn(space, name)(hi)):  # else per set by critical_speeds (invalid parts undecided)
        fast = trivial_rows(engine.compiled, P)[0]  # the one triviality decision
    ix = np.flatnonzero(fast)
    if ix.size:
        r, d, c, s0, st = critical_speeds_batch(engine, P[ix], lo, hi, max_crossings, return_status=True)
        roots[ix], dirs[ix], counts[ix], start[ix] = r, d, c, s0
        status[ix] = np.where(st != 0, int(PointStatus.UNDECIDED), int(PointStatus.OK))
    for i in (int(j) for j in np.flatnonzero(~fast)):
        sub = space.with_values({k: float(v[i]) for k, v in cols.items()})
        res = critical_speeds(engine, sub, lo, hi)
        found = list(res.crossings)  # type: ignore[attr-defined]
        for k, (v, dd) in enumerate(found[:max_crossings]):
            roots[i, k] = v
            dirs[i, k] = 1 if dd == "stabilizing" else -1
        counts[i] = len(found)
        start[i] = bool(res.stable_at_start)  # type: ignore[attr-defined]
        status[i] = int(PointStatus.OK) if res.complete else int(PointStatus.UNDECIDED)  # type: ignore[attr-defined]
    if return_status:
        return roots, dirs, counts, start, status
    return roots, dirs, counts, start


def critical_speeds_batch(engine: Engine, params: np.ndarray, lo: float, hi: float, max_crossings: int = 8, *,
                          return_status: bool = False) -> tuple[np.ndarray, ...]:
    """All stability changes along Ω in ``(lo, hi)`` for many parameter vectors (trivial silent motion).

    Each set is first handled by the certified compiled kernel
    (:func:`~._compiled.critical_batch`); sets it cannot certify (roots
    closer than 2^-40 relative, a root at ``lo``/``hi``, overflow) are
    recomputed by exact rational root isolation
    (:func:`exact_omega_crossings`).  The result is complete: every
    stability change in ``(lo, hi)`` is reported (up to ``max_crossings``
    columns; ``counts`` holds the true number).

    Parameters
    ----------
    engine : Engine
        The model's engine; it needs the critical-speed kernel (:attr:`Capabilities.omega_kernel
        <brakesqueal.codegen.engine.Capabilities.omega_kernel>`).
    params : ndarray, shape (n, n_parameters)
        Parameter vectors in the model's packing order (Ω ignored); the
        silent motion of every row must be trivial (for the paper's model
        ``mu1 h10 = mu2 h20``, eq. 49).
    lo, hi : float
        The Ω range [rad/s], ``0 < lo < hi``; any width (split internally).
    max_crossings : int
        Columns of the outputs.
    return_status : bool
        Also return the per-set status (0 complete, 5 undecided somewhere in the range).

    Returns
    -------
    crossings : ndarray (n, max_crossings)
        Ω values [rad/s] where stability changes, ascending, NaN-padded.
    directions : ndarray (n, max_crossings) int8
        ``-1`` destabilizing (stable below, unstable above), ``+1`` stabilizing.
    counts : ndarray (n,)
        Number of crossings found (may exceed ``max_crossings``).
    stable_at_start : ndarray (n,) bool
        Verdict just above ``lo``.
    status : ndarray (n,) int8, only with ``return_status``
        0 if the result is complete, 5 if a part of the range stayed undecided.
    """
    from ._compiled import PARALLEL_MIN, critical_batch, critical_batch_chunks

    P = np.ascontiguousarray(np.atleast_2d(params), dtype=float)
    n = P.shape[0]
    bounds = omega_subranges(float(lo), float(hi))
    roots = np.full((n, max_crossings), np.nan)
    dirs = np.zeros((n, max_crossings), dtype=np.int8)
    counts = np.zeros(n, dtype=np.int64)
    start = np.zeros(n, dtype=np.bool_)
    flags = np.zeros(n, dtype=np.uint8)
    status = np.zeros(n, dtype=np.int8)
    E, R = omega_entries(engine, P)
    if n >= PARALLEL_MIN:
        critical_batch_chunks(E, R, bounds, roots, dirs, counts, start, flags, max(1, n // (PARALLEL_MIN // 4)))
    else:
        critical_batch(E, R, bounds, roots, dirs, counts, start, flags)
    for i in np.flatnonzero(flags):
        st, found, undecided = exact_omega_crossings(engine, P[i], float(lo), float(hi))
        roots[i] = np.nan
        dirs[i] = 0
        for k, (v, d) in enumerate(found[:max_crossings]):
            roots[i, k] = v
            dirs[i, k] = 1 if d == "stabilizing" else -1
        counts[i] = len(found)
        start[i] = bool(st)
        status[i] = 5 if undecided else 0
    if return_status:
        return roots, dirs, counts, start, status
    return roots, dirs, counts, start
