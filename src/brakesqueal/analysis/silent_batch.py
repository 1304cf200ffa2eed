r"""Silent motions of many parameter points at once: a compiled, batched Newton stage with hand-over.

:func:`~.equilibrium.silent_motion` finds the silent motion of one point in
two stages: Newton's method from the trivial state (scaled unknowns and rows,
abandoned as soon as the steps stop contracting), and, where that does not
converge cleanly, the globalised solver (pseudo-arclength continuation of the
Newton homotopy).  This module runs the **first stage for many points in one
compiled loop** (numba, generated per model from the same source as
:class:`~brakesqueal.codegen.compiled.CompiledModel`), with the same
scaling, the same iteration and the same convergence test as the Newton
stage of :func:`~.equilibrium.silent_motion_vector`; so a point it accepts has the
silent motion the per-point route finds (the same root, equal to rounding).

Every point it does not accept cleanly is **handed to the per-point solver**
(:func:`~.equilibrium.silent_motion_vector`), whose status (by the type of
its failure) and value are then used as they are:

* the Newton stage did not converge, left the kinematics' range, or met a
  singular or non-finite Jacobian;
* a pad's normal force or sliding speed at the solution is near its limit
  (``F_n <= 1e-7 max(|F_n(0)|, |F_n|)``, the same for ``|v_r|``), where the
  rounding difference between two evaluations could change the sign;
* the point's residuals at the trivial state vanish to rounding (the trivial
  silent motion, ``q0 = 0``: decided as in :func:`~.equilibrium.silent_motion`,
  not by Newton).

Statuses are therefore those of the per-point route by construction: the
batched stage never reports a failure (no false failures); it only skips the
per-point solver where that solver's first stage would have succeeded.

The kernel is compiled by numba on first use per model (seconds; cached on
disk beside the generated source).  :func:`brakesqueal.analysis.points.evaluate_arrays`
therefore sends fewer than :data:`COMPILE_MIN` points through the per-point
solver unless the kernel is ready (:func:`kernel_ready`).

**Why the Newton stage starts from the trivial state, not from a neighbour's
solution.**  The silent motion of a point is the one connected to the trivial
state (:mod:`~.equilibrium`).  A Newton iteration warm-started from the
neighbouring grid point's solution converges to the root that *continues the
neighbour's*, which is a property of the grid, not of the point: where the
homotopy from the trivial state folds (no silent motion, an established
status) the neighbour's branch may still continue, and a warm start would
report a silent motion the per-point route does not have (measured: the
paper's model with ``general`` values, ``mu1 = 1.68``, soft ``k_t``: for
``k_t`` below about 1.1e4 the homotopy folds, while Newton warm-started along
``k_t`` from the stiffer neighbour converges to admissible tilts all the way
down to ``k_t = 1``; ``tests/analysis/test_silent_batch.py``).  The start from the
trivial state costs a few iterations more (:attr:`SilentMotions.iterations
<brakesqueal.analysis.equilibrium.SilentMotions.iterations>`)
and keeps every point's result independent of the grid.
"""

from __future__ import annotations

import re
import types
from typing import Any

from ..numeric import cache

__all__ = ["kernel_source", "load_kernel", "kernel_ready", "KERNEL_NAME", "HANDOVER", "COMPILE_MIN"]

#: File name of the kernel module in the model's cache entry.
KERNEL_NAME = "silent.py"

#: Reasons a point is handed to the per-point solver (codes of :attr:`.equilibrium.SilentMotions.handover`).
HANDOVER = {
    0: "accepted by the compiled Newton stage",
    1: "Newton from the trivial state did not converge cleanly (per-point globalised solver)",
    2: "a pad's normal force or sliding speed near its limit (per-point solver decides)",
    3: "non-finite residuals or Jacobian (per-point solver decides)",
    4: "trivial silent motion (decided to rounding, no Newton)",
}

#: Fewest points for which the batched route compiles its kernel (numba, seconds on first use per model) when its
#: machine code is not at hand; fewer points go through the per-point solver (~1 ms each).
COMPILE_MIN = 2000

_DECORATOR = '@njit(cache=True, error_model="numpy")'
_READY: set[tuple[str, bool]] = set()

