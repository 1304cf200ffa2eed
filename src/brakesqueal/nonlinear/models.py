r"""The brake models as systems of the nonlinear machinery: Hopf criticality at every stability crossing.

:func:`model_system` turns any model (the paper's, the built-in and TOML
models) and one settable parameter of a
:class:`~brakesqueal.model.parameters.ParameterSpace` into a
:class:`~.system.SmoothSystem`: the state is the integrator's
``y = (Q, Qdot, L_dynamic)`` in SI units
(:class:`~brakesqueal.simulation.SimulationModel`), ``f`` is the compiled
right-hand side of the simulation and ``A = f_y`` its exact Jacobian from the
generated derivatives of eq. (44) and the pads' balances (implicit
differentiation, :func:`~brakesqueal.simulation.state_jacobian`).  The second
and third derivatives ``B``, ``C`` of Kuznetsov's formula are central
differences of that exact Jacobian with error estimates
(:func:`~.system.fd_bilinear`, :func:`~.system.fd_trilinear`), so ``l1``
carries an error bar.

:func:`hopf_points` finds the stability crossings along a path
(:func:`~brakesqueal.analysis.crossings.crossings`, exact where the model
allows) and computes at each the first Lyapunov coefficient with MatCont's
conventions (:func:`~.hopf.first_lyapunov`): ``<q, q> = 1``, ``<p, q> = 1``,
``l1 = Re c1 / omega0``, and the normalisation-free prediction of every state
component's first-harmonic amplitude ``A_j ~ a_j sqrt(|p - p0|)``.

Pad treatment (stated in every result): massless pads with Coulomb friction
are quasi-static (``ldot := 0``) here as in the simulation; this is exact for
the linearization at the trivial silent motion but not beyond first order
(with a finite ``k_ip`` the pads' true tangential rate changes ``l1``).  Rigid
pads (``k_ip = inf``), pads with their own tangential DOF and pads with
rate-dependent friction have no such approximation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import BrakesquealError
from .hopf import HopfResult, first_lyapunov
from .system import SmoothSystem

__all__ = ["model_system", "hopf_points", "HopfPoint", "squeal_branch", "SquealBranch"]


def model_system(space: Any, name: str, *, use_cache: bool = True) -> SmoothSystem:
    """A model as a :class:`~.system.SmoothSystem` in the settable parameter ``name`` of ``space``.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides; tied names follow ``name``.
    name : str
        The continuation parameter (a settable name of ``space``, e.g. ``Omega`` or ``mu``).
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    SmoothSystem
        ``f(y, p)``, exact ``jac(y, p)``; state names ``Q``, ``dQ``, dynamic pads' ``L``.

    Raises
    ------
    ParameterError
        ``name`` is not settable in ``space``.
    """
    from ..simulation import simulation_model

    if name not in space.settable():
        space.resolve({name: 1.0})  # raises the one message for unknown or tied names
    params0 = space.resolve({})
    sim = simulation_model(params0.model, use_cache=use_cache)
    cache: dict[float, tuple[Any, Any]] = {}

    def fields(p: float) -> tuple[Any, Any]:
        key = float(p)
        if key not in cache:
            if len(cache) > 8:
                cache.clear()
            params = space.resolve({name: key})
            cache[key] = sim.vector_field(params)
        return cache[key]

    def f(x: np.ndarray, p: float) -> np.ndarray:
        return fields(p)[0](x)

    def jac(x: np.ndarray, p: float) -> np.ndarray:
        return fields(p)[1](x)

    system = SmoothSystem(f=f, jac=jac, n=len(sim.state_names), state_names=tuple(sim.state_names),
                          parameter_name=name)
    object.__setattr__(system, "simulation_model", sim)
    return system


@dataclass(frozen=True)
class HopfPoint:
    """A stability crossing of the silent motion with its Hopf normal-form data.

    Attributes
    ----------
    parameter : str
        The path parameter.
    value : float
        Where stability changes (refined Hopf point when ``hopf`` is given).
    direction : str
        ``"destabilizing"`` or ``"stabilizing"`` with increasing parameter.
    hopf : HopfResult or None
        The normal form (``None`` when it could not be computed; see ``message``).
    pad_treatment : dict
        Every pad deformation's treatment (``"quasi-static"`` or ``"dynamic"``).
    message : str
        Why ``hopf`` is missing, or a note on the pad treatment.
    """

    parameter: str
    value: float
    direction: str
    hopf: HopfResult | None
    pad_treatment: dict[str, str]
    message: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: l1 and its error, criticality, frequency, side and amplitude coefficients."""
        d: dict[str, Any] = {"value": self.value, "direction": self.direction, "pad_treatment": self.pad_treatment,
                             "message": self.message}
        h = self.hopf
        if h is None:
            d["hopf"] = None
            return d
        names = tuple(h.state_names or ())
        d["hopf"] = {
            "p0": h.p0, "omega0": h.omega0, "frequency_hz": h.frequency0_hz, "l1": h.l1,
            "l1_error": h.l1_error, "criticality": h.criticality, "c1": [h.c1.real, h.c1.imag],
            "dRe_lambda_dp": h.dRe_lambda_dp, "side": h.side,
            "cycles_exist_for": ("p > p0" if h.side > 0 else "p < p0") if h.side else None,
            "amplitude_coefficients": dict(zip(names, map(float, h.amplitude_coefficients))),
            "frequency_slope": h.frequency_slope, "multilinear": h.multilinear,
            "conventions": "state (Q, dQ/dt, L_dynamic) in SI units; <q,q> = 1, <p,q> = 1; l1 = Re(c1)/omega0 "
                           "(Kuznetsov; MatCont); A_j ~ a_j sqrt(|p - p0|)",
            "warnings": list(h.warnings),
        }
        return d


