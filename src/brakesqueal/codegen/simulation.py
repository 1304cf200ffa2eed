r"""A model's simulation kernels and the flow integrator: generated numba source and loaders.

The equations of a model (:func:`~brakesqueal.symbolic.assemble.build_equations`,
``R(Q, Qdot, Qddot, L, Ldot) = 0`` and ``G(Q, Qdot, L, Ldot) = 0``) are turned
once into numba source by the package's one printer
(:func:`brakesqueal.codegen.printer.generate_module`, common subexpressions
eliminated):

* ``pad_balance_e(y, l, dl, p, e, out)`` — per pad unknown ``j``: ``G_j`` and its
  derivative with respect to the pad's unknown (``l_j`` of a quasi-static pad,
  ``ldot_j`` of a dynamic pad), with the pads' engagement ``e`` (1 pressed, 0
  lifted off: the balance without the friction force);
* ``mass_force(y, l, dl, p, out)`` — the mass matrix ``M(Q) = dR/dQddot``
  (``n x n``, row-major) and the forcing ``f = R(Qddot = 0)``, so that
  ``M Qddot + f = 0`` (``R`` is linear in ``Qddot``: checked when generating);
* ``contact(y, l, dl, p, out)`` — per pad the
  :data:`~brakesqueal.codegen.compiled.CONTACT_FIELDS` ``F_n, v_r (3), h, hdot, l``;
* ``energy(y, l, dl, p, out)`` — ``T2, T1, T0, V_support, V_pads``
  (:func:`~brakesqueal.symbolic.assemble.energy_terms`);
* ``release(y, l, dl, p, out)`` — per pad the part of ``f`` due to its contact force;
* ``pad_scale(y, l, dl, p, out)`` — per pad unknown the size of the terms of
  ``G_j`` (its rounding level divided by ``eps``: the Newton tolerance);

with ``y = (Q, Qdot)`` (the first ``2n`` entries of the integrator state), ``l``
and ``dl`` the pad deformations ``L`` and their rates, ``p``
(:meth:`Parameters.vector <brakesqueal.model.parameters.Parameters.vector>`).

**Pad treatment** is the engine's (:attr:`Capabilities.treatment
<brakesqueal.codegen.engine.Capabilities.treatment>`, decided once by
:attr:`Pad.treatment <brakesqueal.model.components.Pad.treatment>`): a
*quasi-static* pad has ``ldot := 0`` substituted in all its expressions and
``l`` solves ``G(Q, Qdot, l, 0) = 0``; a *dynamic* pad's ``l`` is a state and
``ldot`` solves ``G(Q, Qdot, l, ldot) = 0``.  Each pad's ``G_j`` depends on its
own unknown only (checked), so both are scalar Newton iterations per pad.

The static parts are templates (:mod:`.templates`): the pad solve, right-hand
side, events and post-processing (:mod:`.templates.simulation_pads`), the one
DOP853 step (:mod:`.templates.dop853`) and the simulation's driver
(:mod:`.templates.simulation_dop853`).  :func:`variational_source` adds the
exact Jacobians (:mod:`.templates.variational`); :func:`flow_kernel` is the
same DOP853 step driven with variational equations for any system
(:mod:`.templates.flow_dop853`).  Every module is cached
(:func:`brakesqueal.codegen.cache.load_module`) and numba caches its machine
code beside it.
"""

from __future__ import annotations

import types
from typing import TYPE_CHECKING, Any

from . import cache
from .templates import template

if TYPE_CHECKING:
    from .engine import Engine

__all__ = ["KERNEL_NAME", "VARIATIONAL_NAME", "FLOW_KEY", "kernel_source", "variational_source", "load_kernels",
           "flow_source", "flow_kernel"]

#: File name of the kernel module in the model's cache entry.
KERNEL_NAME = "simulate.py"
#: File name of the variational (exact Jacobian) kernel module in the model's cache entry.
VARIATIONAL_NAME = "variational.py"
#: Cache entry of the flow integrator (one per machine: it takes the vector field as first-class functions).
FLOW_KEY = "flow"

_DECORATOR = '@njit(cache=True, error_model="numpy")'

_PREAMBLE = '''import math
from math import sin, cos, tan, sqrt, exp, log, pi

import numpy as np
from numba import njit

_N = {n}  # coordinates Q
_M = {m}  # pad deformations L
_NPAD = {npad}  # pads
_NDYN = {ndyn}  # pad deformations that are states (rate-dependent friction or a tangential damper)
_NY = {ny}  # integrator state (Q, Qdot, L_dynamic)
_NEV = {nev}  # event functions: contact loss and sliding reversal of every pad
_KIND = np.array({kind}, dtype=np.int64)  # per L: 0 quasi-static (unknown l, ldot = 0), 1 dynamic (unknown ldot)
_DYN = np.array({dyn}, dtype=np.int64)  # index into L of the i-th state y[2 N + i]
_PRESSED = np.ones(max(_NPAD, 1), dtype=np.int64)  # engagement of every pad in bilateral contact
'''


