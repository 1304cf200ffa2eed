r"""Generated stability kernels: their sources, data types and on-disk cache (no computer algebra here).

What :mod:`brakesqueal.symbolic.stability_forms` computes once per model (or per
parameter space and axes) becomes source text or JSON tables here, kept in
the on-disk cache (:mod:`.cache`) and loaded as compiled callables:

* :class:`GridKernel` / :class:`MapKernel` — the certified compiled Hurwitz
  classifier of a grid: the exact numerators of the characteristic quartic
  as polynomials in one *inner* axis whose coefficients are monomials in the
  other axes (:func:`kernel_source`; rows evaluated in exponent-scaled
  floating point with error bounds by :mod:`._rows`);
* bounded closed-form entries (:func:`bounded_source`): ``Mbar, Dbar, Kbar``
  (or their Laurent coefficients in Ω) with rigorous rounding bounds;
* :class:`RateBlocks` — the pads' simplified zero-state rate blocks;
* :class:`CharpolyTable` — the exact characteristic polynomial of a zero
  state of any size on two axes.

:class:`~.engine.Engine` builds them lazily, once per model.
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

__all__ = ["GridKernel", "MapKernel", "RateBlocks", "CharpolyTable", "kernel_source", "bounded_source",
           "rate_source", "load_generated", "load_keyed", "disk_json", "inner_exponent", "kernel_segments",
           "charpoly_from_data", "plain_module"]

_U = 2.0 ** -53


@dataclass(frozen=True)
class GridKernel:
    """Compiled, certified Hurwitz classifier over the axes of a grid.

    Attributes
    ----------
    names : tuple of str
        All axes; ``inner`` is the index of the contiguous (fast) one, chosen
        as the axis in which the numerators have the lowest degrees.
    degrees : tuple of int
        Degree of ``N_0..N_4`` in the inner axis.
    exps, slot, mant, e2 : ndarray
        Coefficient table: term ``t`` contributes
        ``mant[t] 2^e2[t] Π_j outer_j^exps[t, j]`` to column ``slot[t]``
        (``slot`` enumerates ``(i, k)``: coefficient of ``inner^k`` in ``N_i``),
        with the inner power ``ipow[t]``.
    ipow : ndarray
        Inner exponent of every term.
    nops : ndarray
        Per column, a bound on the floating-point operations of its evaluation.
    classify : callable
        ``classify(C, EC, t, seg, Tseg, out)``: 0 unstable, 1 stable, 2
        uncertain at ``(row i, inner t[j])`` (see :func:`kernel_source`,
        :func:`kernel_segments`; :func:`run_classify` wraps it).
    coefficients : callable
        ``coefficients(C, t, out)`` writes ``a0..a4`` (scaled) to ``out[5, rows, n_inner]``.
    source : str
        Generated kernel source.
    """

    names: tuple[str, ...]
    inner: int
    degrees: tuple[int, ...]
    exps: np.ndarray
    ipow: np.ndarray
    slot: np.ndarray
    mant: np.ndarray
    e2: np.ndarray
    nops: np.ndarray
    classify: Callable[..., None]
    coefficients: Callable[..., None]
    source: str

    def row_coefficients(self, outer: list[np.ndarray], inner_exp: int) -> tuple[np.ndarray, np.ndarray]:
        """Per-row coefficient table ``C`` and its absolute error bound ``EC``.

        Parameters
        ----------
        outer : list of ndarray
            Values of the outer axes (``names`` without ``inner``), each of
            length ``rows``.
        inner_exp : int
            The inner variable is ``t = inner / 2^inner_exp``.

        Returns
        -------
        C, EC : ndarray, shape (rows, Σ(degrees + 1))
            Coefficients of ``t^k`` in ``N_i`` (column blocks ``i = 0..4``),
            each row multiplied by one positive power of two (balanced with
            ``λ -> 2^e λ`` and normalised); ``EC`` bounds their errors.
        """
        C, EC, _ = self.row_tables(outer, inner_exp)
        return C, EC

    def row_tables(self, outer: list[np.ndarray], inner_exp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`row_coefficients` and, per row, the exponent ``e`` of its balancing ``λ = 2^e ν``.

        Returns
        -------
        C, EC : ndarray
            As :meth:`row_coefficients`.
        lam_e : ndarray of int64, shape (rows,)
            The roots ``ν`` of a row's scaled quartic times ``2^lam_e`` are the eigenvalues ``λ`` [1/s].
        """
        from ._rows import normalise_rows, rows_eval

        n_rows = int(np.size(outer[0])) if outer else 1
        ncol = int(sum(d + 1 for d in self.degrees))
        nout = len(outer)
        Um = np.empty((n_rows, max(nout, 1)))
        Qe = np.zeros((n_rows, max(nout, 1)), dtype=np.int64)
        for j, v in enumerate(outer):
            m, e = np.frexp(np.asarray(v, dtype=float))
            Um[:, j], Qe[:, j] = m, e
        e2 = self.e2 + inner_exp * self.ipow
        C = np.zeros((n_rows, ncol))
        EC = np.zeros((n_rows, ncol))
        lam_e = np.zeros(n_rows, dtype=np.int64)
        rows_eval(self.exps, self.slot, self.mant, e2, Um, Qe, self.nops, C, EC)
        normalise_rows(C, EC, np.array(self.degrees, dtype=np.int64), lam_e)
        bad = ~(np.all(np.isfinite(C), axis=1) & np.all(np.isfinite(EC), axis=1))
        if bad.any():  # such rows are classified uncertain (a4 = 0 with an infinite bound)
            C[bad] = 0.0
            EC[bad] = np.inf
        return C, EC, lam_e


