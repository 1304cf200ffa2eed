r"""The model :func:`~._integrate.simulate` integrates: an engine's simulation kernels with their silent motion,
linearization and vector field (any model).

:func:`simulation_model` wraps the simulation kernels of an
:class:`~brakesqueal.codegen.engine.Engine` (:meth:`Engine.simulation_kernels
<brakesqueal.codegen.engine.Engine.simulation_kernels>`); the engine is built by
the caller (an entry point), never here.  The pads' treatment is the engine's
(:attr:`Capabilities.treatment <brakesqueal.codegen.engine.Capabilities.treatment>`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np

from ..errors import BrakesquealError, ParameterError
from .estimate import LinearModes, linear_modes

if TYPE_CHECKING:
    from ..analysis.equilibrium import SilentMotion
    from ..analysis.linear import LinearModel
    from ..codegen.compiled import CompiledModel
    from ..codegen.engine import Engine
    from ..model.components import ModelSpec
    from ..model.parameters import Parameters

__all__ = ["SilentState", "SimulationModel", "simulation_model", "state_jacobian"]

_EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class SilentState:
    """The silent motion in the integrator's variables.

    Attributes
    ----------
    y : ndarray, shape (2n + k,)
        ``(Q0, 0, L0 of the dynamic pads)``.
    l, dl : ndarray, shape (m,)
        Pad deformations ``L0`` and their rates (zero).
    vr0 : ndarray, shape (3 n_pads,)
        Sliding velocity of every pad at the silent motion (reference of the sliding-reversal events).
    ztol : ndarray, shape (m,)
        Absolute Newton tolerance of every pad unknown: its rounding level
        ``64 eps S_j / |dG_j/dz_j|`` with ``S_j`` the size of the terms of ``G_j``
        at the silent motion (generated ``pad_scale``).
    silent : SilentMotion
        The silent motion (:func:`~brakesqueal.analysis.equilibrium.silent_motion`).
    """

    y: np.ndarray
    l: np.ndarray
    dl: np.ndarray
    vr0: np.ndarray
    ztol: np.ndarray
    silent: SilentMotion


@dataclass(frozen=True, eq=False)
class SimulationModel:
    """A model :func:`~._integrate.simulate` integrates: its engine and compiled simulation kernels.

    Build it with :func:`simulation_model`.

    Attributes
    ----------
    engine : Engine
        The model's engine (:func:`brakesqueal.codegen.build`, built by the caller): its equations, pad
        treatment, silent motion and linearization.
    kernels : module
        numba functions ``rhs``, ``solve_pads``, ``event_values``, ``contact``, ``energy``, ``post_process``
        and the integrator ``dop853`` (:meth:`Engine.simulation_kernels
        <brakesqueal.codegen.engine.Engine.simulation_kernels>`).
    use_cache : bool
        Whether the on-disk code cache is used.
    """

    engine: Engine
    kernels: ModuleType
    use_cache: bool = True

    @property
    def spec(self) -> ModelSpec:
        """The model."""
        return self.engine.spec

    @property
    def compiled(self) -> CompiledModel:
        """The model's compiled residuals (:attr:`Engine.compiled <brakesqueal.codegen.engine.Engine.compiled>`)."""
        return self.engine.compiled

    # ---------------------------------------------------------------- structure
    @property
    def name(self) -> str:
        """The model's name."""
        return str(self.spec.name)

    @property
    def coords(self) -> tuple[str, ...]:
        """Coordinates ``Q`` (the names of
        :attr:`LinearModel.coords <brakesqueal.analysis.linear.LinearModel.coords>`)."""
        return self.engine.caps.coords

    @property
    def pad_unknowns(self) -> tuple[str, ...]:
        """Pad deformations ``L`` (``l_<pad>``)."""
        return self.engine.caps.algebraic

    @property
    def pad_kinds(self) -> tuple[str, ...]:
        """Treatment of every entry of :attr:`pad_unknowns`: ``"quasi-static"`` or ``"dynamic"`` (the engine's
        :attr:`Capabilities.treatment <brakesqueal.codegen.engine.Capabilities.treatment>`)."""
        return self.engine.caps.treatment

    @property
    def dynamic(self) -> tuple[str, ...]:
        """Pad deformations that are states (rate-dependent friction or a tangential damper)."""
        return tuple(n for n, k in zip(self.pad_unknowns, self.pad_kinds) if k == "dynamic")

    def undamped(self, params: Parameters) -> tuple[str, ...]:
        """The :attr:`dynamic` pad deformations without a tangential damper (``d_ip = 0`` at ``params``).

        Their rate is not determined through lift-off (``docs/simulation.md``, unilateral contact).
        """
        by_pad = {p.name: p for p in self.spec.pads}
        out = []
        for name, pad in zip(self.pad_unknowns, self.unknown_pads):
            d = by_pad[pad].d_ip
            value = float(params[d]) if isinstance(d, str) else float(d)
            if name in self.dynamic and not value > 0.0:
                out.append(name)
        return tuple(out)

    @property
    def pads(self) -> tuple[str, ...]:
        """Pad names."""
        return tuple(p.name for p in self.spec.pads)

    @property
    def unknown_pads(self) -> tuple[str, ...]:
        """The pad of every entry of :attr:`pad_unknowns`."""
        return tuple(p.name for p in self.spec.pads if p.treatment is not None)

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.coords)

    @property
    def state_names(self) -> tuple[str, ...]:
        """Names of the integrator state ``y = (Q, Qdot, L_dynamic)``."""
        return (*self.coords, *(f"d{c}" for c in self.coords), *self.dynamic)

    @property
    def tilting(self) -> bool:
        """Whether the disk tilts (``q1, q2`` are the first coordinates)."""
        return bool(self.spec.disk.tilting)

    # ---------------------------------------------------------------- numbers
    def parameters(self, params: Parameters) -> Parameters:
        """``params`` as :class:`~brakesqueal.model.parameters.Parameters` of this model (checked)."""
        from ..analysis.equilibrium import as_parameters
        from ..codegen.compiled import model_key

        params = as_parameters(params)
        if params.model is not self.spec and model_key(params.model) != self.engine.key:
            raise ParameterError(f"the parameters are of model '{params.model.name}', the simulation model is "
                                 f"'{self.name}'")
        return params

    def parameter_vector(self, params: Parameters) -> np.ndarray:
        """Parameters in packing order (compliances ``1/k_ip``): the ``p`` of every kernel."""
        return np.asarray(self.parameters(params).vector(), dtype=float)

    def silent(self, params: Parameters) -> SilentState:
        """The silent motion (eq. 46) in the integrator's variables.

        Raises
        ------
        SilentMotionError
            When there is no usable silent motion.
        ParameterError
            When a pad with rate-dependent friction has no determined
            tangential rate at the silent motion (``dG/dldot = 0``, e.g. a
            zero friction slope) or a pad mode too fast to integrate.
        """
        from ..analysis.equilibrium import silent_motion

        params = self.parameters(params)
        cm = self.compiled
        sm = silent_motion(self.engine, params)
        p = self.parameter_vector(params)
        n, m = cm.n, cm.m
        dyn = [j for j, k in enumerate(self.pad_kinds) if k == "dynamic"]
        y = np.concatenate([sm.q0, np.zeros(n), sm.l0[dyn]]).astype(float)
        l = np.array(sm.l0, dtype=float)
        dl = np.zeros(m)
        ztol = np.zeros(m)
        if m:
            S = np.empty(m)
            self.kernels.pad_scale(y, l, dl, p, S)
            J = cm.jacobian_matrix(sm.state(), list(p))
            for j, kind in enumerate(self.pad_kinds):
                G_l, G_dl = J[n + j, 3 * n + j], J[n + j, 3 * n + m + j]
                d = G_l if kind == "quasi-static" else G_dl
                pad = f"pad '{self.unknown_pads[j]}'"
                if not (math.isfinite(d) and d != 0.0):
                    raise ParameterError(
                        f"{pad}: the tangential balance does not determine the pad's "
                        f"{'deformation' if kind == 'quasi-static' else _NO_RATE} "
                        "at the silent motion; give the pad a rate-dependent friction law with a nonzero slope "
                        "or a coulomb law")  # fmt: skip
                if kind == "dynamic" and abs(G_l / G_dl) > 1e9:
                    raise ParameterError(
                        f"{pad}: its pad mode (lambda ~ {-G_l / G_dl:.3g} 1/s, from the friction slope) is too fast "
                        "for the explicit integrator (|lambda| > 1e9 1/s); use a larger friction slope or a coulomb "
                        "law for this pad")  # fmt: skip
                ztol[j] = 64 * _EPS * float(S[j]) / abs(d) if math.isfinite(float(S[j])) else 0.0
        cb = np.empty(7 * len(self.pads))
        self.kernels.contact(y, l, dl, p, cb)
        vr0 = np.concatenate([cb[7 * j + 1:7 * j + 4] for j in range(len(self.pads))])
        return SilentState(y=y, l=l, dl=dl, vr0=vr0, ztol=ztol, silent=sm)

    def linear_matrix(self, params: Parameters) -> tuple[np.ndarray, LinearModel | None]:
        """First-order state matrix of the linearization that matches the simulated equations.

        Its state is the deviation ``(Q - Q0, Qdot, L_dynamic - L0)`` of the
        integrator's state.  It is ``linearize(params, pad_rates="quasi-static").A``
        when every pad is quasi-static, ``linearize(params).A`` when the pads
        it keeps are exactly the dynamic pads, and otherwise the same
        elimination made here with this model's pad treatment (quasi-static
        pads: ``ldot := 0``; dynamic pads kept).

        Returns
        -------
        A : ndarray, shape (2n + k, 2n + k)
        linear : LinearModel or None
            The :class:`~brakesqueal.analysis.linear.LinearModel` used (``None``
            for the own elimination).
        """
        from ..analysis.linear import linearize

        params = self.parameters(params)
        dyn = self.dynamic
        lm = linearize(self.engine, params, pad_rates="kept" if dyn else "quasi-static")
        if tuple(lm.pad_states) == dyn:
            return np.asarray(lm.A, dtype=float), lm
        return _own_linear_matrix(self, params, lm.silent), None

    def linear_modes(self, params: Parameters) -> LinearModes | None:
        """Eigenvalues and left/right eigenvectors of :meth:`linear_matrix` (``None`` if unavailable)."""
        try:
            return linear_modes(self.linear_matrix(params)[0])
        except (BrakesquealError, np.linalg.LinAlgError):
            return None

    def _engagement(self, engaged: Sequence[bool] | None) -> np.ndarray:
        """Per pad 1 pressed, 0 lifted off (int64, the kernels' type); default every pad pressed."""
        eng = np.ones(len(self.pads), dtype=np.int64) if engaged is None else np.asarray(engaged, dtype=np.int64)
        if eng.shape != (len(self.pads),):
            raise ParameterError(f"'engaged' must have one entry per pad ({len(self.pads)}); got {eng.size}")
        return eng

    def contact_at(self, params: Parameters, y: Sequence[float] | np.ndarray, silent: SilentState | None = None,
                   engaged: Sequence[bool] | None = None) -> np.ndarray:
        """Contact quantities at an integrator state ``y`` (pad unknowns solved), shape ``(n_pads, 7)``.

        Columns are :data:`~brakesqueal.codegen.compiled.CONTACT_FIELDS`.  With ``engaged`` (one entry per
        pad, default all pressed) the pad unknowns of lifted pads solve their balance without friction; the
        columns are still the bilateral quantities (``F_n`` is the force the pad would carry if pressed).
        """
        st = silent or self.silent(params)
        p = self.parameter_vector(params)
        yy = np.ascontiguousarray(y, dtype=float)
        l, dl = st.l.copy(), st.dl.copy()
        g = np.empty(2 * len(l) + 1)
        eng = self._engagement(engaged)
        if not self.kernels.solve_pads_e(yy, l, dl, p, st.ztol, g, eng):
            raise ParameterError("the pad equations cannot be solved at this state")
        cb = np.empty(7 * len(self.pads))
        self.kernels.contact(yy, l, dl, p, cb)
        return cb.reshape(len(self.pads), 7)

    def vector_field(self, params: Parameters, silent: SilentState | None = None, engaged: Sequence[bool] | None = None
                     ) -> tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray]]:
        """``f(y)`` and its exact Jacobian ``f_y(y)`` at fixed parameters (the pad unknowns solved, warm-started).

        ``f`` is the compiled right-hand side the integrator uses; ``f_y`` is
        :func:`state_jacobian` of the generated ``d(R, G)/dx`` at the state.

        Parameters
        ----------
        params : Parameters
            The parameters.
        silent : SilentState, optional
            The silent motion (default: computed).
        engaged : sequence of bool, optional
            Unilateral contact: which pads are pressed (default all).  With a
            lifted pad ``f`` is the integrator's right-hand side without that
            pad's contact force and ``f_y`` is a fourth-order central
            difference of it (steps ``1e-4`` of each component's scale:
            relative error about ``1e-12``-``1e-10``).

        Returns
        -------
        f, jac : callable
            ``f(y) -> (2n + k,)`` and ``jac(y) -> (2n + k, 2n + k)``.

        Raises
        ------
        ParameterError
            (from the callables) when the pad equations cannot be solved at a state.
        """
        st = silent or self.silent(params)
        p = self.parameter_vector(params)
        plist = list(map(float, p))
        k, cm, n = self.kernels, self.compiled, self.n
        l, dl = st.l.copy(), st.dl.copy()
        g, mw = np.empty(2 * len(l) + 1), np.empty(n * n + n)
        ny = st.y.size
        eng = self._engagement(engaged)
        D = np.empty(len(self.pads) * n + 1)

        def f(y: np.ndarray) -> np.ndarray:
            out = np.empty(ny)
            k.rhs_u(np.ascontiguousarray(y, dtype=float), l, dl, p, st.ztol, g, mw, eng, D, out)
            if not np.all(np.isfinite(out)):
                raise ParameterError("the equations of motion cannot be solved at this state (pad equations or "
                                     "a singular mass matrix)")
            return out

        if not eng.all():
            scale = np.abs(st.y) + np.concatenate([_scales(self, params)[:n], _scales(self, params)[:n] * 1e3,
                                                   _scales(self, params)[n:]]) * 1e-3

            def jac_fd(y: np.ndarray) -> np.ndarray:
                y = np.asarray(y, dtype=float)
                J = np.empty((ny, ny))
                for i in range(ny):
                    h = 1e-4 * max(scale[i], abs(y[i]))
                    e = np.zeros(ny)
                    e[i] = h
                    J[:, i] = (8 * (f(y + e) - f(y - e)) - (f(y + 2 * e) - f(y - 2 * e))) / (12 * h)
                return J

            return f, jac_fd

        def jac(y: np.ndarray) -> np.ndarray:
            y = np.ascontiguousarray(y, dtype=float)
            acc = f(y)[n:2 * n]
            x = [*y[:n], *y[n:2 * n], *acc, *l, *dl]
            return state_jacobian(self, cm.jacobian_matrix(x, plist))

        return f, jac

    def variational_kernels(self) -> ModuleType:
        """The model's compiled vector field with its exact Jacobian (generated, numba; loaded on first use).

        Functions ``nl_f(y, s, theta, out)``, ``nl_jac(y, s, theta, out)`` and ``nl_dfdp(y, s, theta, out)``
        with the signatures of :data:`brakesqueal.nonlinear.compiled.F_SIGNATURE` /
        ``JAC_SIGNATURE``: ``f(y)`` (the integrator's right-hand side, bilateral contact), its exact
        Jacobian ``f_y`` (implicit differentiation of the generated ``d(R, G)/dx``, the same as
        :func:`state_jacobian`) and ``f_p dp/ds``; ``theta`` from :meth:`variational_theta`.
        """
        return self.engine.simulation_kernels(variational=True, use_cache=self.use_cache)

    def variational_theta(self, params: Parameters, dp: Sequence[float] | np.ndarray | None = None,
                          silent: SilentState | None = None) -> np.ndarray:
        """The ``theta`` vector of :meth:`variational_kernels` at ``params``.

        Parameters
        ----------
        params : Parameters
            The parameters.
        dp : sequence of float, optional
            Derivative of :meth:`parameter_vector` along the continuation parameter ``s``
            (``nl_dfdp`` returns ``f_p dp/ds``); default zeros.
        silent : SilentState, optional
            The silent motion (its pad unknowns start the pads' Newton iterations; default computed).

        Returns
        -------
        ndarray
            ``(p, dp/ds, ztol, l, dl)``; the kernels update ``l``, ``dl`` in place (warm start).
        """
        st = silent or self.silent(params)
        p = self.parameter_vector(params)
        d = np.zeros(p.size) if dp is None else np.asarray(dp, dtype=float)
        if d.shape != p.shape:
            raise ParameterError(f"'dp' must have one entry per parameter ({p.size}); got {d.size}")
        return np.ascontiguousarray(np.concatenate([p, d, st.ztol, st.l, st.dl]), dtype=float)

    def rhs(self, params: Parameters, silent: SilentState | None = None) -> Callable[[float, np.ndarray], np.ndarray]:
        """``f(t, y)`` for SciPy (the pad unknowns are solved on the way, warm-started)."""
        st = silent or self.silent(params)
        p = self.parameter_vector(params)
        k = self.kernels
        l, dl = st.l.copy(), st.dl.copy()
        g, mw = np.empty(2 * len(l) + 1), np.empty(self.n * self.n + self.n)
        ny = st.y.size

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            out = np.empty(ny)
            k.rhs(np.ascontiguousarray(y, dtype=float), l, dl, p, st.ztol, g, mw, out)
            return out

        return fun


