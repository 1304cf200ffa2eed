r"""A compiled flow: numba DOP853 with variational equations, for systems given as numba kernels.

The vector field is given as three numba functions with fixed signatures
(compile them with ``numba.njit(F_SIGNATURE)`` / ``numba.njit(JAC_SIGNATURE)``):

* ``f(x, p, theta, out)``: ``out[:] = f(x, p)``;
* ``jac(x, p, theta, out)``: ``out[:, :] = f_x(x, p)`` (C-contiguous ``(n, n)``);
* ``dfdp(x, p, theta, out)``: ``out[:] = f_p(x, p)``;

``p`` is the continuation parameter and ``theta`` a fixed float64 vector of the other model
parameters (e.g. the vector the simulation kernels take), given once to :func:`compiled_system`.

The integrator kernel (:func:`brakesqueal.codegen.simulation.flow_kernel`: the
one DOP853 step of the package, SciPy's coefficients, error norm and
step-size control, shared with the simulation) takes them as first-class
functions, so it is compiled once per machine and cached by numba; each
system only compiles its own three small functions.  :func:`compiled_system` wraps the
kernels into a :class:`~.system.SmoothSystem` (Python callables, used by
:func:`~.hopf.first_lyapunov`), and :class:`CompiledFlow` implements the
:class:`~.flow.Flow` protocol for shooting and continuation.  Switching
events are not supported here: use :class:`~.flow.ScipyFlow` for a
:class:`~.system.PiecewiseSystem`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from numba import types

from ..errors import ParameterError
from .flow import FlowError, FlowResult, _check_duration, _check_rtol, _flow_atol, _flow_start
from .system import SmoothSystem

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["CompiledFlow", "compiled_system", "model_flow", "F_SIGNATURE", "JAC_SIGNATURE"]

#: ``f(x, p, theta, out)`` and ``dfdp(x, p, theta, out)``: ``x``, ``theta`` (fixed model parameters) and
#: ``out`` C-contiguous float64 vectors, ``p`` the continuation parameter.
F_SIGNATURE = types.void(types.float64[::1], types.float64, types.float64[::1], types.float64[::1])
#: ``jac(x, p, theta, out)`` with ``out`` a C-contiguous float64 ``(n, n)`` matrix.
JAC_SIGNATURE = types.void(types.float64[::1], types.float64, types.float64[::1], types.float64[:, ::1])


def compiled_system(f: Any, jac: Any, dfdp: Any, n: int, theta: Any = (), **kwargs: Any) -> SmoothSystem:
    """A :class:`~.system.SmoothSystem` whose Python callables call numba kernels.

    Parameters
    ----------
    f, jac, dfdp : numba dispatchers
        Kernels with the signatures of the module docstring.
    n : int
        State dimension.
    theta : array_like
        Fixed model parameters passed to every kernel call (default: empty).
    **kwargs
        Further :class:`~.system.SmoothSystem` fields (``B``, ``C``,
        ``jac_p``, ``state_names``, ``parameter_name``, ...).

    Returns
    -------
    SmoothSystem
        With ``f``, ``jac`` and ``dfdp`` evaluating the kernels.
    """
    th = np.ascontiguousarray(np.asarray(theta, dtype=float).ravel())

    def f_py(x: np.ndarray, p: float) -> np.ndarray:
        out = np.empty(n)
        f(np.ascontiguousarray(x, dtype=float), float(p), th, out)
        return out

    def jac_py(x: np.ndarray, p: float) -> np.ndarray:
        out = np.empty((n, n))
        jac(np.ascontiguousarray(x, dtype=float), float(p), th, out)
        return out

    def dfdp_py(x: np.ndarray, p: float) -> np.ndarray:
        out = np.empty(n)
        dfdp(np.ascontiguousarray(x, dtype=float), float(p), th, out)
        return out

    system = SmoothSystem(f=f_py, jac=jac_py, n=n, dfdp=dfdp_py, **kwargs)
    object.__setattr__(system, "_kernels", (f, jac, dfdp))
    object.__setattr__(system, "_theta", th)
    return system


@dataclass
class CompiledFlow:
    """Flow with sensitivities by the compiled DOP853 kernel (see the module docstring).

    Parameters
    ----------
    system : SmoothSystem
        A system from :func:`compiled_system` (its kernels are used), or any
        SmoothSystem when ``kernels`` is given.
    kernels : tuple, optional
        ``(f, jac, dfdp)`` numba kernels (default: those of ``system``).
    theta : ndarray, optional
        Fixed model parameters for the kernels (default: those given to :func:`compiled_system`).
    rtol : float
        Relative tolerance, in ``[1e-13, 1e-3]`` (default ``1e-11``).
    atol : float or ndarray, optional
        Absolute tolerance of the state (default ``1e-3 rtol scale``).
    max_steps : int
        Maximum number of steps per call.
    theta_of : callable, optional
        ``theta_of(p) -> ndarray``: the kernels' ``theta`` at the parameter ``p`` (instead of the fixed
        ``theta``; e.g. :func:`model_flow`, where ``theta`` holds the whole parameter vector at ``p``).
    use_cache : bool
        Keep the integrator's machine code in the on-disk code cache.
    """

    system: SmoothSystem
    kernels: tuple[Any, Any, Any] | None = None
    theta: Any = None
    rtol: float = 1e-11
    atol: Any = None
    max_steps: int = 1_000_000
    theta_of: Callable[[float], np.ndarray] | None = None
    use_cache: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.system, SmoothSystem):
            raise ParameterError(
                f"CompiledFlow: 'system' must be a SmoothSystem (no events); got {type(self.system).__name__}"
            )
        if self.kernels is None:
            self.kernels = getattr(self.system, "_kernels", None)
        if self.kernels is None or len(self.kernels) != 3:
            raise ParameterError("CompiledFlow: give kernels=(f, jac, dfdp) or a system from compiled_system()")
        th = getattr(self.system, "_theta", np.empty(0)) if self.theta is None else self.theta
        self.theta = np.ascontiguousarray(np.asarray(th, dtype=float).ravel())
        _check_rtol(self.rtol)
        from ..codegen.simulation import flow_kernel

        self._kernel = flow_kernel(self.use_cache).dop853

    @property
    def method(self) -> str:
        """Integrator name (``"DOP853-jit"``)."""
        return "DOP853-jit"

    def __call__(self, x0: np.ndarray, T: float, p: float, *, sensitivities: bool = True, n_samples: int = 0,
                 scale: np.ndarray | None = None) -> FlowResult:  # fmt: skip
        """Integrate from ``x0`` over ``[0, T]`` (see :class:`~.flow.Flow`).

        Parameters
        ----------
        x0 : ndarray
            Initial state.
        T : float
            Duration (> 0).
        p : float
            Parameter.
        sensitivities : bool
            Also return the monodromy matrix and ``d phi / d p``.
        n_samples : int
            Number of uniform output samples over ``[0, T)``.
        scale : ndarray, optional
            Typical magnitude of each state component.

        Returns
        -------
        FlowResult
            End state and sensitivities.
        """
        n = self.system.n
        x0 = np.asarray(x0, dtype=float)
        _check_duration(T)
        y = _flow_start(x0, n, sensitivities)
        atol = _flow_atol(self.atol, self.rtol, n, x0, scale, sensitivities)
        ts = T * np.arange(n_samples) / n_samples if n_samples else np.empty(0)
        S = np.empty((n_samples, n))
        f, jac, dfdp = self.kernels  # type: ignore[misc]
        theta = self.theta if self.theta_of is None else self.theta_of(float(p))
        status, nfev, _h = self._kernel(f, jac, dfdp, y, float(p), theta, float(T), float(self.rtol), atol,
                                        bool(sensitivities), ts, S, 0.0, int(self.max_steps))  # fmt: skip
        if status != 0:
            what = {-1: "step size too small", -2: "too many steps", -3: "non-finite state"}.get(int(status), "failure")
            raise FlowError(f"compiled DOP853 failed ({what}) at p = {p:.12g}")
        x = y[:n].copy()
        Z = y[n:].reshape(n, n + 1) if sensitivities else None
        return FlowResult(
            x=x, f_end=self.system.rhs(x, p), monodromy=Z[:, :n].copy() if Z is not None else None,
            dp=Z[:, n].copy() if Z is not None else None, t_samples=ts if n_samples else None,
            x_samples=S if n_samples else None, events=[], modes=[], mode_end=0, nfev=int(nfev),
            monodromy_method="variational" if sensitivities else "none",
        )  # fmt: skip


def model_flow(engine: Engine, space: ParameterSpace, name: str, *, system: SmoothSystem | None = None,
               use_cache: bool = True, rtol: float = 1e-11) -> CompiledFlow:
    """The compiled flow of a brake model with its exact, generated Jacobian (variational equations in numba).

    The vector field, its Jacobian and its parameter derivative are the model's generated kernels
    (:meth:`SimulationModel.variational_kernels <brakesqueal.simulation.SimulationModel.variational_kernels>`):
    the same ``f`` and ``f_y`` as :func:`~.models.model_system` (whose Jacobian is the Python
    :func:`~brakesqueal.simulation.state_jacobian`), compiled, so shooting and continuation on a brake model
    integrate the monodromy matrix without calling Python.  ``f_p`` is exact too (the generated
    ``d(R, G)/dp`` times the derivative of the parameter vector along ``name``, which is a fourth-order
    central difference of ``space.resolve``: exact up to rounding for untied or linearly tied parameters).

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller).
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The continuation parameter (settable in ``space``).
    system : SmoothSystem, optional
        The system the flow belongs to (default :func:`~.models.model_system` ``(engine, space, name)``).
    use_cache : bool
        Use the on-disk code cache.
    rtol : float
        Relative tolerance of the integrator.

    Returns
    -------
    CompiledFlow
        Bilateral contact (every pad pressed); for unilateral contact use the piecewise system's ScipyFlow.
    """
    from ..simulation import simulation_model
    from .models import _recent, model_system

    if system is None:
        system = model_system(engine, space, name, use_cache=use_cache)
    sim = simulation_model(engine, use_cache=use_cache)
    mod = sim.variational_kernels()

    def theta_at(p: float) -> np.ndarray:
        params = space.resolve({name: p})
        h = 1e-3 * max(abs(p), 1e-300)
        v = [sim.parameter_vector(space.resolve({name: p + k * h})) for k in (-2, -1, 1, 2)]
        with np.errstate(invalid="ignore"):
            dp = (8 * (v[2] - v[1]) - (v[3] - v[0])) / (12 * h)
        same = (v[0] == v[1]) & (v[1] == v[2]) & (v[2] == v[3])
        dp = np.where(same, 0.0, dp)
        if not np.all(np.isfinite(dp)):
            raise ParameterError(f"the model parameters are not differentiable along {name!r} at {p:.12g}")
        return sim.variational_theta(params, dp)

    theta_of = _recent(theta_at, 16)

    return CompiledFlow(system, kernels=(mod.nl_f, mod.nl_jac, mod.nl_dfdp), theta=np.empty(0), rtol=rtol,
                        theta_of=theta_of, use_cache=use_cache)