def _value(se: Any, eq: Any, v: Any) -> Any:
    """Symbolic value of a component field (parameter name, number; stiffnesses through their compliance)."""
    if v is None:
        return se.Integer(0)
    if isinstance(v, str):
        names = list(eq.spec.parameters)
        sym = eq.params[names.index(v)]
        return 1 / sym if v in eq.spec.stiffness_names() else sym
    return se.Integer(int(v)) if float(v).is_integer() else se.sympify(float(v))


def _check_free(what: str, expr: Any, forbidden: set[Any]) -> None:
    bad = set(expr.free_symbols) & forbidden
    if bad:
        raise ValueError(f"cannot generate simulation kernels: {what} depends on {sorted(map(str, bad))}")


def _expressions(engine: Engine) -> dict[str, Any]:
    """Symbolic outputs of the generated functions (symengine) with the pad treatment of the engine."""
    import symengine as se

    from ..symbolic.assemble import ENERGY_TERMS, build_equations, energy_terms

    spec = engine.spec
    eq = build_equations(spec)
    n, m = eq.n, eq.m
    kinds = engine.caps.treatment
    if len(kinds) != m:
        raise AssertionError("pad treatment does not match the pad deformations of the equations")
    quasi = {eq.dL[j]: 0 for j in range(m) if kinds[j] == "quasi-static"}

    def qs(e: Any) -> Any:
        return se.sympify(e).subs(quasi) if quasi else se.sympify(e)

    ddQ = set(eq.ddQ)
    # mass matrix and forcing: R = M(Q) Qddot + f(Q, Qdot, L, Ldot), R linear in Qddot
    R = [qs(eq.R[i]) for i in range(n)]
    Mx, f = [], []
    zero_dd = {s: 0 for s in eq.ddQ}
    for i in range(n):
        for j in range(n):
            e = R[i].diff(eq.ddQ[j])
            _check_free(f"dR/dQddot[{i}, {j}]", e, ddQ)  # R is linear in Qddot
            Mx.append(e)
        f.append(R[i].subs(zero_dd))
    # unilateral contact: the engagement chi_j (1 pressed, 0 lifted) factors pad j's contact force f_p
    chi = [se.Symbol(f"chi__{j}") for j in range(len(spec.pads))]
    eq_u = build_equations(spec, engagement={pad.name: c for pad, c in zip(spec.pads, chi)})
    # pad balances with the engagement (a lifted pad's G_j has no friction term): each G_j depends on its own
    # unknown only
    bal, dbal = [], []
    for j in range(m):
        g = qs(eq_u.G[j])
        others = {eq.L[k] for k in range(m) if k != j} | {eq.dL[k] for k in range(m) if k != j}
        _check_free(f"G[{j}]", g, others | ddQ)
        bal.append(g)
        dbal.append(g.diff(eq.L[j] if kinds[j] == "quasi-static" else eq.dL[j]))
    contact: list[Any] = []
    for c, l in zip(eq.pads, eq.tangential):
        contact += [qs(c.F_n), qs(c.v_r[0]), qs(c.v_r[1]), qs(c.v_r[2]), qs(c.h), qs(c.hdot), qs(l)]
    terms = energy_terms(eq)
    # unilateral contact: R = R(chi = 0) + sum_j chi_j D_j
    release = []
    for j in range(len(spec.pads)):
        for i in range(n):
            r = qs(eq_u.R[i])
            e = r.diff(chi[j]) if chi[j] in r.free_symbols else se.Integer(0)
            _check_free(f"dR[{i}]/dchi[{j}]", e, ddQ | set(chi))  # the contact force is linear in chi, free of Qddot
            release.append(e)
    return {"eq": eq, "chi": chi, "kinds": kinds, "mass_force": Mx + f, "pad_balance": bal + dbal, "contact": contact,
            "energy": [qs(terms[k]) for k in ENERGY_TERMS], "pad_scale": [qs(e) for e in _pad_scales(se, eq)],
            "release": release}