def kernel_source(degrees: tuple[int, ...]) -> str:
    """Numba source of the certified classifier for inner-axis degrees ``degrees`` of ``N_0..N_4``.

    Two passes per row: a vectorizable pass with one error bound per row
    (valid for every ``|t| <= max|t|``), then, only for the rare points it
    leaves uncertain, a scalar pass with the point's own (tighter) bounds.
    """
    offs = np.concatenate([[0], np.cumsum([d + 1 for d in degrees])]).tolist()
    load = "; ".join(f"c{i}_{k} = C[i, {offs[i] + k}]" for i in range(5) for k in range(degrees[i] + 1))
    gam = [(2 * d + 4) * _U * 1.0001 for d in degrees]
    loadb = "\n".join(f"        b{i}_{k} = EC[i, {offs[i] + k}] + {gam[i]!r} * abs(c{i}_{k})"
                      for i in range(5) for k in range(degrees[i] + 1))

    def horner(i: int, pre: str, var: str, wrap: str = "") -> str:
        d = degrees[i]
        expr = f"{wrap}({pre}{i}_{d})" if wrap else f"{pre}{i}_{d}"
        for k in range(d - 1, -1, -1):
            term = f"{wrap}({pre}{i}_{k})" if wrap else f"{pre}{i}_{k}"
            expr = f"({term} + {var} * {expr})"
        return expr

    def indent(text: str, n: int) -> str:
        return "\n".join(" " * n + ln for ln in text.splitlines())

    poly = "\n".join(f"a{i} = {horner(i, 'c', 'x')}" for i in range(5))
    rowb = "\n".join(f"E{i} = ({horner(i, 'b', 'T')}) * 1.0000000001 + 1e-300" for i in range(5))
    rowB = "\n".join(f"B{i} = {horner(i, 'c', 'T', 'abs')} * 1.0000000001 + E{i}" for i in range(5))
    ehrow = ("ehb = (E1 * B3 * B2 + B1 * E3 * B2 + B1 * B3 * E2 + E4 * B1 * B1 + 2.0 * B4 * E1 * B1\n"
             "       + 2.0 * E3 * B3 * B0 + B3 * B3 * E0 + 1.2e-15 * (B1 * B3 * B2 + B4 * B1 * B1 + B3 * B3 * B0))"
             " * 1.0000001 + 1e-300")
    test = ("s = math.copysign(1.0, a4)\n"
            "d0 = s * a0\nd1 = s * a1\nd2 = s * a2\nd3 = s * a3\n"
            "h = d1 * (d3 * d2 - abs(a4) * d1) - d3 * d3 * d0\n"
            "sg = abs(a4) > E4\n"
            "st = sg & (d0 > E0) & (d1 > E1) & (d2 > E2) & (d3 > E3) & (h > ehb)\n"
            "ng = sg & ((d0 < -E0) | (d1 < -E1) | (d2 < -E2) | (d3 < -E3) | (h < -ehb))")
    # pass 1: d_k / E_k > 1 for all k <=> certified stable, < -1 for one k <=> certified unstable; the
    # reciprocals are rounded down by 4.5e-16 so that fl(d_k r_k) > 1 implies d_k > E_k (no NaN can occur:
    # finite tables, |t|^deg < 2^300, see kernel_scaling and GridKernel.row_coefficients)
    fast = ("s = math.copysign(1.0, a4)\n"
            "d0 = s * a0\nd1 = s * a1\nd2 = s * a2\nd3 = s * a3\n"
            "h = d1 * (d3 * d2 - abs(a4) * d1) - d3 * d3 * d0\n"
            "sg = abs(a4) > E4\n"
            "m = min(min(min(d0 * r0, d1 * r1), min(d2 * r2, d3 * r3)), h * rh)")
    ehpt = ("A0 = abs(a0) + E0\nA1 = abs(a1) + E1\nA2 = abs(a2) + E2\nA3 = abs(a3) + E3\nA4 = abs(a4) + E4\n"
            "ehb = (E1 * A3 * A2 + abs(a1) * E3 * A2 + abs(a1 * a3) * E2 + E4 * A1 * A1"
            " + abs(a4) * E1 * (A1 + abs(a1))\n"
            "       + E3 * (A3 + abs(a3)) * A0 + a3 * a3 * E0 + 1.2e-15 * (A1 * A3 * A2 + A4 * A1 * A1 + A3 * A3 * A0))"
            " * 1.0000001 + 1e-300")
    lines = [
        f'"""Generated by brakesqueal.codegen.stability (degrees {degrees}). Do not edit."""',
        "import math", "", "import numba", "import numpy as np", "", "",
        '@numba.njit(cache=True, fastmath={"contract"}, error_model="numpy", boundscheck=False)',
        "def classify(C, EC, t, seg, Tseg, out):",
        '    """Certified Hurwitz verdict: out[i, j] = 1 stable, 0 unstable, 2 uncertain at (row i, inner t[j]).',
        "",
        "    a_k = Horner(C row, t) with |error| <= E_k (coefficient bounds EC plus Horner rounding);",
        "    s = sign(a4) per point (a common denominator of any sign drops out), d_k = s a_k and",
        "    s H3 = d1 (d3 d2 - |a4| d1) - d3^2 d0; H3's error bound",
        "    follows from the E_k by interval reasoning.  Pass 1 uses one bound per segment",
        "    t[seg[q]:seg[q+1]] (valid for |t| <= Tseg[q]), pass 2 re-tests its uncertain points",
        "    with their own bounds.",
        '    """',
        "    n = t.shape[0]",
        "    for i in range(C.shape[0]):",
        f"        {load}",
        loadb,
        "        orow = out[i]",
        "        for q in range(seg.shape[0] - 1):",
        "            T = Tseg[q]",
        indent(rowb, 12), indent(rowB, 12), indent(ehrow, 12),
        "            r0 = (1.0 / E0) * (1.0 - 4.5e-16)",
        "            r1 = (1.0 / E1) * (1.0 - 4.5e-16)",
        "            r2 = (1.0 / E2) * (1.0 - 4.5e-16)",
        "            r3 = (1.0 / E3) * (1.0 - 4.5e-16)",
        "            rh = (1.0 / ehb) * (1.0 - 4.5e-16)",
        "            ts = t[seg[q]:seg[q + 1]]",
        "            o = orow[seg[q]:seg[q + 1]]",
        "            for j in range(ts.shape[0]):",
        "                x = ts[j]",
        indent(poly, 16), indent(fast, 16),
        "                o[j] = 2 - (sg & (m > 1.0)) - 2 * (sg & (m < -1.0))",
        "        o = orow",
        "        nu = np.uint8(0)",
        "        for j in range(n):",
        "            nu = max(nu, o[j])",
        "        if nu < 2:",
        "            continue",
        "        for j in range(n):",
        "            if o[j] != 2:",
        "                continue",
        "            x = t[j]",
        "            T = abs(x)",
        indent(rowb, 12), indent(poly, 12), indent(ehpt, 12), indent(test, 12),
        "            o[j] = 1 if st else (0 if ng else 2)",
        "", "",
        '@numba.njit(cache=True, fastmath={"contract"}, error_model="numpy", boundscheck=False)',
        "def coefficients(C, t, out):",
        '    """Scaled quartic numerators: out[k, i, j] = N_k at (row i, inner t[j]) (no error bound)."""',
        "    for i in range(C.shape[0]):",
        f"        {load}",
        "        for j in range(t.shape[0]):",
        "            x = t[j]",
        indent(poly, 12),
    ]
    lines += [f"            out[{i}, i, j] = a{i}" for i in range(5)]
    return "\n".join(lines) + "\n"


