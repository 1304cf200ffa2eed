"""Side by side with AUTO-07p: any model as AUTO's C user functions, and a Hopf curve computed by AUTO.

:func:`auto_source` writes the model's right-hand side (the C export of
:func:`brakesqueal.export_code`, the simulation's equations: massless pads
with a finite ``k_ip`` quasi-static, which leaves the linearization and so the
Hopf curves exact) with AUTO's ``func``/``stpnt`` (and empty ``bcnd``,
``icnd``, ``fopt``, ``pvls``): ``PAR(1)`` and ``PAR(2)`` are the ``x`` and
``y`` parameters scaled to the unit box of their axes (``log10`` for a log
axis: ``x = start + PAR(1) (stop - start)``, or ``x = 10^(log10 start +
PAR(1) log10(stop/start))``), so that AUTO's arclength treats both alike;
every model parameter is a C expression of them (the preset's ties, SymPy's C
printer; compliances ``1/k_ip``).  Time is scaled by ``W`` (``time_scale``)
so that AUTO sees eigenvalues of order one.

:func:`auto_hopf_curve` compiles it against AUTO-07p's library
(``/usr/lib/auto-07p``, or ``$AUTO_DIR``), continues the equilibrium in ``y``
from ``(x0, y_start)`` to the first Hopf bifurcation (``HB``, ``ISW=1``), then
the Hopf point in ``(y, x)`` both ways (``ISW=2``) until it leaves the box
(``UZSTOP``), and returns AUTO's curve points read from its ``fort.7``.

:func:`auto_cycle_branch` continues the periodic orbits from that Hopf point (``IPS=2``) to their first fold
(``LP``); :func:`auto_fold_curve` continues that fold in two parameters (``ISW=2``: AUTO's start run, then both
ways from it, as AUTO's demo ``plp``), with user points (``UZR``) at given values of the second parameter.  Both
see the smooth bilateral equations: compare with :func:`~.folds.fold_curves` ``contact="bilateral"``.  With
``jac=1`` the user functions supply the Jacobian (``JAC=1``) by central differences with the step
``eps^(1/3) (1 + |u_j|)`` instead of AUTO's ``1e-7 (1 + max |u|)``.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Sequence
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..validation import Range, validated

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["AutoCurve", "AutoCycles", "auto_dir", "auto_available", "auto_source", "auto_hopf_curve",
           "auto_cycle_branch", "auto_fold_curve", "to_unit", "from_unit"]


def auto_dir() -> Path:
    """AUTO-07p's directory (``$AUTO_DIR``, else the Debian package's ``/usr/lib/auto-07p``)."""
    return Path(os.environ.get("AUTO_DIR") or "/usr/lib/auto-07p")


def _include_dir() -> Path | None:
    for d in (auto_dir() / "include", Path("/usr/include")):
        if (d / "auto_f2c.h").is_file():
            return d
    return None


def _libgfortran() -> str | None:
    for d in ("/lib/x86_64-linux-gnu", "/usr/lib/x86_64-linux-gnu", "/usr/lib64", "/usr/lib"):
        for name in ("libgfortran.so", "libgfortran.so.5"):
            if os.path.exists(os.path.join(d, name)):
                return os.path.join(d, name)
    return None


def auto_available() -> str | None:
    """Why AUTO-07p cannot be run here, or ``None`` when it can (library, header, C compiler, libgfortran)."""
    if not (auto_dir() / "lib" / "libauto_c.a").is_file():
        return (f"AUTO-07p is not installed (no {auto_dir() / 'lib' / 'libauto_c.a'}; Debian: apt-get install "
                "auto-07p, or set AUTO_DIR)")
    if _include_dir() is None:
        return "AUTO-07p's header auto_f2c.h is not found (Debian package auto-07p)"
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        return "no C compiler (gcc) to build AUTO-07p's user functions"
    if _libgfortran() is None:
        return "libgfortran is not installed (AUTO-07p's library is Fortran)"
    return None


def _unit_c(ax: Axis, par: str) -> str:
    if ax.log:
        a, b = math.log10(ax.start), math.log10(ax.stop)
        return f"pow(10.0, {a!r} + {par} * {b - a!r})"
    return f"({float(ax.start)!r} + {par} * {float(ax.stop - ax.start)!r})"


@validated
def to_unit(ax: Axis, v: float) -> float:
    """A value of an axis in AUTO's parameter (the unit box: 0 at ``start``, 1 at ``stop``; ``log10`` on a log axis).

    Parameters
    ----------
    ax : Axis
        The axis.
    v : float
        A value (positive on a log axis).

    Returns
    -------
    float
    """
    if ax.log:
        return (math.log10(v) - math.log10(ax.start)) / (math.log10(ax.stop) - math.log10(ax.start))
    return (v - ax.start) / (ax.stop - ax.start)


@validated
def from_unit(ax: Axis, u: float) -> float:
    """AUTO's parameter as the value of the axis (inverse of :func:`to_unit`).

    Parameters
    ----------
    ax : Axis
        The axis.
    u : float
        AUTO's ``PAR``.

    Returns
    -------
    float
    """
    if ax.log:
        a, b = math.log10(ax.start), math.log10(ax.stop)
        return float(10.0 ** (a + u * (b - a)))
    return float(ax.start + u * (ax.stop - ax.start))


@validated
def auto_source(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x0: float, y0: float, *,
                time_scale: float | None = None, state_scale: Sequence[float] | np.ndarray | None = None,
                scale: float = 1.0, precision: str = "double") -> str:
    """The model as AUTO-07p C user functions with ``PAR(1)``, ``PAR(2)`` the axes ``x``, ``y`` in the unit box.

    AUTO's state is ``u = y / s`` and its time ``tau = W t`` (``y`` the simulation's state ``(Q, Qdot, L)`` in
    SI units), so its vector field is ``f(s u) / (W s)``: with the default ``s = (1, W, 1)`` (rates in units of
    ``W``) and ``W = |lambda|`` of the eigenvalue pair nearest the imaginary axis at ``(x0, y0)``, a squeal
    frequency of kilohertz is of order one for AUTO, whose finite differences (its Jacobian, and the third
    derivatives of its l1) assume that.  (Scaling every state by the critical eigenvector instead makes AUTO's
    Hopf continuation fail on the built models.)

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller: :func:`brakesqueal.engine`).
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        Two settable parameters and their ranges (:func:`to_unit`).
    x0, y0 : float
        Their values at the start (``stpnt``: the silent motion there).
    time_scale : float, optional
        ``W`` [rad/s] (positive).
    state_scale : sequence of float, optional
        ``s`` (positive, one per state).
    scale : float
        A factor on the default ``s`` (positive; ignored with ``state_scale``).  AUTO's finite differences of the
        nonlinear terms (the third derivatives of its ``l1``) step ``1.2e-4`` along the unit eigenvector in its
        units: a smaller ``scale`` makes that step smaller against the model's nonlinearity (the error falls as
        ``scale^2``) until the rounding of the forces takes over; see ``precision``.
    precision : {"double", "long double"}
        The arithmetic of the exported model's right-hand side: ``"long double"`` (x87 extended, the C export
        compiled with ``<tgmath.h>``) cuts the rounding of the large, cancelling forces by ~2000, so that a smaller
        ``scale`` pays (the six-dof model: AUTO's GH point within 1e-6 of the box at ``scale = 0.03``, 2e-4 with
        the defaults).  The best ``scale`` depends on the model (about ``min(1, 10 Omega / W)``, ``Omega`` the
        disk's speed: six-dof, Omega ~ 37 rad/s, W ~ 1e4 rad/s; Fig. 3's set, Omega ~ 3000 rad/s, is best at 1, its
        GH point within 4e-8 of ours, and 1e-5 off at 0.1).

    Returns
    -------
    str
        A C file for AUTO's ``libauto_c``.
    """
    import sympy as sp

    from ..export import export_code
    from ..simulation import simulation_model

    if x.name == y.name:
        raise ParameterError(f"The parameters x and y must differ; got {x.name!r} for both", parameter="y")
    params = space.resolve({x.name: x0, y.name: y0})
    eng = engine.require_nonlinear("the AUTO-07p export")
    sim = simulation_model(eng)
    ystate = np.asarray(sim.silent(params).y, dtype=float)
    n = ystate.size
    if time_scale is None:
        from ..nonlinear.models import model_system

        J = model_system(eng, space.with_values({x.name: x0}), y.name).jacobian(ystate, y0)
        lams = np.linalg.eigvals(J)
        cand = lams[lams.imag > 0] if np.any(lams.imag > 0) else lams
        time_scale = float(abs(cand[np.argmin(np.abs(cand.real) / np.maximum(np.abs(cand), 1e-300))])) or 1.0
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise ParameterError(f"The option 'scale' must be positive and finite; got {scale!r}", parameter="scale")
    if state_scale is None:  # rates in units of W: (Q, Qdot / W, the pads' states), times `scale`
        nq = len(sim.coords)
        state_scale = [float(scale)] * nq + [float(scale * time_scale)] * nq + [float(scale)] * (n - 2 * nq)
    sc = np.asarray(state_scale, dtype=float).ravel()
    if not (math.isfinite(time_scale) and time_scale > 0):
        raise ParameterError(f"The option 'time_scale' must be positive and finite; got {time_scale!r}",
                             parameter="time_scale")
    if sc.size != n or not np.all(np.isfinite(sc) & (sc > 0)):
        raise ParameterError(f"The option 'state_scale' must hold {n} positive finite numbers; got {sc.size}",
                             parameter="state_scale")
    sx, sy = sp.Symbol("bsq_x"), sp.Symbol("bsq_y")
    exprs = space.symbolic({x.name: sx, y.name: sy})
    kip = set(space.model.stiffness_names())
    lines = []
    for i, name in enumerate(space.model.parameters):
        e = exprs[name]
        if name in kip:
            e = sp.Integer(0) if e == sp.oo else 1 / e
        if e.has(sp.oo, sp.zoo, sp.nan):
            raise ParameterError(f"the model parameter {name} is not finite as a function of {x.name}, {y.name}: "
                                 f"{e}", parameter=name)
        lines.append(f"    p[{i}] = {sp.ccode(e)};  /* {name} */")
    body = export_code("c", "nonlinear", params, name="brakesqueal_auto")
    w = float(time_scale)
    uscale = [float(v) for v in sc]  # physical state = u * these
    fscale = [w * v for v in uscale]  # AUTO's field = f / these
    u0 = "\n".join(f"    u[{i}] = {float(v) / uscale[i]!r};" for i, v in enumerate(ystate))
    if precision not in ("double", "long double"):
        raise ParameterError(f"The option 'precision' must be double or long double; got {precision!r}",
                             parameter="precision")
    if precision == "long double":  # the exported model in extended precision (type-generic math)
        body = ("#include <math.h>\n#include <tgmath.h>\n#define double long double\n" + body
                + "\n#undef double\n#undef complex  /* tgmath.h's, a type name of auto_f2c.h */\n")
    return f"""{body}
