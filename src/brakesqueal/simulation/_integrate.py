r"""The simulation entry point :func:`simulate` and the compiled model it integrates (any model)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Callable, Literal, Sequence

import numpy as np

from ..errors import BrakesquealError, ParameterError, SilentMotionError
from ..model.options import stick_slip_everywhere
from ..status import RunStatus
from .estimate import LinearModes, linear_modes
from .trajectory import EstimationRecord, Trajectory

__all__ = ["METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "SimulationModel", "SilentState", "default_model",
           "simulation_model", "simulate", "estimation_rate", "state_jacobian"]

#: Integration methods: the compiled DOP853 (default) and SciPy's ``solve_ivp`` methods.
METHODS: tuple[str, ...] = ("DOP853-jit", "DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
#: Samples per period of the highest linear frequency in the estimation record (summary numbers).
POINTS_PER_PERIOD = 20
#: Largest number of output samples of one run (``sample_rate`` x duration).
MAX_OUTPUT_SAMPLES = 50_000_000
#: Largest deviation of the default start along the leading mode: tilt [rad] (a non-tilting disk: coordinate [m]).
START_AMPLITUDE = 1e-5
#: Wall time [s] of one call of the compiled integrator (between calls progress is reported, Ctrl-C acts and
#: other threads get the interpreter lock: the explorer's server stays responsive while a simulation runs).
CHUNK_SECONDS = 0.02
#: Output samples post-processed per compiled call (about 0.1 s).
_POST_BLOCK = 65536
EventMode = Literal["stop", "continue", "off"]
ContactLaw = Literal["bilateral", "unilateral"]
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
    silent: Any


@dataclass(frozen=True, eq=False)
class SimulationModel:
    """A model :func:`simulate` integrates: its compiled equations and numba kernels.

    Attributes
    ----------
    spec : ModelSpec
        The model.
    kernels : module
        numba functions ``rhs``, ``solve_pads``, ``event_values``, ``contact``,
        ``energy``, ``post_process`` and the integrator ``dop853``
        (:mod:`brakesqueal.simulation._kernels`).
    engine : Engine
        The model's engine (:func:`brakesqueal.codegen.build`), for the silent motion and the linearization.
    use_cache : bool
        Whether the on-disk code cache is used.
    """

    spec: Any
    kernels: ModuleType
    engine: Any
    use_cache: bool = True

    @property
    def compiled(self) -> Any:
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
        return tuple(self.kernels.META["coords"])

    @property
    def pad_unknowns(self) -> tuple[str, ...]:
        """Pad deformations ``L`` (``l_<pad>``)."""
        return tuple(self.kernels.META["algebraic"])

    @property
    def pad_kinds(self) -> tuple[str, ...]:
        """Treatment of every entry of :attr:`pad_unknowns`: ``"quasi-static"`` or ``"dynamic"``."""
        return tuple(self.kernels.META["kinds"])

    @property
    def dynamic(self) -> tuple[str, ...]:
        """Pad deformations that are states (rate-dependent friction or a tangential damper)."""
        return tuple(n for n, k in zip(self.pad_unknowns, self.pad_kinds) if k == "dynamic")

    def undamped(self, params: Any) -> tuple[str, ...]:
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
        return tuple(self.kernels.META["pads"])

    @property
    def unknown_pads(self) -> tuple[str, ...]:
        """The pad of every entry of :attr:`pad_unknowns`."""
        return tuple(p.name for p in self.spec.pads if "tangential" not in p.dofs
                     and (isinstance(p.k_ip, str) or math.isfinite(p.k_ip)))

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
    def parameters(self, params: Any) -> Any:
        """``params`` as :class:`~brakesqueal.model.parameters.Parameters` of this model (checked)."""
        from ..analysis.equilibrium import as_parameters
        from ..codegen.compiled import model_key

        params = as_parameters(params)
        if params.model is not self.spec and model_key(params.model) != model_key(self.spec):
            raise ParameterError(f"the parameters are of model '{params.model.name}', the simulation model is "
                                 f"'{self.name}'")
        return params

    def parameter_vector(self, params: Any) -> np.ndarray:
        """Parameters in packing order (compliances ``1/k_ip``): the ``p`` of every kernel."""
        return np.asarray(self.parameters(params).vector(), dtype=float)

    def silent(self, params: Any) -> SilentState:
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

    def linear_matrix(self, params: Any) -> tuple[np.ndarray, Any]:
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

    def linear_modes(self, params: Any) -> LinearModes | None:
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

    def contact_at(self, params: Any, y: Sequence[float], silent: SilentState | None = None,
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

    def vector_field(self, params: Any, silent: SilentState | None = None, engaged: Sequence[bool] | None = None
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
        from ._kernels import load_variational

        mod = self.__dict__.get("_variational")
        if mod is None:
            mod = load_variational(self.spec, self.use_cache)
            object.__setattr__(self, "_variational", mod)
        return mod

    def variational_theta(self, params: Any, dp: Sequence[float] | None = None,
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

    def rhs(self, params: Any, silent: SilentState | None = None) -> Callable[[float, np.ndarray], np.ndarray]:
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


def _own_linear_matrix(model: SimulationModel, params: Any, sm: Any) -> np.ndarray:
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


_MODELS: dict[tuple[str, bool], SimulationModel] = {}


def simulation_model(model: Any = "paper", *, use_cache: bool = True) -> SimulationModel:
    """The compiled simulation model of any model.

    Parameters
    ----------
    model : ModelSpec or str, optional
        The model, a built-in model's name or a model file (default the
        paper's model).
    use_cache : bool, optional
        Keep the generated kernel source in the package cache (see
        :mod:`brakesqueal.codegen.cache`), where numba also caches its
        machine code (default ``True``); ``False`` generates and compiles in
        memory and writes no file.

    Returns
    -------
    SimulationModel
        Memoized per process by the model's equations.
    """
    from ..codegen import build
    from ..codegen.compiled import model_key
    from ..model.parameters import as_model_spec as _model
    from ._kernels import load_kernels

    spec = _model(model)
    key = (model_key(spec), use_cache)
    sim = _MODELS.get(key)
    if sim is None:
        sim = SimulationModel(spec=spec, kernels=load_kernels(spec, use_cache), engine=build(spec, use_cache=use_cache),
                              use_cache=use_cache)
        _MODELS[key] = sim
    elif sim.spec is not spec:
        sim = SimulationModel(spec=spec, kernels=sim.kernels, engine=sim.engine.with_spec(spec), use_cache=use_cache)
    return sim


def default_model(use_cache: bool = True) -> SimulationModel:
    """The paper's general 2-DOF model (eq. 44 with quasi-static pads): ``simulation_model("paper")``.

    Parameters
    ----------
    use_cache : bool, optional
        See :func:`simulation_model`.

    Returns
    -------
    SimulationModel
    """
    return simulation_model("paper", use_cache=use_cache)


def _value(params: Any, v: Any) -> float:
    return float(params[v]) if isinstance(v, str) else float(v)


def _scales(model: SimulationModel, params: Any) -> np.ndarray:
    """Scale of every coordinate and pad state ``(Q, L_dynamic)``: 1 rad for a tilt, the largest pad radius [m]
    for a length."""
    length = max(abs(_value(params, p.radius)) for p in model.spec.pads) or 1.0
    q = [1.0 if c in ("q1", "q2") and model.tilting else length for c in model.coords]
    return np.array(q + [length] * len(model.dynamic))


def _default_atol(model: SimulationModel, params: Any, rtol: float, modes: LinearModes | None) -> np.ndarray:
    """``1e-6 rtol`` times the scale of every component (:func:`_scales`), the rates' scale times
    ``w = sqrt(k_t/Theta)`` (a non-tilting disk: the largest ``|lambda|``)."""
    spec = model.spec
    if model.tilting:
        w = math.sqrt(max(_value(params, spec.disk.k_t), 1.0) / _value(params, spec.disk.Theta))
    else:
        w = float(np.abs(modes.eigenvalues).max()) if modes is not None else 1.0
        w = w if math.isfinite(w) and w > 0 else 1.0
    s = _scales(model, params)
    n = model.n
    return rtol * 1e-6 * np.concatenate([s[:n], s[:n] * w, s[n:]])


def _check_tolerances(rtol: float, atol: Any, default: np.ndarray) -> np.ndarray:
    if not (isinstance(rtol, (int, float)) and math.isfinite(rtol) and 1e-13 <= rtol <= 1e-2):
        raise ParameterError(f"The option 'rtol' must be in [1e-13, 1e-2]; got {rtol!r}", parameter="rtol")
    if atol is None:
        return default
    try:
        a = np.broadcast_to(np.asarray(atol, dtype=float), default.shape).copy()
    except (ValueError, TypeError):
        raise ParameterError(f"The option 'atol' must be one value or {default.size}; got {atol!r}",
                             parameter="atol") from None
    if not np.all(np.isfinite(a)) or np.any(a <= 0) or np.any(a > 1.0):
        raise ParameterError(f"The option 'atol' must be in (0, 1] (one value or {default.size}); got {atol!r}",
                             parameter="atol")
    return a


def _start_vector(model: SimulationModel, modes: LinearModes, scales: np.ndarray) -> np.ndarray:
    """``Re(v_0)`` scaled so that its largest coordinate or pad state relative to its scale is ``START_AMPLITUDE``."""
    v = np.real(modes.right[:, 0])
    n = model.n
    ref = np.concatenate([v[:n], v[2 * n:]]) / scales
    s = float(np.abs(ref).max())
    return START_AMPLITUDE * v / (s if s > 0 else 1.0)


def _pads_at_rest(model: SimulationModel, params: Any, p: np.ndarray, y0: np.ndarray, st: SilentState) -> str:
    """Start every damped pad (a :attr:`~SimulationModel.dynamic` pad with ``d_ip > 0``) at rest on its support.

    When the initial state leaves the pad states out, the damped pads' deformations ``l`` are set (in ``y0``,
    in place) to the root of their balance with ``ldot = 0``: the spring carries the friction at the initial
    tilt.  Kept at the silent motion's value instead, a tilted start would put the whole change of the friction
    force on the damper (``ldot ~ dF / d_ip``, often faster than the sliding speed: a spurious reversal).
    Returns a note for the trajectory's ``start`` ("" when no pad is changed).
    """
    undamped = set(model.undamped(params))
    dyn = [j for j, k in enumerate(model.pad_kinds) if k == "dynamic"]
    damped = [(i, j) for i, j in enumerate(dyn) if model.pad_unknowns[j] not in undamped]
    if not damped:
        return ""
    n, m = model.n, len(model.pad_kinds)
    l, dl, g = st.l.copy(), np.zeros(m), np.empty(2 * m + 1)
    for i, j in damped:
        l[j] = y0[2 * n + i]
    for _ in range(60):  # G is l + O(c_ip) in l (eqs. 33-34): a secant-free fixed point converges at once
        model.kernels.pad_balance(y0, l, dl, p, g)
        step = max(abs(float(g[j])) for _i, j in damped)
        for i, j in damped:
            l[j] -= g[j]
        if not step > 1e-15 * (1.0 + max(abs(float(l[j])) for _i, j in damped)):
            break
    if not all(math.isfinite(float(l[j])) for _i, j in damped):
        return ""
    for i, j in damped:
        y0[2 * n + i] = l[j]
    return "; damped pads at rest on their supports (ldot = 0)"


def _initial_state(model: SimulationModel, x0: Any, perturbation: Any, y_s: np.ndarray,
                   modes: LinearModes | None, scales: np.ndarray) -> tuple[np.ndarray, str]:
    """Initial state and a description of it (``start`` of the trajectory)."""
    n, N = model.n, y_s.size
    names = model.state_names
    if x0 is not None and perturbation is not None:
        raise ParameterError("give either x0 (absolute initial state) or perturbation, not both")
    if x0 is not None:
        v = np.asarray(x0, dtype=float).ravel()
        if v.size not in (2 * n, N):
            sizes = f"{2 * n}" + (f" or {N}" if N > 2 * n else "")
            raise ParameterError(f"The initial state x0 must have {sizes} values ({', '.join(names[:2 * n])}"
                                 f"{', ' + ', '.join(names[2 * n:]) if N > 2 * n else ''}); got {v.size}")
        y0, start = np.concatenate([v, y_s[v.size:]]), "x0 (absolute state)"
    elif perturbation is None and modes is not None:
        y0 = y_s + _start_vector(model, modes, scales)
        start = "leading mode, real part of its eigenvector, "
        if model.tilting and model.n == 2 and not model.dynamic:
            start += f"max tilt deviation {START_AMPLITUDE:g} rad"
        else:
            length = float(max(v for v, c in zip(scales, (*model.coords, *model.dynamic))
                               if c not in ("q1", "q2") or not model.tilting))
            start += (f"max deviation {START_AMPLITUDE:g} of a coordinate or pad state relative to its scale "
                      f"(tilts 1 rad, lengths {length:g} m)")
    else:
        if perturbation is None:
            d = np.zeros(n)
            d[0] = START_AMPLITUDE * scales[0]
        else:
            d = np.asarray(perturbation, dtype=float).ravel()
        if d.size not in (n, 2 * n, N):
            raise ParameterError(
                f"The perturbation must have {n} ({', '.join(names[:n])}) or {2 * n} values (with the rates "
                f"{', '.join(names[n:2 * n])}){f' or {N} (with the pad states)' if N > 2 * n else ''}; got {d.size}")
        y0 = y_s + np.concatenate([d, np.zeros(N - d.size)])
        start = "perturbation of the silent motion"
    if not np.all(np.isfinite(y0)):
        raise ParameterError(f"The initial state must be finite; got {y0.tolist()}")
    if model.tilting and np.any(np.abs(y0[:2]) >= 0.5 * math.pi):
        raise ParameterError(f"The initial tilt angles must be in (-pi/2, pi/2); got {y0[:2].tolist()}")
    return y0, start


def estimation_rate(modes: LinearModes | None, duration: float) -> float:
    """Sampling rate [Hz] of the estimation record: ``POINTS_PER_PERIOD`` per period of the fastest mode.

    The "frequency" of a mode is ``|lambda| / 2 pi`` (so that a real, fast
    eigenvalue is resolved too); at least 64 samples cover ``duration``.

    Parameters
    ----------
    modes : LinearModes or None
        Linear modes of the silent motion; without them the rate is 64
        samples over the run.
    duration : float
        Duration of the run [s].

    Returns
    -------
    float
        The rate [Hz].
    """
    fmax = float(np.abs(modes.eigenvalues).max()) / (2 * math.pi) if modes is not None else 0.0
    return max(POINTS_PER_PERIOD * fmax, 64.0 / duration)


def simulate(
    model: SimulationModel | Any | None,
    params: Any,
    t_span: float | Sequence[float] = 0.5,
    x0: Sequence[float] | np.ndarray | None = None,
    *,
    perturbation: Sequence[float] | np.ndarray | None = None,
    method: str = "DOP853-jit",
    rtol: float = 1e-9,
    atol: float | Sequence[float] | None = None,
    sample_rate: float = 44100.0,
    events: EventMode = "stop",
    max_step: float = math.inf,
    max_steps: int = 50_000_000,
    progress: Callable[[float], None] | None = None,
    estimate_samples: int = 65536,
    contact: ContactLaw = "bilateral",
) -> Trajectory:
    r"""Integrate the nonlinear equations of any model (eq. 44 generalized) from a perturbed silent motion.

    Parameters
    ----------
    model : SimulationModel, ModelSpec, str or None
        The model; ``None`` is the model of ``params`` (:func:`simulation_model`).
    params : Parameters
        Parameter values (of the model; the paper's 17-parameter sets are accepted for the paper's model).
    t_span : float or (float, float)
        End time ``t_end`` [s] (start 0) or ``(t0, t_end)``; ``t_end > t0``.
    x0 : array_like, shape (2n,) or (2n + k,), optional
        Absolute initial state ``(Q, Qdot[, L_dynamic])`` (the paper's model:
        ``(q1, q2, dq1, dq2)`` [rad, rad/s]).
    perturbation : array_like, shape (n,), (2n,) or (2n + k,), optional
        Initial deviation from the silent motion (rates zero if ``n`` values).
        Default when neither is given: along the leading mode of the
        linearization, ``x(0) = Re(v_0)`` with ``v_0`` its right eigenvector
        scaled so that its largest coordinate or pad state, in units of 1 rad
        for a tilt and of the largest pad radius for a length, is
        ``START_AMPLITUDE = 1e-5`` (the paper's model: the largest tilt
        deviation is 1e-5 rad).
    method : str
        ``"DOP853-jit"`` (compiled Dormand–Prince 8(5,3), default) or one of
        SciPy's ``solve_ivp`` methods ``"DOP853", "RK45", "RK23", "Radau",
        "BDF", "LSODA"`` (the same compiled right-hand side, called from Python; slower).
    rtol : float
        Relative tolerance, in ``[1e-13, 1e-2]``.
    atol : float or array_like (2n + k,), optional
        Absolute tolerance(s) in ``(0, 1]``; default ``1e-6 rtol`` times 1 for
        tilts [rad], the largest pad radius for lengths [m], and those times
        ``w = sqrt(k_t/Theta)`` for the rates (a non-tilting disk: the
        largest ``|lambda|``).
    sample_rate : float
        Output samples per second [Hz] (uniform grid, dense output) of
        :attr:`Trajectory.t` / :attr:`Trajectory.y` (NetCDF, WAV, plot).  The
        summary numbers do not use this grid but the estimation record
        (``estimate_samples``).
    events : {"stop", "continue", "off"}
        ``"stop"`` ends the run at the first contact loss (``F_n <= 0``) or
        sliding reversal (``v_r . v_r0 <= 0``, ``v_r0`` the silent-motion
        sliding velocity of that pad) of any pad; ``"continue"`` records the
        event times (``contact-loss-pad-<name>``, ``sliding-reversal-pad-<name>``)
        and integrates on with the same equations (bilateral contact, friction
        direction ``v_r/|v_r|``); ``"off"`` ignores them.  When every pad has
        regularised stick-slip (law ``stick``,
        :func:`~brakesqueal.model.options.regularised_pads` with ``stick_speed``)
        a sliding reversal is ordinary motion: ``"stop"`` stops at a contact
        loss only and records the reversals in :attr:`Trajectory.event_times`.
    max_step : float
        Largest step [s].
    max_steps : int
        Step budget (compiled method); exceeding it ends the run with status ``"failed"``.
    progress : callable, optional
        Called with the fraction done (0..1) while integrating (about every 0.1 s of wall time).
    estimate_samples : int
        Length of the estimation record (default 65536): the integrator's
        dense output at ``POINTS_PER_PERIOD = 20`` samples per period of the
        fastest linear mode (:func:`estimation_rate`), of which the last
        ``estimate_samples`` are kept (a ring buffer).  :attr:`Trajectory.summary`
        is computed from it.
    contact : {"bilateral", "unilateral"}
        ``"bilateral"`` (default): the equations hold with any sign of ``F_n``
        (``events`` decides what happens at a contact loss).
        ``"unilateral"``: the normal force of every pad is ``max(0, F_n)``
        (``docs/simulation.md``, unilateral contact): at ``F_n = 0`` the pad
        lifts off (its contact force and friction vanish, the run goes on), and it
        comes back when its ``F_n`` (the force the support would exert at
        the disk's surface) turns positive again; lift-offs and re-contacts
        are recorded in :attr:`Trajectory.event_times`
        (``contact-loss-pad-<name>``, ``re-contact-pad-<name>``) and the
        contact state per sample in :attr:`Trajectory.engaged`.  Needs
        ``method="DOP853-jit"`` and events ``"stop"`` (the run stops at a
        sliding reversal, where Coulomb friction would stick) or
        ``"continue"`` (sliding reversals recorded, the friction direction
        follows ``v_r/|v_r|``).  Not available for pads with rate-dependent
        friction (their tangential deformation is a state): ``ldot`` enters
        the pad's balance ``G(Q, Qdot, l, ldot) = 0`` through the friction
        force and ``F_n``, so ``dG/dldot`` shrinks with ``F_n`` (at ``F_n = 0``
        only the support damper's share is left) and can change sign while
        the pad is still pressed: the pad mode ``-G_l / G_ldot`` diverges
        before lift-off (``docs/simulation.md``, unilateral contact).

    Returns
    -------
    Trajectory
        Status, message, samples and summary numbers; the partial trajectory
        is kept when the run stops early.

    Raises
    ------
    ParameterError
        Bad options or initial state (non-finite, ``t_end <= t0``, tolerances
        out of range, a pad out of contact at the initial state).
    SilentMotionError
        If the silent motion does not exist (needed for the reference state).
    KeyboardInterrupt
        On Ctrl-C: the compiled integrator runs in calls of about 0.1 s, and
        the interrupt takes effect between them (nothing is returned).

    Notes
    -----
    Massless pads with coulomb friction are quasi-static (``ldot := 0``,
    ``l`` from ``G(Q, Qdot, l, 0) = 0``); with rate-dependent friction their
    deformation is a state and ``ldot`` solves ``G(Q, Qdot, l, ldot) = 0``
    (``docs/simulation.md``).
    """
    if method not in METHODS:
        raise ParameterError(f"The option 'method' must be one of {', '.join(METHODS)}; got {method!r}",
                             parameter="method")
    if events not in ("stop", "continue", "off"):
        raise ParameterError(f"The option 'events' must be one of stop, continue, off; got {events!r}",
                             parameter="events")
    if contact not in ("bilateral", "unilateral"):
        raise ParameterError(f"The option 'contact' must be bilateral or unilateral; got {contact!r}",
                             parameter="contact")
    if contact == "unilateral" and (method != "DOP853-jit" or events == "off"):
        raise ParameterError("contact='unilateral' needs method='DOP853-jit' and events 'stop' or 'continue'; got "
                             f"method={method!r}, events={events!r}")
    if np.ndim(t_span) == 0:
        t0, t1 = 0.0, float(t_span)  # type: ignore[arg-type]
    else:
        t0, t1 = (float(v) for v in t_span)  # type: ignore[union-attr]
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise ParameterError(f"The end time must be finite and greater than the start time {t0:g} s; got {t1!r}",
                             parameter="t_end")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise ParameterError(f"The option 'sample_rate' must be a positive number; got {sample_rate!r}",
                             parameter="sample_rate")
    samples = (t1 - t0) * sample_rate  # a float: no overflow converting an enormous count to int
    if not samples < MAX_OUTPUT_SAMPLES:
        raise ParameterError(f"The options 'sample_rate' and 't_end' ask for {samples:.3g} output samples "
                             f"(sample_rate x duration); at most {MAX_OUTPUT_SAMPLES:.0e} are allowed: lower "
                             "'sample_rate' or 't_end'", parameter="sample_rate", names=("t_end",))
    n_out = int(math.floor(samples + 1e-9)) + 1
    if not (max_step > 0):
        raise ParameterError(f"The option 'max_step' must be positive; got {max_step!r}")
    if not (isinstance(estimate_samples, (int, np.integer)) and 64 <= estimate_samples <= 50_000_000):
        raise ParameterError(f"The option 'estimate_samples' must be an integer in [64, 5e7]; got {estimate_samples!r}")
    from ..analysis.equilibrium import as_parameters
    from ._interrupt import interrupt_guard

    with interrupt_guard():
        return _simulate(model, as_parameters(params), t0, t1, x0, perturbation, method, rtol, atol, sample_rate,
                         events, max_step, max_steps, progress, estimate_samples, n_out, contact)


def _simulate(model, params, t0, t1, x0, perturbation, method, rtol, atol, sample_rate, events, max_step,
              max_steps, progress, estimate_samples, n_out, contact="bilateral"):  # type: ignore[no-untyped-def]
    from ._interrupt import check_interrupt

    if not isinstance(model, SimulationModel):
        model = simulation_model(params.model if model is None else model)
    check_interrupt()
    params = model.parameters(params)
    p = model.parameter_vector(params)
    unilateral = contact == "unilateral"
    if unilateral and (undamped := model.undamped(params)):
        raise ParameterError(f"contact='unilateral' needs a tangential damper d_ip > 0 on every pad whose rate is a "
                             f"state ({', '.join(undamped)}, rate-dependent friction): without one its rate ldot "
                             "solves the friction balance G(Q, Qdot, l, ldot) = 0, whose slope dG/dldot shrinks "
                             "with F_n and can change sign before F_n = 0, so the pad mode diverges before the "
                             "pad lifts off (docs/simulation.md, unilateral contact); give the pads a d_ip, use "
                             "coulomb friction or contact='bilateral'")
    try:
        st = model.silent(params)
    except SilentMotionError as exc:
        raise type(exc)(f"cannot simulate: {exc}") from None
    modes = model.linear_modes(params)
    check_interrupt()
    y0, start = _initial_state(model, x0, perturbation, st.y, modes, _scales(model, params))
    given = np.asarray(x0 if x0 is not None else perturbation if perturbation is not None else [], dtype=float)
    if (x0 is not None or perturbation is not None) and given.size < y0.size:
        start += _pads_at_rest(model, params, p, y0, st)
    atol_v = _check_tolerances(rtol, atol, _default_atol(model, params, rtol, modes))
    k = model.kernels
    npad = len(model.pads)
    l0, dl0 = st.l.copy(), st.dl.copy()
    f0 = np.empty(y0.size)
    g, mw = np.empty(2 * l0.size + 1), np.empty(model.n * model.n + model.n)
    k.rhs(y0, l0, dl0, p, st.ztol, g, mw, f0)
    ev0 = np.empty(2 * npad)
    k.event_values(y0, l0, dl0, p, st.vr0, np.empty(7 * npad), ev0)
    if not np.all(np.isfinite(f0)) or not np.all(np.isfinite(ev0)):
        raise ParameterError(f"the equations cannot be evaluated at the initial state {y0.tolist()}")
    eng0 = (ev0[:npad] > 0).astype(np.int64) if unilateral else np.ones(npad, dtype=np.int64)
    for j, pad in enumerate(model.pads):
        if ev0[j] <= 0 and not unilateral:
            raise ParameterError(f"pad '{pad}' is out of contact at the initial state (F_n = {ev0[j]:.6g} N <= 0); "
                                 "use a smaller initial perturbation")
        if ev0[npad + j] <= 0 and events != "off" and eng0[j]:
            raise ParameterError(f"pad '{pad}' does not slide forward at the initial state; use a smaller "
                                 "perturbation")
    t_out = t0 + np.arange(n_out) / sample_rate
    est = _EstimationGrid(t0, 1.0 / estimation_rate(modes, t1 - t0), int(estimate_samples), y0.size)
    if unilateral and not eng0.all():
        D0 = np.empty(npad * model.n + 1)
        k.rhs_u(y0, l0, dl0, p, st.ztol, g, mw, eng0, D0, f0)
        k.event_values_u(y0, l0, dl0, p, st.vr0, np.empty(7 * npad), eng0, ev0)
    run = _Run(model, p, st, y0, l0, dl0, f0, ev0, t0, t1, rtol, atol_v, max_step, t_out, est, events, progress,
               eng0 if unilateral else None)
    wall = time.perf_counter()
    res = run.jit(max_steps) if method == "DOP853-jit" else run.scipy(method)
    wall = time.perf_counter() - wall
    check_interrupt()
    n = res["n"]
    Y = res["Y"][:n]
    m = st.l.size
    L, dL = np.full((n, m), np.nan), np.full((n, m), np.nan)
    C, E = np.full((n, 7 * npad), np.nan), np.full((n, 5), np.nan)
    lw, dlw = st.l.copy(), st.dl.copy()  # warm starts carried from block to block
    engaged = None
    if unilateral:
        engaged = engagement_at(t_out[:n], eng0.astype(bool), res.get("switch_times", [[] for _ in range(npad)]))
    ENG = (np.ones((n, npad), dtype=np.int64) if engaged is None else engaged.astype(np.int64))
    for a in range(0, n, _POST_BLOCK):  # blocks of bounded wall time: Ctrl-C acts between them
        b = min(a + _POST_BLOCK, n)
        k.post_process(Y[a:b], b - a, lw, dlw, p, st.ztol, ENG[a:b], L[a:b], dL[a:b], C[a:b], E[a:b])
        check_interrupt()
    if engaged is not None:
        C[:, 0::7] = np.where(engaged, C[:, 0::7], 0.0)  # the acting normal force max(0, F_n)
    message = res["message"]
    if res["status"] == RunStatus.FAILED and model.dynamic and n:
        Fn = C[:, 0::7]
        last = np.flatnonzero(np.all(np.isfinite(Fn), axis=1))
        if last.size and (ref := float(np.max(np.abs(Fn[0])))) > 0 and float(Fn[last[-1]].min()) < 0.2 * ref:
            message += (f"; a pad's normal force had fallen to {float(Fn[last[-1]].min()):.4g} N (from "
                        f"{ref:.4g} N): a pad with rate-dependent friction cannot reach contact loss when its rate "
                        "balance degenerates first (docs/simulation.md, unilateral contact)")
    return Trajectory(
        status=res["status"], message=message, t=t_out[:n], y=Y, l=L, contact=C.reshape(n, npad, 7),
        energy_terms=E, params=params, q0=np.asarray(st.silent.q0, dtype=float).copy(), method=method, rtol=rtol,
        atol=atol_v, t_span=(t0, t1), t_event=res.get("t_event"), y_event=res.get("y_event"),
        event_times=res.get("event_times", {}), stats={"nfev": res["nfev"], "wall_s": wall, **res.get("stats", {})},
        model=model.name, record=est.record(), modes=modes, sample_rate=float(sample_rate), y_start=y0.copy(),
        start=start, coords=model.coords, pads=model.pads, pad_unknowns=model.pad_unknowns, dynamic=model.dynamic,
        tilting=model.tilting, y_silent=st.y.copy(), l_rates=dL, event_pad=res.get("event_pad"),
        contact_law=contact, engaged=engaged, t_final=float(res["t_final"]),
    )  # fmt: skip


_NO_RATE = "rate (a zero friction slope dmu/dv and no tangential damper d_ip)"


def engagement_at(t: np.ndarray, engaged0: np.ndarray, switch_times: Sequence[Sequence[float]]) -> np.ndarray:
    """Contact state of every pad at the times ``t`` from its initial state and its switching times.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Times (increasing).
    engaged0 : ndarray of bool, shape (n_pads,)
        Whether each pad is pressed at the start.
    switch_times : sequence of sequences
        Per pad, its lift-off and re-contact times in increasing order.

    Returns
    -------
    ndarray of bool, shape (N, n_pads)
        A pad switched at time ``t_s`` has its new state from ``t > t_s`` on.
    """
    out = np.empty((t.size, engaged0.size), dtype=bool)
    for j in range(engaged0.size):
        flips = np.searchsorted(np.asarray(switch_times[j], dtype=float), t)  # switches at times < t
        out[:, j] = engaged0[j] ^ (flips % 2 == 1)
    return out


class _EstimationGrid:
    """The estimation record being filled: times ``t0 + i dt`` in a ring buffer of ``size`` rows."""

    def __init__(self, t0: float, dt: float, size: int, width: int) -> None:
        self.t0, self.dt = float(t0), float(dt)
        self.buf = np.full((size, width), np.nan)
        self.count = 0  # samples written so far (index of the next one)

    def put(self, Y: np.ndarray) -> None:
        """Append samples (rows of ``Y``, at the next grid times)."""
        size, k = self.buf.shape[0], Y.shape[0]
        idx = (self.count + np.arange(k)) % size
        if k > size:
            idx, Y = idx[-size:], Y[-size:]
        self.buf[idx] = Y
        self.count += k

    def times(self, a: float, b: float) -> tuple[int, np.ndarray]:
        """Index of the first grid time ``>= a`` and the grid times in ``[a, b]``."""
        i0 = max(int(math.ceil((a - self.t0) / self.dt)) - 1, 0)
        while self.t0 + i0 * self.dt < a:
            i0 += 1
        i1 = int(math.floor((b - self.t0) / self.dt)) + 1
        while self.t0 + i1 * self.dt > b:
            i1 -= 1
        i = np.arange(i0, i1 + 1)
        return i0, self.t0 + i * self.dt

    def record(self) -> EstimationRecord:
        """The last ``min(count, size)`` samples in time order."""
        size = self.buf.shape[0]
        m = min(self.count, size)
        i = np.arange(self.count - m, self.count)
        return EstimationRecord(t=self.t0 + i * self.dt, y=self.buf[i % size].copy(), rate=1.0 / self.dt,
                                complete=self.count <= size)  # fmt: skip


def _dop853_tables() -> tuple[np.ndarray, ...]:
    from scipy.integrate._ivp import dop853_coefficients as c

    A = np.ascontiguousarray(c.A, dtype=float)
    return A, np.asarray(c.B, float), np.asarray(c.C, float), np.asarray(c.E3, float), np.asarray(c.E5, float), \
        np.ascontiguousarray(c.D, dtype=float)  # fmt: skip


class _Run:
    """One integration: the compiled DOP853 in calls of bounded wall time, or SciPy's ``solve_ivp``."""

    def __init__(self, model, p, st, y0, l0, dl0, f0, ev0, t0, t1, rtol, atol, max_step, t_out, est, events,
                 progress, engaged=None):  # type: ignore[no-untyped-def]
        self.model, self.p, self.st = model, p, st
        self.y0, self.l0, self.dl0, self.f0, self.ev0 = y0, l0, dl0, f0, ev0
        self.t0, self.t1, self.rtol, self.atol, self.max_step = t0, t1, rtol, atol, max_step
        self.t_out, self.est, self.events, self.progress = t_out, est, events, progress
        self.npad = len(model.pads)
        self.engaged = engaged
        #: every pad has regularised stick-slip (law ``stick``): ``events="stop"`` stops at contact loss only
        self.stick = stick_slip_everywhere(model.spec)

    def _event_name(self, k: int) -> tuple[str, str]:
        pad = self.model.pads[k % self.npad]
        return (("contact-loss", "sliding-reversal", "re-contact")[k // self.npad]), pad

    def _status(self, code: int, t: float, k_event: int, t_event: float | None) -> tuple[RunStatus, str]:
        if code == 0:
            return RunStatus.FINISHED, "reached the end time"
        if code == 1:
            kind, pad = self._event_name(k_event)
            if kind == "contact-loss":
                return RunStatus.CONTACT_LOSS, f"pad '{pad}' lost contact (F_n <= 0) at t = {t_event:.6g} s"
            return (RunStatus.SLIDING_REVERSAL,
                    f"sliding at pad '{pad}' reversed (v_r . v_r0 <= 0) at t = {t_event:.6g} s")
        reason = {
            -1: "step size became too small",
            -2: "the state became non-finite or the pad equations G = 0 could not be solved",
            -3: "the step budget max_steps was exhausted",
            -4: "a pad's contact switched twice within 10 minimal steps (chattering contact, e.g. a pad pressed "
                "with zero force while the disk moves along its surface)",
            -5: "an expression of the equations divided by zero (e.g. a pad's friction direction v_r/|v_r| at "
                "exactly zero sliding speed; regularised stick-slip, law 'stick', is defined there)",
        }.get(code, f"integrator error {code}")
        return RunStatus.FAILED, f"integration failed at t = {t:.6g} s: {reason}"

    def jit(self, max_steps: int) -> dict[str, Any]:
        from ._interrupt import check_interrupt

        k, est, st = self.model.kernels, self.est, self.st
        tables = _dop853_tables()
        N = self.y0.size
        Y = np.full((self.t_out.size, N), np.nan)
        mode = {"off": 0, "stop": 1, "continue": 2}[self.events]
        if mode == 1 and self.stick:
            mode = 5  # a sliding reversal is ordinary motion: recorded; a contact loss stops
        eng = np.ones(self.npad, dtype=np.int64)
        if self.engaged is not None:
            mode = 4 if self.events == "stop" else 3
            eng = self.engaged.copy()
        ev_t = np.zeros(10000)
        ev_k = np.zeros(10000, dtype=np.int64)
        drained_t: list[np.ndarray] = []
        drained_k: list[np.ndarray] = []
        y, f, l, dl, ev_old = self.y0.copy(), self.f0.copy(), self.l0.copy(), self.dl0.copy(), self.ev0.copy()
        ev_prev = np.full(ev_old.size, np.inf)
        stats = np.zeros(3, dtype=np.int64)
        y_event = np.full(N, np.nan)
        h = min(1e-7, (self.t1 - self.t0) / 10)
        t, i_out, i_est, n_ev = self.t0, 0, 0, 0
        status, k_event, t_event = 0, -1, math.nan
        budget = 256
        while True:
            chunk = min(budget, max_steps - int(stats[1]))
            if chunk <= 0:
                status = -3
                break
            w0 = time.perf_counter()
            try:
                status, t, h, i_out, i_est, n_ev, k_event, t_event = k.dop853(
                    y, f, l, dl, ev_old, ev_prev, self.p, st.ztol, st.vr0, t, self.t1, h, self.rtol, self.atol,
                    self.max_step, self.t_out, i_out, Y, est.t0, est.dt, i_est, est.buf, mode, ev_t, ev_k, n_ev, chunk,
                    stats, y_event, eng, *tables)  # fmt: skip
            except ZeroDivisionError:  # numba raises for 0.0 ** -1 under any error model
                status = -5
                break
            if mode in (3, 4):  # unilateral: every switch is kept (the buffer is drained after each call)
                drained_t.append(ev_t[:n_ev].copy())
                drained_k.append(ev_k[:n_ev].copy())
                n_ev = 0
            dt = time.perf_counter() - w0
            check_interrupt()
            est.count = int(i_est)
            if self.progress is not None:
                self.progress((t - self.t0) / (self.t1 - self.t0))
            if status != 2:
                break
            budget = int(min(max(budget * CHUNK_SECONDS / max(dt, 1e-4), 16), 10_000_000))
        if mode in (3, 4):
            ev_t = np.concatenate(drained_t) if drained_t else np.zeros(0)
            ev_k = np.concatenate(drained_k) if drained_k else np.zeros(0, dtype=np.int64)
            n_ev = ev_t.size
        recorded: dict[str, list[float]] = {}
        switches: list[list[float]] = [[] for _ in range(self.npad)]
        for i in range(min(n_ev, ev_t.size)):
            kind, pad = self._event_name(int(ev_k[i]))
            recorded.setdefault(f"{kind}-pad-{pad}", []).append(float(ev_t[i]))
            if mode in (3, 4) and kind != "sliding-reversal":
                switches[int(ev_k[i]) % self.npad].append(float(ev_t[i]))
        te = float(t_event) if status == 1 else None
        st_, msg = self._status(status, t, k_event, te)
        t_final = te if te is not None else (self.t1 if status == 0 else float(t))
        return {"status": st_, "message": msg, "Y": Y, "n": i_out, "nfev": int(stats[0]), "t_event": te,
                "t_final": t_final,
                "y_event": y_event.copy() if status == 1 else None, "event_times": recorded,
                "event_pad": self._event_name(k_event)[1] if status == 1 else None, "switch_times": switches,
                "stats": {"steps": int(stats[1]), "rejected": int(stats[2])}}  # fmt: skip

    def scipy(self, method: str) -> dict[str, Any]:
        """``solve_ivp`` in chunks no longer than the estimation ring buffer (bounded memory)."""
        from scipy.integrate import solve_ivp

        from ._interrupt import check_interrupt

        k, st, est, p = self.model.kernels, self.st, self.est, self.p
        t0, t1, progress = self.t0, self.t1, self.progress
        N, npad = self.y0.size, self.npad
        lbuf, dlbuf = self.l0.copy(), self.dl0.copy()
        g, mw = np.empty(2 * lbuf.size + 1), np.empty(self.model.n ** 2 + self.model.n)
        calls = [0]

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            out = np.empty(N)
            k.rhs(np.ascontiguousarray(y, dtype=float), lbuf, dlbuf, p, st.ztol, g, mw, out)
            check_interrupt()
            calls[0] += 1
            if progress is not None and calls[0] % 2000 == 0:
                progress((t - t0) / (t1 - t0))
            return out

        evfuns = []
        names = [self._event_name(i) for i in range(2 * npad)]
        if self.events != "off":
            lev, dlev = self.l0.copy(), self.dl0.copy()
            vals, cb, gev = np.empty(2 * npad), np.empty(7 * npad), np.empty(2 * lbuf.size + 1)

            def make(i: int) -> Callable[[float, np.ndarray], float]:
                def ev(t: float, y: np.ndarray) -> float:
                    yy = np.ascontiguousarray(y, dtype=float)
                    # the same start every call: an event function must be a function of y alone (SciPy's root
                    # finder re-evaluates the step's ends; a warm start from the last call can change the sign)
                    lev[:], dlev[:] = self.l0, self.dl0
                    k.solve_pads(yy, lev, dlev, p, st.ztol, gev)
                    k.event_values(yy, lev, dlev, p, st.vr0, cb, vals)
                    return float(vals[i])

                # with regularised stick-slip a sliding reversal (i >= npad) is recorded, not terminal
                ev.terminal = self.events == "stop" and not (self.stick and i >= npad)  # type: ignore[attr-defined]
                ev.direction = -1  # type: ignore[attr-defined]
                return ev

            evfuns = [make(i) for i in range(2 * npad)]
        t_out = self.t_out
        Y = np.full((t_out.size, N), np.nan)
        n = 0
        nfev = 0
        t_event, y_event, k_event = None, None, -1
        recorded: dict[str, list[float]] = {}
        chunk = est.buf.shape[0] * est.dt
        a, y = t0, np.asarray(self.y0, dtype=float)
        code, t_end, sol_msg = 0, t0, ""
        first = True
        while True:
            b = min(a + chunk, t1)
            if t1 - b < 1e-9 * chunk:
                b = t1
            lo = "left" if first else "right"
            i0, i1 = np.searchsorted(t_out, a, side=lo), np.searchsorted(t_out, b, side="right")
            _, te = est.times(a, b)
            if not first:
                te = te[te > a]
            ts, inv = np.unique(np.concatenate([t_out[i0:i1], te, [b]]), return_inverse=True)
            try:
                sol = solve_ivp(fun, (a, b), y, method=method, t_eval=ts, rtol=self.rtol, atol=self.atol,
                                max_step=self.max_step, events=evfuns or None)  # fmt: skip
            except ZeroDivisionError:  # numba raises for 0.0 ** -1 under any error model
                code, t_end, sol_msg = -5, a, ""
                break
            nfev += int(sol.nfev)
            got = sol.t.size
            Yc = np.ascontiguousarray(sol.y.T)
            io, ie = inv[: i1 - i0], inv[i1 - i0 : i1 - i0 + te.size]
            ok_o, ok_e = io < got, ie < got
            Y[i0 : i0 + int(ok_o.sum())] = Yc[io[ok_o]]
            n = i0 + int(ok_o.sum())
            est.put(Yc[ie[ok_e]])
            if evfuns:
                for i, tev in enumerate(sol.t_events):
                    if tev.size:
                        kind, pad = names[i]
                        recorded.setdefault(f"{kind}-pad-{pad}", []).extend(float(v) for v in tev)
                        if sol.status == 1 and (t_event is None or tev[0] < t_event):
                            t_event, y_event, k_event = float(tev[0]), np.asarray(sol.y_events[i][0]), i
            code = {0: 0, 1: 1, -1: -2}[sol.status]
            t_end = float(sol.t[-1]) if got else a
            sol_msg = sol.message
            if code != 0 or b >= t1:
                break
            a, y, first = b, Yc[inv[-1]].copy(), False  # ts ends at b: the state to continue from
        if progress is not None:
            progress(1.0)
        st_, msg = self._status(code, t_end, k_event, t_event)
        if code == -2:
            msg = f"solve_ivp ({method}) failed: {sol_msg}"
        t_final = t_event if code == 1 and t_event is not None else (t1 if code == 0 else t_end)
        return {"status": st_, "message": msg, "Y": Y, "n": n, "nfev": nfev, "t_event": t_event, "t_final": t_final,
                "y_event": y_event,
                "event_times": recorded if self.events == "continue" else (
                    {k_: v for k_, v in recorded.items() if k_.startswith("sliding-reversal")} if self.stick else {}),
                "event_pad": names[k_event][1] if code == 1 else None}  # fmt: skip