def inner_exponent(values: np.ndarray) -> int:
    """Power-of-two scale of an inner axis: ``t = value / 2^e`` has magnitudes near one."""
    a = np.abs(np.asarray(values, dtype=float))
    a = a[np.isfinite(a) & (a > 0)]
    if a.size == 0:
        return 0
    return int(round(0.5 * (math.log2(a.min()) + math.log2(a.max()))))


def kernel_segments(t: np.ndarray, min_len: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Segments of the inner values for the kernel's first pass: ``|t|`` within a factor 8, at least ``min_len`` long.

    Returns ``(seg, Tseg)``: boundaries ``seg[0] = 0 < ... < seg[-1] = len(t)``
    and the largest ``|t|`` of every segment (the error bounds hold for every
    point of a segment; longer segments only make them looser).
    """
    a = np.abs(np.asarray(t, dtype=float))
    n = a.size
    if n == 0:
        return np.array([0], dtype=np.int64), np.zeros(0)
    with np.errstate(divide="ignore", invalid="ignore"):
        cls = np.where(a > 0, np.floor(np.log2(np.where(a > 0, a, 1.0)) / 3.0), -1e6)
    cls[~np.isfinite(a)] = 1e6
    cuts = np.flatnonzero(np.diff(cls)) + 1
    seg = [0]
    for c in cuts:
        if c - seg[-1] >= min_len:
            seg.append(int(c))
    if n - seg[-1] < min_len and len(seg) > 1:
        seg.pop()
    seg.append(n)
    segs = np.array(seg, dtype=np.int64)
    with np.errstate(invalid="ignore"):
        T = np.maximum.reduceat(a, segs[:-1])
    return segs, T


# ---------------------------------------------------------------- 2-D map kernel
@dataclass(frozen=True)
class MapKernel:
    """The grid kernel of a 2-D map, with the axis roles named.

    Attributes
    ----------
    outer, inner : str
        Axis names; the inner axis is the contiguous (fast) one.
    degrees : tuple of int
        Degree of ``N_0..N_4`` in the inner axis.
    grid : GridKernel
        The underlying kernel.
    """

    outer: str
    inner: str
    degrees: tuple[int, ...]
    grid: GridKernel

    @property
    def classify(self) -> Callable[..., None]:
        """``classify(C, EC, t, seg, Tseg, out)`` (see :class:`GridKernel`, :func:`run_classify`)."""
        return self.grid.classify

    @property
    def coefficients(self) -> Callable[..., None]:
        """``coefficients(C, t, out)`` (see :class:`GridKernel`)."""
        return self.grid.coefficients

    @property
    def source(self) -> str:
        """Generated kernel source."""
        return self.grid.source

    def row_coefficients(self, outer_values: np.ndarray, inner_exp: int) -> tuple[np.ndarray, np.ndarray]:
        """``(C, EC)`` per outer value for ``t = inner / 2^inner_exp`` (see :meth:`GridKernel.row_coefficients`)."""
        return self.grid.row_coefficients([np.asarray(outer_values, dtype=float)], inner_exp)

    def row_tables(self, outer_values: np.ndarray, inner_exp: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(C, EC, lam_e)`` per outer value (see :meth:`GridKernel.row_tables`)."""
        return self.grid.row_tables([np.asarray(outer_values, dtype=float)], inner_exp)

    def verdicts(self, outer_values: np.ndarray, inner_values: np.ndarray) -> np.ndarray:
        """Verdict codes ``(n_outer, n_inner)``: 0 unstable, 1 stable, 2 uncertain."""
        e = inner_exponent(inner_values)
        C, EC = self.row_coefficients(outer_values, e)
        t = np.ascontiguousarray(np.ldexp(np.asarray(inner_values, dtype=float), -e))
        out = np.empty((C.shape[0], t.size), dtype=np.uint8)
        seg, T = kernel_segments(t)
        self.classify(C, EC, t, seg, T, out)
        return out


def bounded_source(fname: str, slots: list[list[tuple[float, dict[int, int]]]], doc: str, nparams: int) -> str:
    """Numba source ``fname(P, V, R)``: ``V[n, s]`` = Σ terms of slot ``s``, ``R[n, s]`` its rounding bound."""
    lines = [f'"""Generated by brakesqueal.codegen.stability: {doc}. Do not edit."""', "import numba", "", "",
             '@numba.njit(cache=True, error_model="numpy")', f"def {fname}(P, V, R):",
             f'    """{doc}; R bounds the rounding error of V."""',
             "    for n in range(P.shape[0]):", "        p = P[n]"]
    lines.append("        " + ", ".join(f"x{i}" for i in range(nparams)) + " = "
                 + ", ".join(f"p[{i}]" for i in range(nparams)))
    for s, terms in enumerate(slots):
        if not terms:
            lines.append(f"        V[n, {s}] = 0.0")
            lines.append(f"        R[n, {s}] = 0.0")
            continue
        lines.append("        v = 0.0")
        lines.append("        a = 0.0")
        kmax = 0
        for c, powers in terms:
            fac = [repr(float(c))]
            ops = 1
            for i, k in sorted(powers.items()):
                if k > 0:
                    fac.extend([f"x{i}"] * k)
                ops += abs(k)
            den = [f"x{i}" for i, k in sorted(powers.items()) for _ in range(-k)]
            expr = " * ".join(fac)
            if den:
                expr = f"({expr}) / ({' * '.join(den)})"
            kmax = max(kmax, ops)
            lines.append(f"        t = {expr}")
            lines.append("        v += t")
            lines.append("        a += abs(t)")
        g = (kmax + len(terms) + 4) * _U * 1.001
        lines.append(f"        V[n, {s}] = v")
        lines.append(f"        R[n, {s}] = {g!r} * a + 1e-300")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, eq=False)