typedef {precision} bsq_real;  /* the model's arithmetic */
/* ---- AUTO-07p user functions (brakesqueal.region.auto) ----
 * {x.name} = {_unit_c(x, "PAR(1)")}
 * {y.name} = {_unit_c(y, "PAR(2)")}
 * time scaled by W = {w!r} rad/s, state by s (below): AUTO's u = y / s, du/dtau = f(s u) / (W s)
 */
#include "auto_f2c.h"

#define BSQ_NP {len(space.model.parameters)}
#define BSQ_STEP 6.0e-6

static void bsq_parameters(const doublereal *par, bsq_real *p)
{{
    const double bsq_x = {_unit_c(x, "par[0]")};
    const double bsq_y = {_unit_c(y, "par[1]")};
    (void)bsq_x;
    (void)bsq_y;
{chr(10).join(lines)}
}}

static void bsq_field(const doublereal *u, const doublereal *par, doublereal *f)
{{
    static const double uscale[{n}] = {{{", ".join(repr(v) for v in uscale)}}};
    static const double fscale[{n}] = {{{", ".join(repr(v) for v in fscale)}}};
    bsq_real p[BSQ_NP], y[{n}], dy[{n}];
    bsq_parameters(par, p);
    for (int i = 0; i < {n}; ++i) y[i] = (bsq_real)u[i] * uscale[i];
    if (brakesqueal_rhs(0.0, y, p, dy) != 0) {{
        for (int i = 0; i < {n}; ++i) f[i] = NAN;
        return;
    }}
    for (int i = 0; i < {n}; ++i) f[i] = (doublereal)(dy[i] / fscale[i]);
}}