def _own_linear_matrix(model: SimulationModel, params: Parameters, sm: SilentMotion) -> np.ndarray:
    """State matrix of ``E xi' = A xi``, ``xi = (dQ, dQdot, dL_dyn)``; quasi-static pads eliminated (``ldot = 0``)."""
    cm = model.compiled
    p = list(map(float, params.vector()))
    J = cm.zero_jacobian_matrix(p) if sm.trivial else cm.jacobian_matrix(sm.state(), p)
    return state_jacobian(model, J)


def state_jacobian(model: SimulationModel, J: np.ndarray) -> np.ndarray:
    """Jacobian of the integrator's vector field ``y' = f(y)``, ``y = (Q, Qdot, L_dynamic)``, at one state.

    Implicit differentiation of the residuals ``(R, G)(Q, Qdot, Qddot, L, Ldot) = 0`` (eq. 44 and the pads'
    tangential balances) for the unknowns ``Qddot``, the quasi-static pads' ``L`` (``Ldot = 0``) and the
    dynamic pads' ``Ldot``: ``f_y = E^-1 A``.

    Parameters
    ----------
    model : SimulationModel
        The model (its pad treatment).
    J : ndarray, shape (n + m, 3n + 2m)
        ``d(R, G)/dx`` at the state (:meth:`CompiledModel.jacobian_matrix
        <brakesqueal.codegen.compiled.CompiledModel.jacobian_matrix>`), with the pad unknowns solved there.

    Returns
    -------
    ndarray, shape (2n + k, 2n + k)
    """
    cm = model.compiled
    n, m = cm.n, cm.m
    R, G = J[:n], J[n:]
    Q, dQ, ddQ, L, dL = (slice(0, n), slice(n, 2 * n), slice(2 * n, 3 * n), slice(3 * n, 3 * n + m),
                         slice(3 * n + m, 3 * n + 2 * m))  # fmt: skip
    dyn = np.array([k == "dynamic" for k in model.pad_kinds], dtype=bool)
    qs = ~dyn
    M, D, K = R[:, ddQ].copy(), R[:, dQ].copy(), R[:, Q].copy()
    if not dyn.any():  # no pad state: f_y = [[0, I], [-M^-1 K, -M^-1 D]] (the same elimination, fewer operations)
        if m:
            P = np.linalg.solve(G[:, L].T, R[:, L].T).T
            M, D, K = M - P @ G[:, ddQ], D - P @ G[:, dQ], K - P @ G[:, Q]
        out = np.zeros((2 * n, 2 * n))
        out[:n, n:] = np.eye(n)
        out[n:] = -np.linalg.solve(M, np.hstack([K, D]))
        return out
    R_L, R_dL = R[:, L], R[:, dL]
    G_Q, G_dQ, G_ddQ, G_L, G_dL = G[:, Q], G[:, dQ], G[:, ddQ], G[:, L], G[:, dL]
    if qs.any():
        P = np.linalg.solve(G_L[np.ix_(qs, qs)].T, R_L[:, qs].T).T
        M, D, K = M - P @ G_ddQ[qs], D - P @ G_dQ[qs], K - P @ G_Q[qs]
        Pd = np.linalg.solve(G_L[np.ix_(qs, qs)].T, G_L[np.ix_(dyn, qs)].T).T
        R_Ld = R_L[:, dyn] - P @ G_L[np.ix_(qs, dyn)]
        G_Qd, G_dQd, G_ddQd = G_Q[dyn] - Pd @ G_Q[qs], G_dQ[dyn] - Pd @ G_dQ[qs], G_ddQ[dyn] - Pd @ G_ddQ[qs]
        G_Ld = G_L[np.ix_(dyn, dyn)] - Pd @ G_L[np.ix_(qs, dyn)]
    else:
        R_Ld, G_Qd, G_dQd, G_ddQd, G_Ld = R_L, G_Q, G_dQ, G_ddQ, G_L
    k = int(dyn.sum())
    I, Z = np.eye(n), np.zeros((n, n))
    Znk, Zkn = np.zeros((n, k)), np.zeros((k, n))
    E = np.block([[I, Z, Znk], [Z, M, R_dL[:, dyn]], [Zkn, G_ddQd, G_dL[np.ix_(dyn, dyn)]]])
    A = np.block([[Z, I, Znk], [-K, -D, -R_Ld], [-G_Qd, -G_dQd, -G_Ld]])
    return np.linalg.solve(E, A)