_PREAMBLE = '''import math
from math import sin, cos, tan, sqrt, exp, log, pi

import numpy as np
from numba import njit

_N = {n}  # coordinates Q
_M = {m}  # pad deformations L
_NPAD = {npad}  # pads
_NF = {nf}  # contact fields per pad
_TILTING = {tilting}  # the disk tilts: |q1|, |q2| < MAX_TILT
'''

# The static part: scaled Newton from the trivial state, exactly the iteration of equilibrium.newton_from_trivial.
_TEMPLATE = r'''

@njit(cache=True, error_model="numpy")
def _lu_solve(A, b, x):
    """Solve A x = b by Gaussian elimination with partial pivoting (A, b overwritten); False if singular."""
    k = A.shape[0]
    for c in range(k):
        piv = c
        best = abs(A[c, c])
        for r in range(c + 1, k):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                piv = r
        if not best > 0.0:
            return False
        if piv != c:
            for j in range(k):
                t = A[c, j]
                A[c, j] = A[piv, j]
                A[piv, j] = t
            t = b[c]
            b[c] = b[piv]
            b[piv] = t
        for r in range(c + 1, k):
            f = A[r, c] / A[c, c]
            if f != 0.0:
                for j in range(c + 1, k):
                    A[r, j] -= f * A[c, j]
                b[r] -= f * b[c]
    for c in range(k - 1, -1, -1):
        s = b[c]
        for j in range(c + 1, k):
            s -= A[c, j] * x[j]
        x[c] = s / A[c, c]
    return True


@njit(cache=True, error_model="numpy")
def newton_batch(P, S, floor, max_tilt, max_iter, Z, code, iters, FN, SPEED):
    """Newton from the trivial state for every row of P (scaled as equilibrium._System).

    S[i]: per residual row the magnitude of its terms at z = 0 (a residual is zero to rounding when
    |F_k| <= floor eps S_k).

    Z[i] = (Q0, L0); code[i] = 0 accepted, 1 not converged / inadmissible, 2 contact or sliding near its limit,
    3 non-finite residual or Jacobian; FN, SPEED: per pad at the solution (accepted points).
    """
    K = _N + _M
    eps = 2.220446049250313e-16
    z = np.zeros(K)
    y = np.zeros(K)
    r = np.zeros(K)
    step = np.zeros(K)
    J = np.zeros((K, K))
    J0 = np.zeros((K, K))
    row = np.zeros(K)
    col = np.zeros(K)
    c0 = np.zeros((_NPAD, _NF))
    c1 = np.zeros((_NPAD, _NF))
    for i in range(P.shape[0]):
        p = P[i]
        iters[i] = 0
        for k in range(K):
            z[k] = 0.0
            y[k] = 0.0
        # equilibration at z = 0: rows by their largest entry, then columns
        static_jacobian(z, p, J0)
        bad = False
        for a in range(K):
            mx = 0.0
            for b in range(K):
                v = abs(J0[a, b])
                if not v < math.inf:
                    bad = True
                if v > mx:
                    mx = v
            row[a] = mx if mx > 0.0 else 1.0
        for b in range(K):
            mx = 0.0
            for a in range(K):
                v = abs(J0[a, b]) / row[a]
                if v > mx:
                    mx = v
            col[b] = mx if mx > 0.0 else 1.0
        if bad:
            code[i] = 3
            continue
        ok = False
        last = math.inf
        rlast = math.inf
        it = 0
        while it < max_iter:
            it += 1
            for k in range(K):
                z[k] = y[k] / col[k]
            static_residuals(z, p, r)
            finite = True
            resid = True
            for k in range(K):
                if not abs(r[k]) <= floor * eps * S[i, k]:
                    resid = False
                r[k] = -r[k] / row[k]
                if not abs(r[k]) < math.inf:
                    finite = False
            if not finite:
                break
            rsize = 0.0
            for k in range(K):
                if abs(r[k]) > rsize:
                    rsize = abs(r[k])
            stalled = rsize >= 0.5 * rlast
            rlast = rsize
            if it == 1:  # z = 0: the Jacobian of the equilibration
                for a in range(K):
                    for b in range(K):
                        J[a, b] = J0[a, b]
            else:
                static_jacobian(z, p, J)
            for a in range(K):
                for b in range(K):
                    J[a, b] = J[a, b] / row[a] / col[b]
            if not _lu_solve(J, r, step):
                break
            size = 0.0
            small = True
            ymax = 0.0
            for k in range(K):
                if not abs(step[k]) < math.inf:
                    finite = False
                y[k] += step[k]
            if not finite:
                break
            for k in range(K):
                s = abs(step[k])
                if s > size:
                    size = s
                if s > 8.0 * eps * abs(y[k]):
                    small = False
                if abs(y[k]) > ymax:
                    ymax = abs(y[k])
            if small or size == 0.0:
                ok = True
                break
            at_floor = size <= 1e-9 * ymax or resid or (stalled and size <= 1e-6 * ymax)
            if size > 0.9 * last and at_floor:
                ok = True
                break
            if it > 1 and size > 0.5 * last:
                ok = at_floor  # no longer contracting: converged only at the noise floor
                break
            last = size
            if it == max_iter:
                ok = at_floor
        iters[i] = it
        for k in range(K):
            z[k] = y[k] / col[k]
            Z[i, k] = z[k]
        if not ok:
            code[i] = 1
            continue
        admissible = True
        for k in range(K):
            if not abs(z[k]) < math.inf:
                admissible = False
        if _TILTING and (abs(z[0]) >= max_tilt or abs(z[1]) >= max_tilt):
            admissible = False
        if not admissible:
            code[i] = 1
            continue
        # contact and sliding at the solution, against their values at the trivial state
        contact_table(z, p, c1)
        for k in range(K):
            y[k] = 0.0
        contact_table(y, p, c0)
        near = False
        for j in range(_NPAD):
            fn = c1[j, 0]
            v = math.sqrt(c1[j, 1] ** 2 + c1[j, 2] ** 2 + c1[j, 3] ** 2)
            v0 = math.sqrt(c0[j, 1] ** 2 + c0[j, 2] ** 2 + c0[j, 3] ** 2)
            FN[i, j] = fn
            SPEED[i, j] = v
            if not (fn > 1e-7 * max(abs(c0[j, 0]), abs(fn)) and fn < math.inf):
                near = True
            if not (v > 1e-7 * max(v0, v) and v < math.inf):
                near = True
        code[i] = 2 if near else 0
    return None


@njit(cache=True, error_model="numpy")
def jacobian_batch(P, Z, out):
    """out[i] = d(R, G)/dx at x = (Q, 0, 0, L, 0) with z = Z[i], p = P[i] (row-major, flat)."""
    for i in range(P.shape[0]):
        full_jacobian(Z[i], P[i], out[i])
    return None
'''