/* JAC = 1: the derivatives by central differences with the step (cube root of the rounding unit) x (1 + |v|)
 * (AUTO's own use 1e-7 (1 + max |u|), whose rounding error grows with the cancellation in the forces) */
int func(integer ndim, const doublereal *u, const integer *icp, const doublereal *par, integer ijac,
         doublereal *f, doublereal *dfdu, doublereal *dfdp)
{{
    bsq_field(u, par, f);
    if (ijac >= 1) {{
        double v[{n}], fp[{n}], fm[{n}];
        for (int j = 0; j < {n}; ++j) v[j] = u[j];
        for (int j = 0; j < {n}; ++j) {{
            const double h = BSQ_STEP * (1.0 + fabs(u[j]));
            v[j] = u[j] + h;
            bsq_field(v, par, fp);
            v[j] = u[j] - h;
            bsq_field(v, par, fm);
            v[j] = u[j];
            for (int i = 0; i < {n}; ++i) dfdu[i + j * {n}] = (fp[i] - fm[i]) / (2.0 * h);
        }}
        if (ijac >= 2) {{
            for (int k = 0; k < 2; ++k) {{
                const double h = BSQ_STEP * (1.0 + fabs(par[k]));
                double pp[2] = {{par[0], par[1]}};  /* the field reads PAR(1), PAR(2) only */
                pp[k] = par[k] + h;
                bsq_field(u, pp, fp);
                pp[k] = par[k] - h;
                bsq_field(u, pp, fm);
                for (int i = 0; i < {n}; ++i) dfdp[i + k * {n}] = (fp[i] - fm[i]) / (2.0 * h);
            }}
        }}
    }}
    return 0;
}}