def hopf_points(space: Any, axis: Any, *, use_cache: bool = True, result: Any = None) -> list[HopfPoint]:
    """Every stability crossing along a path with its first Lyapunov coefficient and cycle prediction.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides (any model).
    axis : Axis
        The path (``name``, ``start``, ``stop``; ``log`` as for
        :func:`~brakesqueal.analysis.crossings.crossings`).
    use_cache : bool
        Use the on-disk code cache.
    result : CrossingResult, optional
        The crossings along ``axis`` when already computed (default: computed here).

    Returns
    -------
    list of HopfPoint
        In increasing parameter order; a crossing where the normal form cannot
        be computed (a real eigenvalue crossing, a failed refinement) has
        ``hopf = None`` and a message.
    """
    from ..analysis.crossings import crossings

    r = crossings(space, axis) if result is None else result
    system = model_system(space, axis.name, use_cache=use_cache)
    sim = system.simulation_model  # type: ignore[attr-defined]
    treatment = dict(zip(sim.pad_unknowns, sim.pad_kinds))
    note = ""
    params0 = space.resolve({})
    finite = [pad.k_ip for pad in params0.model.pads if pad.name in sim.unknown_pads]
    finite = [k for k in finite if not (isinstance(k, (int, float)) and math.isinf(k))
              and not (isinstance(k, str) and math.isinf(float(params0[k])))]
    if any(k == "quasi-static" for k in treatment.values()) and finite:
        note = ("massless Coulomb pads are quasi-static (ldot := 0): exact for the linearization, not beyond first "
                "order (l1 with a finite k_ip is approximate; give the pads a tangential DOF for their true dynamics)")
    out = []
    for value, direction in r.crossings:  # type: ignore[attr-defined]
        try:
            params = space.resolve({axis.name: float(value)})
            y0 = sim.silent(params).y
            h = first_lyapunov(system, y0, float(value), refine=True)
            out.append(HopfPoint(axis.name, float(h.p0), direction, h, treatment, note))
        except (BrakesquealError, np.linalg.LinAlgError) as exc:
            out.append(HopfPoint(axis.name, float(value), direction, None, treatment,
                                 f"no Hopf normal form: {exc}"))
    return out