class CharpolyTable:
    """``det(λ²M + λD + K)`` of a model's zero state as a polynomial in ``λ`` and two axes (exact, then rounded).

    Attributes
    ----------
    outer, inner : str
        The axes (settable names): ``x`` and ``y`` of the table.
    Q : ndarray, shape (2n + 1, da + 1, db + 1)
        ``Q[k, a, b]``: coefficient of ``λ^k x^a y^b`` rounded to the nearest
        double (the exact polynomial has rational coefficients; each row of the
        pencil was multiplied by the least common multiple of its entries'
        denominators, a polynomial in ``x, y`` that does not change the roots
        where it does not vanish — and where it vanishes every coefficient does).
    RQ : ndarray
        Rounding radii of ``Q``.
    """

    outer: str
    inner: str
    Q: np.ndarray
    RQ: np.ndarray

    @property
    def degree(self) -> int:
        """Degree ``2n`` in ``λ``."""
        return int(self.Q.shape[0] - 1)


def charpoly_from_data(outer: str, inner: str, data: dict[str, Any] | None) -> CharpolyTable | None:
    """A :class:`CharpolyTable` from its JSON data (:func:`brakesqueal.symbolic.stability_forms.charpoly_data`)."""
    if data is None:
        return None
    shape = tuple(int(v) for v in data["shape"])
    Q = np.array([[float.fromhex(v) for v in row] for row in data["q"]]).reshape(shape)
    big = float(np.max(np.abs(Q)))
    if big > 0:  # an exact power-of-two scaling (the row multipliers make the integers huge): no overflow later
        Q = np.ldexp(Q, -math.frexp(big)[1])
    RQ = np.abs(Q) * _U + np.where(Q != 0, 2.0 ** -1074, 0.0)
    return CharpolyTable(outer, inner, np.ascontiguousarray(Q), np.ascontiguousarray(RQ))