int stpnt(integer ndim, doublereal t, doublereal *u, doublereal *par)
{{
    par[0] = {to_unit(x, x0)!r};
    par[1] = {to_unit(y, y0)!r};
{u0}
    return 0;
}}

int bcnd(integer ndim, const doublereal *par, const integer *icp, integer nbc, const doublereal *u0,
         const doublereal *u1, integer ijac, doublereal *fb, doublereal *dbc) {{ return 0; }}
int icnd(integer ndim, const doublereal *par, const integer *icp, integer nint, const doublereal *u,
         const doublereal *uold, const doublereal *udot, const doublereal *upold, integer ijac,
         doublereal *fi, doublereal *dint) {{ return 0; }}
int fopt(integer ndim, const doublereal *u, const integer *icp, const doublereal *par, integer ijac,
         doublereal *fs, doublereal *dfdu, doublereal *dfdp) {{ return 0; }}
int pvls(integer ndim, const doublereal *u, doublereal *par) {{ return 0; }}
/* state dimension {n} */
"""


@dataclass(frozen=True)
class AutoCurve:
    """A Hopf curve computed by AUTO-07p.

    Attributes
    ----------
    x_name, y_name : str
        The parameters (``PAR(1)``, ``PAR(2)``).
    x, y : ndarray
        AUTO's curve points (both directions, in AUTO's order).
    hopf_start : tuple of float
        The Hopf point AUTO found on the equilibrium branch (``x0``, ``y``).
    special : tuple of (str, float, float)
        AUTO's special points on the curve: type (``GH``, ``BT``, ``ZH``, ``HH``; ``UZ`` at the box; ``MX``
        where it failed) and ``(x, y)``.
    """

    x_name: str
    y_name: str
    x: np.ndarray
    y: np.ndarray
    hopf_start: tuple[float, float]
    special: tuple[tuple[str, float, float], ...] = ()


@dataclass(frozen=True)
class AutoCycles:
    """A branch of periodic orbits from a Hopf point computed by AUTO-07p (the bilateral equations: AUTO knows
    nothing of contact loss).

    Attributes
    ----------
    name : str
        The continuation parameter (``PAR(2)``).
    hopf : float
        The Hopf point AUTO found on the equilibrium branch.
    p : ndarray
        The parameter along the branch (AUTO's order, from the Hopf point).
    max_state : ndarray
        ``(point, state)``: AUTO's ``MAX U(i)`` (the largest value of each state over the orbit, AUTO's scaled
        state: displacements in SI units, rates divided by the time scale).
    period : ndarray
        The period [s].
    fold : float or None
        AUTO's first fold of cycles (``LP``) on the branch, or ``None``.
    """

    name: str
    hopf: float
    p: np.ndarray
    max_state: np.ndarray
    period: np.ndarray
    fold: float | None


_TY = {0: "", 1: "BP", -2: "CP", 2: "LP", 3: "HB", -3: "ZH", -1: "BT", -32: "GH", 4: "RG", -4: "UZ", 9: "EP",
       -9: "MX"}


def _ty(code: int, hopf_branch: bool = False) -> str:
    """AUTO's type number as its short name (as AUTO's own parseB: the last digit, GH = -32); on a Hopf curve a
    Hopf point is a double Hopf (HH)."""
    if code != -32:
        code = code % 10 if code >= 0 else -((-code) % 10)
    name = _TY.get(code, str(code))
    return "HH" if hopf_branch and name == "HB" else name


def _constants(**kw: object) -> str:
    out = []
    for k, v in kw.items():
        out.append(f"{k} = {v}")
    return "\n".join(out) + "\n"


def _run(workdir: Path, exe: Path, constants: str, restart: Path | None, timeout: float,
         exit_crash_ok: bool = False) -> tuple[str, str]:
    (workdir / "fort.2").write_text(constants)
    if restart is not None:
        shutil.copy(restart, workdir / "fort.3")
    elif (workdir / "fort.3").exists():
        (workdir / "fort.3").unlink()
    for f in ("fort.7", "fort.8", "fort.9"):
        if (workdir / f).exists():
            (workdir / f).unlink()
    try:
        p = subprocess.run([str(exe)], cwd=workdir, capture_output=True, text=True, timeout=timeout,
                           env={**os.environ, "OMP_NUM_THREADS": "1"})
    except subprocess.TimeoutExpired:
        raise BrakesquealError(f"AUTO-07p did not finish within {timeout:g} s") from None
    b7 = (workdir / "fort.7").read_text() if (workdir / "fort.7").exists() else ""
    # AUTO-07p (Debian's 0.9.x) aborts in its own clean-up (free() in cnrlbv) after a fold continuation of
    # periodic orbits has written its output: accepted there when the branch's last row is a labelled end point
    ended = exit_crash_ok and p.returncode < 0 and "cnrlbv" in p.stderr and _labelled_end(b7)
    if (p.returncode != 0 and not ended) or not b7:
        tail = (p.stderr or p.stdout).strip().splitlines()[-1:] or ["no output"]
        raise BrakesquealError(f"AUTO-07p failed (exit {p.returncode}): {tail[0]}")
    return b7, p.stdout


def _labelled_end(b7: str) -> bool:
    """The last row of ``fort.7`` is a labelled point (AUTO wrote the branch's end before it stopped)."""
    rows = _parse_fort7(b7)
    return bool(rows) and int(rows[-1].get("LAB", 0)) > 0 and int(rows[-1].get("TY", 0)) != 0


def _prepare(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x0: float, y_start: float, keep: str | None,
             **source: Any) -> tuple[str, Path]:
    """The checks every AUTO run makes first (AUTO installed), the exported user functions
    (:func:`auto_source` with ``source``'s options) and the run's directory (``keep``, else a new temporary one)."""
    why = auto_available()
    if why:
        raise BrakesquealError(why)
    src = auto_source(engine, space, x, y, x0, y_start, **source)
    tmp = Path(keep) if keep else Path(tempfile.mkdtemp(prefix="brakesqueal-auto-"))
    tmp.mkdir(parents=True, exist_ok=True)
    return src, tmp


def _join(xs: list[float], ys: list[float], pts: list[tuple[float, float]], sign: int) -> None:
    """Add one direction's points of a curve continued both ways from its start: ``sign > 0`` after the points
    so far, ``sign < 0`` reversed before them (so the curve runs in one direction)."""
    if sign < 0:
        xs[:0] = [p[0] for p in pts[::-1]]
        ys[:0] = [p[1] for p in pts[::-1]]
    else:
        xs += [p[0] for p in pts]
        ys += [p[1] for p in pts]


def _parse_fort7(text: str) -> list[dict[str, float]]:
    """Rows of AUTO's ``fort.7`` (header ``PT TY LAB PAR(1) ...``): each row a dict by column name."""
    rows: list[dict[str, float]] = []
    cols: list[str] = []
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "0":
            if len(parts) > 1 and parts[1] == "PT":
                # the column names may hold spaces ("L2-NORM", "PAR(1)"): split at two or more blanks
                import re

                cols = [c for c in re.split(r"\s{2,}", line.strip())][1:]
            continue
        if not cols:
            continue
        try:
            vals = [float(v.replace("D", "E")) for v in parts[1:]]
        except ValueError:
            continue
        row = dict(zip(cols, vals))
        rows.append(row)
    return rows


def _to_first_hopf(src: str, tmp: Path, x: Axis, y: Axis, x0: float, y_start: float, points: int,
                   timeout: float) -> tuple[Path, dict[str, object], int, float]:
    """Build the user functions in ``tmp`` and continue the equilibrium in ``y`` from ``y_start`` to the first
    Hopf point (run 1, its ``fort.8`` kept as ``s.eq``): the executable, the common constants, the HB label and
    ``y`` there."""
    (tmp / "bsq.c").write_text(src)
    cc = shutil.which("gcc") or shutil.which("cc") or "gcc"
    inc = _include_dir()
    cmd = [cc, "-O2", "-fPIC", f"-I{inc}", "-o", str(tmp / "bsq.exe"), str(tmp / "bsq.c"),
           *sorted(str(p) for p in (auto_dir() / "lib").glob("*.o")), str(auto_dir() / "lib" / "libauto_c.a"),
           str(_libgfortran()), "-fopenmp", "-lm"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if p.returncode != 0:
        first = next((ln for ln in p.stderr.splitlines() if "error" in ln), p.stderr.strip()[:200])
        raise BrakesquealError(f"building the AUTO-07p user functions failed: {first}")
    exe = tmp / "bsq.exe"
    ndim = int(src.rsplit("state dimension ", 1)[1].split()[0])
    common: dict[str, object] = dict(NDIM=ndim, IPS=1, ILP=0, NTST=20, NCOL=4, IAD=3, ISP=1, IPLT=0, NBC=0, NINT=0,
                                     NPR=100000, MXBF=0, IID=0, ITMX=8, ITNW=12, NWTN=3, JAC=0, EPSL="1e-10",
                                     EPSU="1e-10", EPSS="1e-8", DSMIN="1e-10", IADS=1, NPAR=2, NMX=points)
    # run 1: the equilibrium in y from y_start, stop at the first Hopf point
    c1 = _constants(**common, IRS=0, ICP="[2]", ISW=1, DS="0.001", DSMAX="0.01", STOP="['HB1']",
                    UZSTOP="{2: [0.0, 1.0]}")
    b7, _ = _run(tmp, exe, c1, None, timeout)
    rows = _parse_fort7(b7)
    hb = [r for r in rows if _ty(int(r.get("TY", 0))) == "HB"]
    if not hb:
        raise BrakesquealError(f"AUTO-07p found no Hopf point on the equilibrium branch at {x.name} = {x0:.10g} "
                               f"from {y.name} = {y_start:.10g}")
    shutil.copy(tmp / "fort.8", tmp / "s.eq")
    return exe, common, int(hb[0]["LAB"]), from_unit(y, hb[0].get("PAR(2)", math.nan))


def _cycles_to_fold(tmp: Path, exe: Path, common: dict[str, object], lab: int, ntst: int, direction: int,
                    timeout: float) -> list[dict[str, float]]:
    """Run 2: the cycles from the Hopf point ``lab`` (branch switching, ``IPS=2``), folds detected, stopping at
    the first (its ``fort.8`` kept as ``s.cyc``): the rows of ``fort.7``."""
    c2 = _constants(**{**common, "IPS": 2, "ILP": 1, "ISP": 2, "NTST": ntst, "NPAR": 11, "EPSS": "1e-6",
                       "DSMIN": "1e-12"}, IRS=lab, ICP="[2, 11]", ISW=1, DS=repr(direction * 1e-4),
                    DSMAX="0.01", STOP="['LP1']", UZSTOP="{2: [0.0, 1.0]}")
    b7, _ = _run(tmp, exe, c2, tmp / "s.eq", timeout)
    shutil.copy(tmp / "fort.8", tmp / "s.cyc")
    return [r for r in _parse_fort7(b7) if "PAR(2)" in r]


@validated
def auto_cycle_branch(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x0: float, y_start: float, *,
                      direction: Annotated[int, Range(-1, 1)] = 1, ntst: Annotated[int, Range(5, 500)] = 40,
                      points: Annotated[int, Range(10, 100000)] = 400,
                      timeout: Annotated[float, Range(1, 3600, open_low=False)] = 300.0,
                      time_scale: Annotated[float, Range(0, open_low=True)] | None = None,
                      state_scale: Sequence[float] | np.ndarray | None = None, scale: float = 1.0,
                      precision: str = "double", keep: str | None = None) -> AutoCycles:
    """The periodic orbits born at the first Hopf point above ``y_start`` at ``x = x0``, continued in ``y`` by
    AUTO-07p to its first fold of cycles (``LP``) or the box's edge (the check of :func:`~.folds.fold_curves`).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model (with nonlinear equations), preset and overrides.
    x, y : Axis
        The fixed parameter and the continuation parameter, with their boxes.
    x0 : float
        The fixed ``x``.
    y_start : float
        Where the equilibrium branch starts (below the Hopf point, inside ``y``).
    direction : {1, -1}
        Sign of AUTO's first step on the cycle branch (``DS``).
    ntst : int
        Mesh intervals of AUTO's collocation (``NTST``).
    points : int
        Largest number of steps of each run (``NMX``).
    timeout : float
        Seconds each AUTO run may take.
    time_scale, state_scale, scale, precision : optional
        As in :func:`auto_source` (defaults there).
    keep : str, optional
        A directory to keep AUTO's files in.

    Returns
    -------
    AutoCycles

    Raises
    ------
    BrakesquealError
        AUTO-07p is not installed, the build or a run fails, or no Hopf point.
    """
    if direction == 0:
        raise ParameterError("The option 'direction' must be 1 or -1; got 0", parameter="direction")
    src, tmp = _prepare(engine, space, x, y, x0, y_start, keep, time_scale=time_scale, state_scale=state_scale,
                        scale=scale, precision=precision)
    try:
        exe, common, lab, y_h = _to_first_hopf(src, tmp, x, y, x0, y_start, points, timeout)
        rows = _cycles_to_fold(tmp, exe, common, lab, ntst, direction, timeout)
        n = int(common["NDIM"])  # type: ignore[call-overload]
        p = np.array([from_unit(y, r["PAR(2)"]) for r in rows])
        mx = np.array([[r.get(f"MAX U({i + 1})", math.nan) for i in range(n)] for r in rows])
        per = np.array([r.get("PERIOD", math.nan) for r in rows])
        # on a branch of periodic orbits AUTO's type 5 is a fold (LP; 2 on equilibria)
        lps = [from_unit(y, r["PAR(2)"]) for r in rows if abs(int(r.get("TY", 0))) % 10 in (2, 5)]
        # AUTO's period is in its time tau = W t
        w = float(src.rsplit("time scaled by W = ", 1)[1].split()[0]) if "time scaled by W = " in src else 1.0
        return AutoCycles(y.name, y_h, p, mx, per / w, lps[0] if lps else None)
    finally:
        if not keep:
            shutil.rmtree(tmp, ignore_errors=True)


@validated
def auto_hopf_curve(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x0: float, y_start: float, *,
                    time_scale: Annotated[float, Range(0, open_low=True)] | None = None,
                    state_scale: Sequence[float] | np.ndarray | None = None,
                    points: Annotated[int, Range(10, 100000)] = 400,
                    timeout: Annotated[float, Range(1, 3600, open_low=False)] = 120.0,
                    jac: Annotated[int, Range(0, 1)] = 0, scale: float = 1.0, precision: str = "double",
                    keep: str | None = None) -> AutoCurve:
    """The Hopf curve through the first Hopf point above ``y_start`` at ``x = x0``, by AUTO-07p.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller: :func:`brakesqueal.engine`).
    space : ParameterSpace
        The model (with nonlinear equations), preset and overrides.
    x, y : Axis
        The parameters and the box (AUTO stops at its edges, ``UZSTOP``).
    x0 : float
        The fixed ``x`` of the equilibrium branch.
    y_start : float
        Where the equilibrium branch starts (below the Hopf point, inside ``y``).
    points : int
        Largest number of continuation steps of each run (``NMX``).
    timeout : float
        Seconds each AUTO run may take.
    time_scale, state_scale, scale, precision : optional
        As in :func:`auto_source` (defaults there).
    jac : {0, 1}
        AUTO's ``JAC``: 1, the Jacobian from the user functions (central differences, see the module).
    keep : str, optional
        A directory to keep the C file and AUTO's output files in.

    Returns
    -------
    AutoCurve

    Raises
    ------
    BrakesquealError
        AUTO-07p is not installed (one line saying what is missing), the build or a run fails, or no Hopf point.
    """
    src, tmp = _prepare(engine, space, x, y, x0, y_start, keep, time_scale=time_scale, state_scale=state_scale,
                        scale=scale, precision=precision)
    try:
        exe, common, lab, y_h = _to_first_hopf(src, tmp, x, y, x0, y_start, points, timeout)
        common = {**common, "JAC": jac}
        xs: list[float] = []
        ys: list[float] = []
        labels: list[tuple[str, float, float]] = []
        for sign in (1, -1):
            # EPSS 1e-6: AUTO's l1 (finite-difference third derivatives) is noisy at ~1e-8 of its scale, so its
            # location of a generalised Hopf point does not converge to a tighter step
            c2 = _constants(**{**common, "EPSS": "1e-6", "ITMX": 20}, IRS=lab, ICP="[2, 1]", ISW=2,
                            DS=repr(sign * 1e-3), DSMAX="0.02",
                            UZSTOP="{1: [0.0, 1.0], 2: [0.0, 1.0]}")
            b7, _ = _run(tmp, exe, c2, tmp / "s.eq", timeout)
            shutil.copy(tmp / "fort.7", tmp / f"b.hopf{'+' if sign > 0 else '-'}")
            rows = [r for r in _parse_fort7(b7) if "PAR(1)" in r and "PAR(2)" in r]
            labels += [(t, from_unit(x, r["PAR(1)"]), from_unit(y, r["PAR(2)"]))
                       for t, r in ((_ty(int(r.get("TY", 0)), True), r) for r in rows) if t not in ("", "RG", "EP")]
            _join(xs, ys, [(from_unit(x, r["PAR(1)"]), from_unit(y, r["PAR(2)"])) for r in rows], sign)
        return AutoCurve(x.name, y.name, np.array(xs), np.array(ys), (float(x0), float(y_h)), tuple(labels))
    finally:
        if not keep:
            shutil.rmtree(tmp, ignore_errors=True)


@validated
def auto_fold_curve(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, x0: float, y_start: float, *,
                    at: Sequence[float] = (), direction: Annotated[int, Range(-1, 1)] = 1,
                    ntst: Annotated[int, Range(5, 500)] = 40, points: Annotated[int, Range(10, 100000)] = 400,
                    timeout: Annotated[float, Range(1, 3600, open_low=False)] = 300.0,
                    time_scale: Annotated[float, Range(0, open_low=True)] | None = None,
                    state_scale: Sequence[float] | np.ndarray | None = None, scale: float = 1.0,
                    precision: str = "double", jac: Annotated[int, Range(0, 1)] = 0,
                    keep: str | None = None) -> AutoCurve:
    """The curve of folds of cycles (``LPC``) through the first fold of the cycle branch of
    :func:`auto_cycle_branch`, continued by AUTO-07p in ``(y, x)`` both ways (``ISW=2``, ``IPS=2``) to the box's
    edges: the bilateral equations (AUTO knows nothing of contact loss).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model (with nonlinear equations), preset and overrides.
    x, y : Axis
        The second parameter of the fold curve (fixed at ``x0`` on the cycle branch) and the cycle branch's
        parameter, with their boxes (AUTO stops at their edges).
    x0, y_start : float
        As in :func:`auto_cycle_branch`.
    at : sequence of float
        Values of ``x`` where AUTO locates the curve's points exactly (user points ``UZR``; ``special`` holds
        them as ``("UZ", x, y)``).
    direction, ntst, points, timeout, time_scale, state_scale, scale, precision, keep :
        As in :func:`auto_cycle_branch`.
    jac : {0, 1}
        As in :func:`auto_hopf_curve`.

    Returns
    -------
    AutoCurve
        ``hopf_start`` is ``(x0, y)`` of the fold on the cycle branch.

    Raises
    ------
    BrakesquealError
        AUTO-07p is not installed, the build or a run fails, no Hopf point, or no fold on the cycle branch.
    """
    if direction == 0:
        raise ParameterError("The option 'direction' must be 1 or -1; got 0", parameter="direction")
    src, tmp = _prepare(engine, space, x, y, x0, y_start, keep, time_scale=time_scale, state_scale=state_scale,
                        scale=scale, precision=precision)
    try:
        exe, common, lab, _y_h = _to_first_hopf(src, tmp, x, y, x0, y_start, points, timeout)
        common = {**common, "JAC": jac}
        rows = _cycles_to_fold(tmp, exe, common, lab, ntst, direction, timeout)
        lps = [r for r in rows if abs(int(r.get("TY", 0))) % 10 in (2, 5)]
        if not lps:
            raise BrakesquealError(f"AUTO-07p found no fold of cycles on the branch at {x.name} = {x0:.10g}")
        lp_lab, y_lp = int(lps[0]["LAB"]), from_unit(y, lps[0]["PAR(2)"])
        uzr = ", ".join(repr(to_unit(x, float(v))) for v in at)
        xs: list[float] = []
        ys: list[float] = []
        labels: list[tuple[str, float, float]] = []
        lpc: dict[str, object] = dict(**{**common, "IPS": 2, "ILP": 1, "ISP": 2, "NTST": ntst, "NPAR": 11,
                                         "EPSS": "1e-6", "DSMIN": "1e-12", "ITMX": 20}, ICP="[2, 1, 11]", ISW=2,
                                      DSMAX="0.02", UZR=f"{{1: [{uzr}]}}" if uzr else "{}",
                                      UZSTOP="{1: [0.0, 1.0], 2: [0.0, 1.0]}")
        # run 3: AUTO's start of a fold continuation of periodic orbits (the null vector; PAR(1) still fixed),
        # then run 4 from its end, both ways (as AUTO's demo plp)
        b7, _ = _run(tmp, exe, _constants(**lpc, IRS=lp_lab, DS="0.001"), tmp / "s.cyc", timeout, exit_crash_ok=True)
        shutil.copy(tmp / "fort.8", tmp / "s.lpstart")
        start = [int(r["LAB"]) for r in _parse_fort7(b7) if int(r.get("LAB", 0)) > 0]
        if not start:
            raise BrakesquealError("AUTO-07p's start of the fold continuation wrote no solution")
        for sign in (1, -1):
            c4 = _constants(**lpc, IRS=start[-1], DS=repr(sign * 1e-3))
            b7, _ = _run(tmp, exe, c4, tmp / "s.lpstart", timeout, exit_crash_ok=True)
            rows3 = [r for r in _parse_fort7(b7) if "PAR(1)" in r and "PAR(2)" in r]
            # a user point inside the box is type -4 as the box's edge: the box's edges are 0 and 1 exactly
            for r in rows3:
                t = _ty(int(r.get("TY", 0)))
                if t in ("", "RG", "EP"):
                    continue
                if t == "UZ" and min(abs(r["PAR(1)"]), abs(r["PAR(1)"] - 1), abs(r["PAR(2)"]),
                                     abs(r["PAR(2)"] - 1)) < 1e-12:
                    t = "EP"  # the box's edge
                labels.append((t, from_unit(x, r["PAR(1)"]), from_unit(y, r["PAR(2)"])))
            _join(xs, ys, [(from_unit(x, r["PAR(1)"]), from_unit(y, r["PAR(2)"])) for r in rows3], sign)
        return AutoCurve(x.name, y.name, np.array(xs), np.array(ys), (float(x0), float(y_lp)), tuple(labels))
    finally:
        if not keep:
            shutil.rmtree(tmp, ignore_errors=True)