def _pad_scales(se: Any, eq: Any) -> list[Any]:
    """Per pad unknown, the size of the terms of ``G_j = (l - u_m) + c (f_t + mu* N0)`` (its rounding level / eps)."""
    from ..model.components import state_name
    from ..symbolic.contact import angle_cos_sin

    spec = eq.spec
    Q = dict(zip(eq.coords, eq.Q))
    cal = {c.name: c for c in spec.calipers}
    out = []
    for pad, c, l in zip(spec.pads, eq.pads, eq.tangential):
        if pad.treatment is None:  # a tangential DOF or a rigid support: no pad unknown
            continue
        comp = 1 / _value(se, eq, pad.k_ip)  # the compliance (symbol, or 1/number)
        mount = cal.get(pad.mount) if pad.mount else None
        ca = angle_cos_sin(se, pad.angle_deg)[0]
        u_m = Q[state_name("uc", mount.name)] * ca if mount and "tangential" in mount.dofs else se.Integer(0)
        out.append(abs(l) + abs(u_m) + abs(comp * c.f_t) + abs(comp * c.mu_star * _value(se, eq, pad.preload)))
    return out


def kernel_source(engine: Engine, ex: dict[str, Any] | None = None) -> str:
    """Complete source of a model's simulation kernel module (generated functions + templates).

    Parameters
    ----------
    engine : Engine
        The model's engine (its equations and pad treatment).
    ex : dict, optional
        The symbolic outputs (:func:`_expressions`; default computed).

    Returns
    -------
    str
        Python source (numba): ``rhs``, ``rhs_u``, ``solve_pads``, ``solve_pads_e``, ``pad_balance``,
        ``event_values``, ``contact``, ``energy``, ``pad_scale``, ``post_process``, ``dop853`` and ``META``.

    Raises
    ------
    ValueError
        If the equations do not have the structure the integrator relies on (``R`` linear in ``Qddot``, each
        pad balance depending on its own unknown only).
    """
    from .printer import FunctionSpec, generate_module

    ex = _expressions(engine) if ex is None else ex
    spec = engine.spec
    eq = ex["eq"]
    n, m, npad = eq.n, eq.m, len(spec.pads)
    kinds = ex["kinds"]
    dyn = [j for j in range(m) if kinds[j] == "dynamic"]
    meta = {"model": spec.name, "coords": list(eq.coords), "algebraic": list(eq.algebraic), "kinds": list(kinds),
            "pads": [p.name for p in spec.pads], "params": list(eq.param_names), "tilting": bool(spec.disk.tilting)}
    preamble = _PREAMBLE.format(n=n, m=m, npad=npad, ndyn=len(dyn), ny=2 * n + len(dyn), nev=2 * npad,
                                kind=[0 if k == "quasi-static" else 1 for k in kinds], dyn=dyn)
    y = ("y_", [*eq.Q, *eq.dQ])
    ll, dl, pp = ("l_", eq.L), ("dl_", eq.dL), ("p_", eq.params)
    args = (y, ll, dl, pp)
    specs = [
        FunctionSpec("pad_balance_e", (y, ll, dl, pp, ("e_", ex["chi"])), ex["pad_balance"],
                     "G_j, then dG_j/dz_j (z_j = l_j quasi-static, ldot_j dynamic), eqs. (33)-(34) generalized; "
                     "e: per pad 1 pressed, 0 lifted off (no friction on the pad)."),
        FunctionSpec("mass_force", args, ex["mass_force"],
                     "M = dR/dQddot (n x n, row-major), then f = R(Qddot = 0): M Qddot + f = 0 (eq. 44 generalized)."),
        FunctionSpec("contact", args, ex["contact"],
                     "Per pad: F_n [N], v_r (3) [m/s], h [m], hdot [m/s], l [m] (eqs. 12-34)."),
        FunctionSpec("energy", args, ex["energy"], "T2, T1, T0, V_support, V_pads [J]."),
        FunctionSpec("release", args, ex["release"],
                     "Per pad j, the part D_j of the forcing f due to its contact force f_p (n entries): f = f0 + "
                     "sum_j chi_j D_j; a lifted pad (chi_j = 0) is removed by f - D_j."),
        FunctionSpec("pad_scale", args, ex["pad_scale"],
                     "Per pad unknown: |l| + |u_m| + |c f_t| + |c mu* N0|, the size of the terms of G_j [m]."),
    ]
    header = (f"Generated by brakesqueal.codegen.simulation for the equations of model {spec.name!r}. Do not edit.\n\n"
              f"y = ({', '.join(str(s) for s in y[1])}, <dynamic pad deformations>)\n"
              f"l = ({', '.join(map(str, eq.L))}); dl = their rates; pad treatment {list(kinds)}\n"
              f"p = ({', '.join(eq.param_names)})")
    src = generate_module(specs, header, decorator=_DECORATOR, unpack="index", out="out_", preamble=preamble)
    body = template("simulation_pads") + template("dop853") + template("simulation_dop853")
    return src + body + f"\nMETA = {meta!r}\n"