@dataclass(frozen=True, eq=False)
class RateBlocks:
    """The pads' rate blocks of a model at the zero state, simplified symbolically (no cancellation noise).

    At the zero state a massless pad's rate terms are differences of terms
    that cancel exactly for a constant friction coefficient (the derivative of
    the sliding direction along the sliding velocity vanishes); generated
    code evaluates such differences to rounding noise, which would give a
    spurious pad mode ``-G_L / G_dL`` of any sign.  These are simplified
    (:func:`brakesqueal.symbolic.stability_forms.rate_block_exprs`), so only the
    genuine part remains (e.g. ``c_ip N0 mu'(v*)`` of a falling friction law)
    and an exact zero stays zero.

    Attributes
    ----------
    n, m : int
        Coordinates and pad deformations.
    function : callable
        The generated ``rate_blocks(*p)`` (NumPy-bound; packing-order parameters).
    """

    n: int
    m: int
    function: Callable[..., Any]

    def evaluate(self, cols: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(R_dL, G_dL, G_ddQ)`` for packing-order parameter arrays of length ``N``.

        Returns arrays of shapes ``(N, n, m)``, ``(N, m, m)``, ``(N, m, n)``.
        """
        n, m = self.n, self.m
        N = int(np.size(cols[0])) if cols else 1
        with np.errstate(all="ignore"):
            raw = self.function(*cols) if (n * m + m * m + m * n) else ()
            vals = [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in raw]
        a = np.stack(vals, axis=-1) if vals else np.zeros((N, 0))
        k1, k2 = n * m, n * m + m * m
        return a[:, :k1].reshape(N, n, m), a[:, k1:k2].reshape(N, m, m), a[:, k2:].reshape(N, m, n)


def rate_source(args: list[Any], exprs: list[Any]) -> str:
    """NumPy source of ``rate_blocks(*p)`` returning the simplified rate-block expressions (SymPy printer)."""
    from sympy.printing.numpy import NumPyPrinter

    pr = NumPyPrinter({"fully_qualified_modules": True, "inline": True, "allow_unknown_functions": False})
    names = [f"p{k}" for k in range(len(args))]
    sub = {a: __import__("sympy").Symbol(nm) for a, nm in zip(args, names)}
    body = ", ".join(pr.doprint(e.xreplace(sub)) for e in exprs)
    return ('"""Generated by brakesqueal.codegen.stability: zero-state rate blocks (R_dL, G_dL, G_ddQ). '
            'Do not edit."""\nimport numpy\n\n\n'
            f"def rate_blocks({', '.join(names)}):\n    return ({body}{',' if exprs else ''})\n")