def _functions(source: str, names: tuple[str, ...]) -> dict[str, str]:
    """The text of the named top-level functions of a generated module."""
    out: dict[str, str] = {}
    blocks = re.split(r"(?m)^(?=def )", source)
    for b in blocks:
        m = re.match(r"def (\w+)\(", b)
        if m and m.group(1) in names:
            out[m.group(1)] = b.rstrip() + "\n"
    missing = set(names) - set(out)
    if missing:
        raise ValueError(f"generated model source lacks {sorted(missing)}")
    return out


def kernel_source(spec: Any, *, use_cache: bool = True) -> str:
    """Source of a model's batched silent-motion kernel (numba).

    The model's generated ``residuals``, ``jacobians`` and ``contact``
    (:attr:`CompiledModel.source <brakesqueal.codegen.compiled.CompiledModel.source>`),
    decorated for numba, plus wrappers at zero rates (``x = (Q, 0, 0, L, 0)``)
    and the static Newton template.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    use_cache : bool, optional
        Use the on-disk cache for the compiled model.

    Returns
    -------
    str
        Python source.
    """
    from ..codegen import compile_model
    from ..codegen.compiled import CONTACT_FIELDS

    cm = compile_model(spec, use_cache=use_cache)
    n, m, nx, npad = cm.n, cm.m, cm.nx, len(cm.spec.pads)
    fns = _functions(cm.source, ("residuals", "jacobians", "contact"))
    K = n + m
    zs = [f"z[{k}]" for k in range(n)] + ["0.0"] * (2 * n) + [f"z[{n + k}]" for k in range(m)] + ["0.0"] * m
    ps = ", ".join(f"p[{k}]" for k in range(len(cm.param_names)))
    x = "(" + ", ".join(zs) + ",)"
    pt = f"({ps},)" if cm.param_names else "()"
    cols = list(range(n)) + list(range(3 * n, 3 * n + m))
    lines = [_PREAMBLE.format(n=n, m=m, npad=npad, nf=len(CONTACT_FIELDS), tilting=bool(cm.spec.disk.tilting))]
    for name in ("residuals", "jacobians", "contact"):
        lines += [_DECORATOR, fns[name]]
    lines += [_DECORATOR, "def static_residuals(z, p, out):",
              '    """(R, G) at x = (Q, 0, 0, L, 0), z = (Q, L)."""',
              f"    r = residuals({x}, {pt})"]
    lines += [f"    out[{k}] = r[{k}]" for k in range(K)]
    lines += ["    return None", "", _DECORATOR, "def static_jacobian(z, p, out):",
              '    """d(R, G)/d(Q, L) at x = (Q, 0, 0, L, 0)."""',
              f"    J = jacobians({x}, {pt})"]
    lines += [f"    out[{a}, {b}] = J[{a * nx + c}]" for a in range(K) for b, c in enumerate(cols)]
    lines += ["    return None", "", _DECORATOR, "def full_jacobian(z, p, out):",
              '    """d(R, G)/dx at x = (Q, 0, 0, L, 0), row-major (n + m) x (3n + 2m)."""',
              f"    J = jacobians({x}, {pt})"]
    lines += [f"    out[{k}] = J[{k}]" for k in range(K * nx)]
    lines += ["    return None", "", _DECORATOR, "def contact_table(z, p, out):",
              '    """Per pad the contact fields at x = (Q, 0, 0, L, 0)."""',
              f"    c = contact({x}, {pt})"]
    nf = len(CONTACT_FIELDS)
    lines += [f"    out[{j}, {f}] = c[{j * nf + f}]" for j in range(npad) for f in range(nf)]
    lines += ["    return None", ""]
    header = (f'"""Generated by brakesqueal.analysis.silent_batch for model {spec.name!r}. Do not edit.\n\n'
              f"z = ({', '.join([*cm.coords, *cm.algebraic])})\np = ({', '.join(cm.param_names)})\n" + '"""\n')
    return header + "\n".join(lines) + _TEMPLATE