def simulation_model(engine: Engine, *, use_cache: bool = True) -> SimulationModel:
    """The simulation model of an engine (any model).

    Parameters
    ----------
    engine : Engine
        The model's engine (:func:`brakesqueal.codegen.build`; the caller builds it once).
    use_cache : bool, optional
        Keep the generated kernel source in the package cache (:mod:`brakesqueal.codegen.cache`), where numba
        also caches its machine code (default ``True``); ``False`` generates and compiles in memory and writes
        no file.

    Returns
    -------
    SimulationModel
        Its kernels are generated once per engine (:meth:`Engine.simulation_kernels
        <brakesqueal.codegen.engine.Engine.simulation_kernels>`).

    Raises
    ------
    ParameterError
        ``engine`` is not an engine.
    """
    from ..codegen.engine import Engine

    if not isinstance(engine, Engine):
        raise ParameterError(f"The argument 'engine' must be an Engine (brakesqueal.engine(model)); got "
                             f"{type(engine).__name__}", parameter="engine")
    return SimulationModel(engine=engine, kernels=engine.simulation_kernels(use_cache=use_cache), use_cache=use_cache)


def _value(params: Parameters, v: str | float) -> float:
    return float(params[v]) if isinstance(v, str) else float(v)


def _scales(model: SimulationModel, params: Parameters) -> np.ndarray:
    """Scale of every coordinate and pad state ``(Q, L_dynamic)``: 1 rad for a tilt, the largest pad radius [m]
    for a length."""
    length = max(abs(_value(params, p.radius)) for p in model.spec.pads) or 1.0
    q = [1.0 if c in ("q1", "q2") and model.tilting else length for c in model.coords]
    return np.array(q + [length] * len(model.dynamic))


_NO_RATE = "rate (a zero friction slope dmu/dv and no tangential damper d_ip)"