def load_generated(source: str, tag: str, *, use_cache: bool = True) -> Any:
    """Import generated kernel source from the on-disk cache (numba caches beside it), keyed by its content."""
    from . import cache

    digest = hashlib.sha256(source.encode()).hexdigest()[:16]
    return cache.load_module("stability-kernels", f"brakesqueal_kernel_{tag}_{digest}.py", lambda: source,
                             use_cache=use_cache)


def load_keyed(tag: str, key: str, generate: Callable[[], str], *, plain: bool = False,
               use_cache: bool = True) -> Any:
    """Import a generated module named by a model key; ``generate`` (SymPy) only runs on a cache miss.

    With ``plain`` the same cached source runs as plain Python (``numba.njit`` a no-op): for a few points that is
    faster than importing numba and loading machine code (the command line's ``linearize``); the arithmetic is
    the same IEEE double precision (the kernels use no ``fastmath``).
    """
    from . import cache

    name = f"brakesqueal_kernel_{tag}_{key}.py"
    if not plain:
        return cache.load_module("stability-kernels", name, generate, use_cache=use_cache)
    source = cache.cached_text("stability-kernels", name, generate, use_cache=use_cache)
    return plain_module(source, f"<brakesqueal plain {name}>")


class _NoJit:
    """Stands in for ``numba`` when generated kernels run as plain Python: ``njit`` returns the function."""

    @staticmethod
    def njit(*args: Any, **kwargs: Any) -> Any:
        if args and callable(args[0]):
            return args[0]
        return lambda f: f


_PLAIN: dict[str, Any] = {}


def plain_module(source: str, label: str, package: str | None = None) -> Any:
    """A numba module's source executed as plain Python (memoized by its source; ``numba.njit`` a no-op).

    ``label`` names it in tracebacks; ``package`` anchors its relative imports.
    """
    import types

    digest = hashlib.sha256(source.encode()).hexdigest()
    if digest not in _PLAIN:
        mod = types.ModuleType(label)
        mod.__dict__.update(numba=_NoJit, __package__=package)
        text = re.sub(r"(?m)^import numba\n", "", source, count=1)
        exec(compile(text, label, "exec"), mod.__dict__)  # noqa: S102 (the package's own generated source)
        _PLAIN[digest] = mod
    return _PLAIN[digest]


def disk_json(kind: str, ident: str, make: Callable[[], Any], *, use_cache: bool = True) -> Any:
    """A JSON-able value built once and kept in the on-disk cache (so that warm starts need no SymPy).

    Keyed by ``kind`` and a hash of ``ident`` (model key, space key, axes); the
    cache's fingerprint covers the generators, so editing one rebuilds it.
    """
    import json

    from . import cache

    name = f"{kind}-{hashlib.sha256(ident.encode()).hexdigest()[:24]}.json"
    return json.loads(cache.cached_text("stability-tables", name, lambda: json.dumps(make()), use_cache=use_cache))