def load_kernel(spec: Any, use_cache: bool = True) -> types.ModuleType:
    """Import a model's batched silent-motion kernel, generating and caching it on first use.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    use_cache : bool, optional
        Keep the source (and numba's machine code) in the package cache,
        entry ``model-<hash>``, file :data:`KERNEL_NAME` (default ``True``).

    Returns
    -------
    module
        With ``newton_batch``, ``jacobian_batch``, ``static_residuals``, ``static_jacobian``,
        ``full_jacobian``, ``contact_table``.
    """
    from ..codegen.compiled import model_key

    return cache.load_module(model_key(spec), KERNEL_NAME, lambda: kernel_source(spec, use_cache=use_cache),
                             use_cache=use_cache)


def kernel_ready(spec: Any, *, use_cache: bool = True) -> bool:
    """Whether a model's kernel runs without compiling: already run in this process, or in numba's disk cache.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    use_cache : bool, optional
        Whether the on-disk cache may be used.

    Returns
    -------
    bool
    """
    from ..codegen.compiled import model_key

    key = model_key(spec)
    if (key, use_cache) in _READY:
        return True
    if not use_cache:
        return False
    try:
        d = cache.entry_dir(key) / "__pycache__"
        return any(d.glob("silent.newton_batch-*.nbi")) and any(d.glob("silent.jacobian_batch-*.nbi"))
    except OSError:
        return False


def mark_ready(spec: Any, use_cache: bool = True) -> None:
    """Record that the model's kernel has run in this process (its machine code is loaded)."""
    from ..codegen.compiled import model_key

    _READY.add((model_key(spec), use_cache))