def variational_source(engine: Engine) -> str:
    """Source of a model's variational module: :func:`kernel_source` plus the exact Jacobians.

    Adds the generated ``rg_jacobian(y, l, dl, a, p, out)`` (``d(R, G)/d(Q, Qdot, Qddot, L, Ldot)`` at
    ``Qddot = a``, ``(n + m) x (3n + 2m)`` row-major, quasi-static pads' ``Ldot = 0`` substituted after
    differentiating) and ``rg_param_jacobian`` (``d(R, G)/dp``, ``(n + m) x P``), and the template
    :mod:`.templates.variational` (``nl_f``, ``nl_jac``, ``nl_dfdp``).

    Parameters
    ----------
    engine : Engine
        The model's engine.

    Returns
    -------
    str
        Python source (numba).
    """
    import symengine as se

    from .printer import FunctionSpec, generate_module

    ex = _expressions(engine)
    eq = ex["eq"]
    n, m = eq.n, eq.m
    quasi = {eq.dL[j]: 0 for j in range(m) if ex["kinds"][j] == "quasi-static"}
    phi = [se.sympify(e) for e in (*eq.R[:n], *(eq.G[:m] if m else []))]
    xs = [*eq.Q, *eq.dQ, *eq.ddQ, *eq.L, *eq.dL]

    def sub(e: Any) -> Any:
        return e.subs(quasi) if quasi else e

    jx = [sub(r.diff(x)) for r in phi for x in xs]
    jp = [sub(r.diff(q)) for r in phi for q in eq.params]
    args = (("y_", [*eq.Q, *eq.dQ]), ("l_", eq.L), ("dl_", eq.dL), ("a_", eq.ddQ), ("p_", eq.params))
    specs = [
        FunctionSpec("rg_jacobian", args, jx, "d(R, G)/d(Q, Qdot, Qddot, L, Ldot), (n + m) x (3n + 2m) row-major."),
        FunctionSpec("rg_param_jacobian", args, jp, "d(R, G)/dp, (n + m) x P row-major."),
    ]
    extra = generate_module(specs, f"Exact Jacobians of the equations of model {engine.spec.name!r}.",
                            decorator=_DECORATOR, unpack="index", out="out_")
    return (kernel_source(engine, ex) + "\n\n" + extra + f"\n_P = {len(eq.params)}  # model parameters\n"
            + template("variational"))


def load_kernels(engine: Engine, *, variational: bool = False, use_cache: bool = True) -> types.ModuleType:
    """Import a model's simulation kernels (or its variational module), generating and caching them on first use.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    variational : bool, optional
        The variational module (:func:`variational_source`, file :data:`VARIATIONAL_NAME`) instead of the
        kernels (:func:`kernel_source`, file :data:`KERNEL_NAME`).
    use_cache : bool, optional
        Keep the source in the package cache (entry ``model-<hash>``), where numba also caches its machine
        code (default ``True``); ``False`` generates and compiles in memory and writes no file.

    Returns
    -------
    module
    """
    if variational:
        return cache.load_module(engine.key, VARIATIONAL_NAME, lambda: variational_source(engine),
                                 use_cache=use_cache)
    return cache.load_module(engine.key, KERNEL_NAME, lambda: kernel_source(engine), use_cache=use_cache)


def flow_source() -> str:
    """Source of the flow integrator: the one DOP853 step (:mod:`.templates.dop853`) driven with variational
    equations and first-class vector fields (:mod:`.templates.flow_dop853`)."""
    head = ('"""Generated by brakesqueal.codegen.simulation: the compiled flow\'s DOP853. Do not edit."""\n\n'
            "import math\n\nimport numpy as np\nfrom numba import njit\n")
    return head + template("dop853") + template("flow_dop853")


_FLOW: dict[bool, types.ModuleType] = {}


def flow_kernel(use_cache: bool = True) -> types.ModuleType:
    """The flow integrator module (``dop853``, ``F_SIGNATURE``, ``JAC_SIGNATURE``), loaded once per process.

    Parameters
    ----------
    use_cache : bool, optional
        Keep the source and numba's machine code in the package cache (entry :data:`FLOW_KEY`).

    Returns
    -------
    module
    """
    mod = _FLOW.get(use_cache)
    if mod is None:
        import warnings

        from numba.core.errors import NumbaExperimentalFeatureWarning

        with warnings.catch_warnings():  # compiled here (explicit signature): the vector field's first-class
            warnings.simplefilter("ignore", NumbaExperimentalFeatureWarning)  # functions ride in the stages' tuple
            mod = _FLOW[use_cache] = cache.load_module(FLOW_KEY, "dop853.py", flow_source, use_cache=use_cache)
    return mod