@dataclass(frozen=True)
class SquealBranch:
    """The limit cycles born at a Hopf point of a brake model, with the pads' contact along them.

    Attributes
    ----------
    hopf : HopfPoint
        Where the branch starts.
    branch : CycleBranch
        The continued branch (:func:`~.continuation.continue_cycles`); its
        ``data`` gains ``F_n_min`` (dims ``point, pad``: the smallest normal
        force over one period [N]) and ``in_contact`` (every pad pressed over
        the whole period).
    contact_loss : float or None
        Parameter value where the first pad's normal force first reaches zero
        on the orbit (interpolated between branch points); beyond it the
        bilateral equations do not describe the brake (the pad lifts off).
    pads : tuple of str
        Pad names (the ``pad`` dimension).
    """

    hopf: HopfPoint
    branch: Any
    contact_loss: float | None
    pads: tuple[str, ...]

    @property
    def data(self) -> Any:
        """The branch's :class:`xarray.Dataset` (see :attr:`branch`)."""
        return self.branch.data

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: Hopf data, contact loss, amplitude and frequency there, folds, status."""
        ds = self.data
        p = ds["p"].values
        ok = ds["in_contact"].values
        last = int(np.flatnonzero(ok)[-1]) if ok.any() else 0
        coords = [str(c) for c in ds["coord"].values]
        return {
            "hopf": self.hopf.to_dict(), "points": int(p.size), "status": self.branch.status,
            "message": self.branch.message, "contact_loss": self.contact_loss,
            "in_contact_up_to": float(p[last]),
            "amplitude_at_last_contact_point": dict(zip(coords, map(float, ds["amplitude"].values[last]))),
            "frequency_hz_at_last_contact_point": float(ds["frequency"].values[last]),
            "special_points": [{"kind": str(k), "p": float(v)} for k, v in
                               zip(ds["special_kind"].values, ds["special_p"].values)],
            "hysteresis_range": ds.attrs.get("hysteresis_range"),
        }

    def plot(self, coord: str | int | None = None) -> Any:
        """Bifurcation diagram (:meth:`CycleBranch.plot`) with the contact loss marked."""
        fig = self.branch.plot(coord)
        if self.contact_loss is not None:
            for ax in fig.axes:
                ax.axvline(self.contact_loss, color="tab:red", ls=":", lw=1)
            fig.axes[0].annotate("contact loss", (self.contact_loss, 0.95), xycoords=("data", "axes fraction"),
                                 color="tab:red", fontsize="small", ha="left", va="top")
        return fig


def squeal_branch(space: Any, axis: Any, *, max_points: int = 60, use_cache: bool = True,
                  tol: float = 1e-8) -> SquealBranch:
    """Continue the limit cycles from the first Hopf point on a path and find where a pad loses contact.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path: the first Hopf point with a cycle prediction in
        ``(start, stop)`` is continued within that range.
    max_points : int
        Largest number of branch points.
    use_cache : bool
        Use the on-disk code cache.
    tol : float
        Newton tolerance of the shooting (scaled update).

    Returns
    -------
    SquealBranch

    Raises
    ------
    ParameterError
        No Hopf point with a cycle prediction on the path.
    """
    from ..errors import ParameterError
    from .continuation import continue_cycles

    pts = [hp for hp in hopf_points(space, axis, use_cache=use_cache) if hp.hopf is not None and hp.hopf.side]
    if not pts:
        raise ParameterError(f"no Hopf point with a limit-cycle prediction for {axis.name} in "
                             f"({axis.start:g}, {axis.stop:g}); see brakesqueal hopf")
    hp = pts[0]
    system = model_system(space, axis.name, use_cache=use_cache)
    sim = system.simulation_model  # type: ignore[attr-defined]
    br = continue_cycles(system, hp.hopf, (axis.start, axis.stop), max_points=max_points, tol=tol)
    ds = br.data
    p = ds["p"].values
    orbits = ds["orbit"].values
    fmin = np.full((p.size, len(sim.pads)), np.nan)
    for i in range(p.size):
        params = space.resolve({axis.name: float(p[i])})
        st = sim.silent(params)
        fmin[i] = np.min([sim.contact_at(params, y, st)[:, 0] for y in orbits[i]], axis=0)
    worst = fmin.min(axis=1)
    loss = None
    bad = np.flatnonzero(~(worst > 0))
    if bad.size and bad[0] > 0:
        i = int(bad[0])
        a, b = worst[i - 1], worst[i]
        loss = float(p[i - 1] + (p[i] - p[i - 1]) * a / (a - b)) if a != b else float(p[i])
    import xarray as xr

    ds["F_n_min"] = xr.DataArray(fmin, dims=("point", "pad"), coords={"pad": list(sim.pads)},
                                 attrs={"units": "N", "long_name": "smallest normal force over one period"})
    ds["in_contact"] = xr.DataArray(worst > 0, dims=("point",),
                                    attrs={"long_name": "every pad pressed over the whole period (bilateral "
                                                        "equations valid)"})
    ds.attrs["contact_loss"] = np.nan if loss is None else loss
    return SquealBranch(hp, br, loss, tuple(sim.pads))
