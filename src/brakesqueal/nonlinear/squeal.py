r"""Limit-cycle branches of the brake models by shooting, with the engineer's summary (:func:`squeal_branch`).

:func:`squeal_branch` continues the cycles from the first Hopf point on a path
(:func:`~.models.hopf_points`) with the compiled flow of the model's simulated
equations (:func:`~.models.model_system`; unilateral contact: the piecewise
system of :func:`~.models.model_piecewise_system`) and adds, per branch point,
the pads' normal forces over the period, their duty cycles and sliding
margins; the contact loss and the end of validity are located by the Illinois
method on the parameter.  :func:`squeal_summary` condenses a branch into a
:class:`SquealSummary`.  ``docs/nonlinear.md``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .models import HopfPoint, hopf_points, model_piecewise_system, model_system
from .system import PiecewiseSystem, SmoothSystem

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import Parameters, ParameterSpace
    from ..simulation import SimulationModel
    from .hopf import HopfResult

__all__ = ["squeal_branch", "SquealBranch", "SquealSummary", "squeal_summary", "predicted_contact_loss",
           "stiffness_ratio", "STIFF_RATIO", "FLOW_METHODS", "IMPLICIT_RTOL"]


def _periodic_min(values: np.ndarray) -> np.ndarray:
    """Smallest value over one period of uniform samples (axis 0), refined by a parabola through the
    smallest sample and its two periodic neighbours (error ~ (2 pi / N)^4 of the amplitude instead of
    (2 pi / N)^2 for the smallest sample)."""
    v = np.asarray(values, dtype=float)
    n = v.shape[0]
    k = np.argmin(v, axis=0)
    cols = np.arange(v.shape[1])
    y0, ym, yp = v[k, cols], v[(k - 1) % n, cols], v[(k + 1) % n, cols]
    curv = ym - 2 * y0 + yp
    with np.errstate(divide="ignore", invalid="ignore"):
        fine = y0 - (yp - ym) ** 2 / (8 * curv)
    return np.where(curv > 0, np.minimum(fine, y0), y0)


def _contact_indicators(sim: SimulationModel, params: Parameters, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pad, the smallest normal force [N] and the smallest sliding margin over one period of samples.

    The sliding margin is the sliding velocity's component along the silent motion's sliding velocity (it
    is negative where a pad's sliding reverses)."""
    st = sim.silent(params)
    cq = np.array([sim.contact_at(params, y, st) for y in samples])  # (phase, pad, 7)
    npad = cq.shape[1]
    slide = np.einsum("spk,pk->sp", cq[:, :, 1:4], st.vr0.reshape(npad, 3))
    return _periodic_min(cq[:, :, 0]), _periodic_min(slide)


def predicted_contact_loss(engine: Engine, space: ParameterSpace, name: str, hopf: HopfResult | None) -> float | None:
    r"""Where the Hopf point's small-amplitude prediction says a pad first loses contact.

    On the cycle $x = x_0 + 2 r\,\mathrm{Re}(q e^{i\theta}) + O(r^2)$ the smallest normal force falls
    linearly in $r \propto \sqrt{|p - p_0|}$, so $F_{\min} \approx F_0 - k\sqrt{|p - p_0|}$; $k$ is taken
    from :meth:`~.hopf.HopfResult.cycle_guess` at two tiny offsets (Richardson: the $O(r^2)$ terms cancel)
    and the prediction is $p_0 \pm (F_0/k)^2$.  Only the leading order: a scale for the continuation and
    an independent estimate of the located contact loss, not the located value.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The path parameter.
    hopf : HopfResult
        The Hopf point (``side`` must be nonzero).

    Returns
    -------
    float or None
        The predicted parameter value, ``None`` if the normal force does not fall on the cycle to first order.
    """
    if hopf is None or not hopf.side:
        return None
    from ..simulation import simulation_model

    sim = simulation_model(engine)
    p0 = float(hopf.p0)
    d = 1e-9 * max(1.0, abs(p0))
    drops = []
    F0 = None
    for dd in (d, 4 * d):
        p = p0 + hopf.side * dd
        params = space.resolve({name: p})
        st = sim.silent(params)
        g = hopf.cycle_guess(p, n_segments=64)
        xe = hopf.x0 + hopf.dx0_dp * (p - p0)
        f0 = sim.contact_at(params, xe, st)[:, 0]
        F = np.array([sim.contact_at(params, y, st)[:, 0] for y in g.x])
        drops.append(f0 - _periodic_min(F))
        F0 = f0 if F0 is None else F0
    k_sqrt_d = 2 * drops[0] - 0.5 * drops[1]  # k sqrt(d), the O(d) term removed
    assert F0 is not None
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = np.where((k_sqrt_d > 0) & (F0 > 0), d * (F0 / k_sqrt_d) ** 2, np.inf)
    best = float(np.min(dist))
    return p0 + hopf.side * best if math.isfinite(best) else None


def _refine_event(system: Any, indicator: Any, pa: float, ga: float, guess_a: tuple[np.ndarray, float],
                  pb: float, gb: float, guess_b: tuple[np.ndarray, float], *, ptol: float,
                  tick: Callable[[], None] | None = None) -> float:
    """Zero of ``indicator(orbit)`` in ``p`` between two branch points (Illinois method on ``p``; each
    evaluation a periodic orbit shot at fixed ``p`` from the nearer known orbit).  Returns the located ``p``
    (the linear interpolation of the bracket if a shooting fails).  ``tick()`` is called before each
    shooting (whatever it raises propagates: the explorer's Cancel)."""
    from .periodic import ShootingError, find_periodic_orbit

    lo, glo, ylo = pa, ga, guess_a
    hi, ghi, yhi = pb, gb, guess_b
    side = 0
    best = lo + (hi - lo) * glo / (glo - ghi)
    for _ in range(40):
        p = best
        if not (min(lo, hi) < p < max(lo, hi)):
            p = 0.5 * (lo + hi)
        if tick is not None:
            tick()
        w = (p - lo) / (hi - lo)
        x_guess = (1 - w) * ylo[0] + w * yhi[0]
        T_guess = (1 - w) * ylo[1] + w * yhi[1]
        try:
            o = find_periodic_orbit(system, x_guess, period=T_guess, p=p, tol=1e-10, n_samples=256)
        except ShootingError:
            return best
        g = float(indicator(o, p))
        best = p
        if g == 0 or abs(hi - lo) <= ptol:
            break
        if (g > 0) == (glo > 0):
            lo, glo, ylo = p, g, (o.x[0], o.period)
            if side == 1:
                ghi /= 2
            side = 1
        else:
            hi, ghi, yhi = p, g, (o.x[0], o.period)
            if side == -1:
                glo /= 2
            side = -1
        best = lo + (hi - lo) * glo / (glo - ghi)
        if abs(best - p) <= ptol:
            break
    return float(best)


def _duty_cycle(orbit: Any, mode0: int, npad: int) -> np.ndarray:
    """Fraction of the period each pad is pressed, from the orbit's switching events (mode bit j = pad j lifted)."""
    T = float(orbit.period)
    off = np.zeros(npad)
    mode, t_prev = mode0, 0.0
    for e in sorted(orbit.events, key=lambda e: e.t):
        t = min(max(float(e.t), 0.0), T)
        for j in range(npad):
            if (mode >> j) & 1:
                off[j] += t - t_prev
        mode, t_prev = int(e.target), t
    for j in range(npad):
        if (mode >> j) & 1:
            off[j] += T - t_prev
    return 1.0 - off / T


@dataclass(frozen=True)
class SquealSummary:
    """What a brake engineer needs from a limit-cycle branch: where squeal exists, how loud, at what frequency.

    Attributes
    ----------
    parameter : str
        The path parameter.
    onset : float
        The linear onset (Hopf point).
    criticality : str
        ``"supercritical"`` (soft onset), ``"subcritical"`` (hard onset) or ``"degenerate"``.
    squeal_range : (float, float) or None
        Parameter range of the computed branch where a *stable* limit cycle exists (squeal can be heard): the
        span of the orbits whose Floquet verdict is ``"stable"`` (an ``"undecided"`` orbit counts as neither);
        ``None`` when no computed cycle is certified stable.
    hysteresis_range : (float, float) or None
        Range below (or above) the linear onset where the silent motion is stable but stable squeal coexists
        (between a fold of cycles and the Hopf point); ``None`` when the branch has no such fold.
    folds : list of float
        Parameter values of the folds of cycles (``LPC``).
    contact : str
        ``"unilateral"`` (pads lift off and come back) or ``"bilateral"``.
    contact_loss : float or None
        Where a pad first lifts off along the branch.
    validity_end : float or None
        Where the model first leaves its validity range along the branch: a pad's sliding velocity
        reverses on the cycle (Coulomb friction would stick; not modelled).  ``None`` if never on the branch.
    table : list of dict
        Per branch point: ``p``, ``frequency_hz``, ``tilt_amplitude`` [rad] (largest first-harmonic tilt),
        ``F_n_max``, ``F_n_min`` [N] per pad (acting force), ``duty_cycle`` per pad (``None`` where a
        bilateral branch is not valid: a pad would pull), ``stable`` (``None``: no verdict, harmonic balance),
        ``sliding_reversal``, ``verdict`` (``"stable"``, ``"unstable"`` or ``"undecided"``: a multiplier within
        the computation's accuracy of the unit circle, or two methods disagreeing; :mod:`.floquet`), ``located``
        (shooting: the Hopf point or a located fold, period doubling or torus point, where a multiplier is on the
        unit circle by construction).
    pads : tuple of str
        Pad names.
    """

    parameter: str
    onset: float
    criticality: str
    squeal_range: tuple[float, float] | None
    hysteresis_range: tuple[float, float] | None
    folds: list[float]
    contact: str
    contact_loss: float | None
    validity_end: float | None
    table: list[dict[str, Any]]
    pads: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (all fields)."""
        return {"parameter": self.parameter, "onset": self.onset, "criticality": self.criticality,
                "squeal_range": self.squeal_range, "hysteresis_range": self.hysteresis_range, "folds": self.folds,
                "contact": self.contact, "contact_loss": self.contact_loss, "validity_end": self.validity_end,
                "pads": list(self.pads), "table": self.table}

    def text(self, rows: int = 8) -> str:
        """A short report: onset, squeal range, hysteresis, and a table of ``rows`` branch points (none if 0)."""
        P = self.parameter
        lines = [f"squeal onset (linear): {P} = {self.onset:.10g}, {self.criticality} "
                 f"({'soft onset' if self.criticality == 'supercritical' else 'hard onset: jump to large squeal'})"]
        undecided = [r["p"] for r in self.table
                     if r.get("verdict") == "undecided" and r["stable"] is not None and not r.get("located")]
        if self.squeal_range is None and self.table and all(r["stable"] is None for r in self.table):
            lines.append("stability not computed (or no verdict) on the computed branch")
        elif self.squeal_range is None:
            lines.append("no stable limit cycle on the computed branch")
        else:
            lines.append(f"stable squeal on the computed branch for {P} in [{self.squeal_range[0]:.8g}, "
                         f"{self.squeal_range[1]:.8g}]")
        if undecided:
            lines.append(f"stability undecided (not counted in the range) at {len(undecided)} of {len(self.table)} "
                         f"computed orbits, {P} in [{min(undecided):.8g}, {max(undecided):.8g}]")
        if self.hysteresis_range is not None:
            lines.append(f"hysteresis: squeal can persist where the linear analysis says stable, {P} in "
                         f"({self.hysteresis_range[0]:.8g}, {self.hysteresis_range[1]:.8g})")
        elif self.folds:
            lines.append("folds of cycles at " + ", ".join(f"{P} = {v:.8g}" for v in self.folds))
        else:
            lines.append("no fold of cycles: no hysteresis on the computed branch")
        if self.contact_loss is not None:
            lines.append(f"a pad first lifts off at {P} = {self.contact_loss:.8g} ({self.contact} contact"
                         f"{'' if self.contact == 'unilateral' else '; the branch beyond is not valid'})")
        if self.validity_end is not None:
            lines.append(f"model validity ends at {P} = {self.validity_end:.8g}: a pad's sliding velocity "
                         "reverses on the cycle (stick-slip is not modelled)")
        if rows <= 0:
            return "\n".join(lines) + "\n"
        pads = self.pads
        head = (f"{P:>12} {'f [Hz]':>10} {'tilt [rad]':>11} "
                + " ".join(f"{'Fn max ' + q:>11} {'duty ' + q:>7}" for q in pads) + "  stable")
        lines.append(head)
        tab = self.table
        idx = sorted(set(np.linspace(0, len(tab) - 1, min(rows, len(tab))).round().astype(int).tolist()))
        for i in idx:
            r = tab[i]
            cells = " ".join(f"{r['F_n_max'][j]:11.5g} " + (f"{r['duty_cycle'][j]:7.3f}" if r["duty_cycle"][j]
                                                                is not None else f"{'-':>7}") for j in range(len(pads)))
            flag = "-" if r["stable"] is None else "yes" if r["stable"] else "no"
            if r.get("verdict") == "undecided":  # a multiplier within the monodromy's accuracy of the unit circle
                flag = "undecided" if r["stable"] is None else f"undecided ({flag})"
            if r["sliding_reversal"]:
                flag += " (sliding reverses)"
            lines.append(f"{r['p']:12.8g} {r['frequency_hz']:10.6g} {r['tilt_amplitude']:11.4g} {cells}  {flag}")
        return "\n".join(lines) + "\n"


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
    contact : str
        ``"bilateral"`` (the branch is valid up to the contact loss) or
        ``"unilateral"`` (continued through lift-off and re-contact; its
        ``data`` also has ``duty_cycle``).
    summary : SquealSummary or None
        The engineer's summary (:func:`squeal_summary`).
    """

    hopf: HopfPoint
    branch: Any
    contact_loss: float | None
    pads: tuple[str, ...]
    contact: str = "bilateral"
    summary: SquealSummary | None = None

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
            "route": "shooting", "n_points": int(p.size),
            "hopf": self.hopf.to_dict(), "points": int(p.size), "status": self.branch.status,
            "message": self.branch.message, "contact_loss": self.contact_loss,
            "in_contact_up_to": float(p[last]),
            "amplitude_at_last_contact_point": dict(zip(coords, map(float, ds["amplitude"].values[last]))),
            "frequency_hz_at_last_contact_point": float(ds["frequency"].values[last]),
            "special_points": [{"kind": str(k), "p": float(v)} for k, v in
                               zip(ds["special_kind"].values, ds["special_p"].values)],
            "hysteresis_range": ds.attrs.get("hysteresis_range"), "contact": self.contact,
            "summary": None if self.summary is None else self.summary.to_dict(),
            "floquet": _floquet_rows(ds),
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


def _floquet_rows(ds: Any) -> list[dict[str, Any]]:
    """Per branch point: the verified Floquet data of the shooting route (:mod:`.floquet`)."""
    if "verdict" not in ds:
        return []
    cols = ("trivial_multiplier_error", "multiplier_accuracy", "largest_multiplier", "multiplier_change")
    return [{"p": float(ds["p"].values[i]), "label": str(ds["label"].values[i]),
             **{c: float(ds[c].values[i]) if c in ds else math.nan for c in cols},
             "stable": bool(ds["stable"].values[i]),
             "verdict": str(ds["verdict"].values[i])} for i in range(ds["p"].size)]


#: Shooting methods of :func:`squeal_branch` (``flow_method``; ``None``: the automatic choice).
FLOW_METHODS: tuple[str, ...] = ("DOP853", "Radau", "BDF")
#: Stiffness ratio (fastest eigenvalue modulus of the linearization at the Hopf point over the Hopf
#: frequency) above which a unilateral branch is shot with the monodromy tolerance relaxed to ``rtol``.
STIFF_RATIO: float = 5.0
#: ``rtol`` of the implicit shooting methods (their error estimator is of low order: at ``1e-9`` the
#: orbit agrees with DOP853 at ``1e-11`` to about ``1e-11`` of its scale, measured on the damped pads).
IMPLICIT_RTOL: float = 1e-9


def stiffness_ratio(system: SmoothSystem, x: np.ndarray, p: float, omega: float) -> float:
    """Fastest eigenvalue modulus of the Jacobian at ``(x, p)`` over the angular frequency ``omega``.

    Parameters
    ----------
    system : SmoothSystem
        The system (its Jacobian).
    x : ndarray
        State (e.g. the silent motion at the Hopf point).
    p : float
        Parameter.
    omega : float
        Angular frequency of the orbit (e.g. the Hopf frequency) [rad/s], positive.

    Returns
    -------
    float
        ``max |lambda(A)| / omega`` (about 1 for the rigid pads of paper-fig3, 9 with a pad damper of
        10 N s/m at ``k_ip = 1e6``, 92 at 1 N s/m).

    Raises
    ------
    ParameterError
        ``omega`` not positive and finite.
    """
    from ..errors import ParameterError

    if not (math.isfinite(omega) and omega > 0):
        raise ParameterError(f"stiffness_ratio: 'omega' must be positive and finite; got {omega!r}")
    ev = np.linalg.eigvals(system.jacobian(np.asarray(x, dtype=float), p))
    return float(np.max(np.abs(ev))) / omega


def _check_flow_method(flow_method: str | None) -> None:
    from ..errors import ParameterError

    if flow_method is not None and flow_method not in FLOW_METHODS:
        raise ParameterError(f"The option 'flow_method' must be None or one of {', '.join(FLOW_METHODS)}; "
                             f"got {flow_method!r}")


def _shooting_flow(pw: PiecewiseSystem, h: Any, flow_method: str | None) -> tuple[Any, dict[str, Any]]:
    """The flow of a unilateral branch and what was chosen (stored in the branch's attrs).

    Measured on paper-fig3 with damped pads (``k_ip = 1e6``, d_ip = 10, 1, 0.3 N s/m, one period past
    lift-off): the steps of DOP853 were limited not by the pad modes' stability but by the rounding noise of
    the lifted modes' finite-difference Jacobian against the monodromy's absolute tolerance ``1e-3 rtol``
    (with ``rtol``: 17 times faster at 1 N s/m, monodromy changed by 5e-11); Radau (rtol 1e-9, exact block
    Jacobian) was 1.4-1.6 times slower than that.  So the automatic choice stays DOP853 and relaxes the
    monodromy tolerance when the linearization is stiff (:data:`STIFF_RATIO`)."""
    from .flow import ScipyFlow

    _check_flow_method(flow_method)
    ratio = stiffness_ratio(pw.modes[0], h.x0, h.p0, abs(float(h.omega0)))
    stiff = ratio > STIFF_RATIO
    method = flow_method or "DOP853"
    rtol = 1e-11 if method == "DOP853" else IMPLICIT_RTOL
    flow = ScipyFlow(pw, method=method, rtol=rtol, atol_monodromy=rtol if stiff else None)
    info = {"flow_method": method, "flow_choice": "automatic" if flow_method is None else "given",
            "stiffness_ratio": ratio, "flow_rtol": rtol, "flow_atol_monodromy": rtol if stiff else 1e-3 * rtol}
    return flow, info


def squeal_branch(engine: Engine, space: ParameterSpace, axis: Axis, *, max_points: int = 60,
                  use_cache: bool = True, tol: float = 1e-8, contact: str = "bilateral", ds: float | None = None,
                  ds_max: float = 0.05, flow_method: str | None = None,
                  progress: Callable[[float], None] | None = None) -> SquealBranch:
    """Continue the limit cycles from the first Hopf point on a path and find where a pad loses contact.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller; :func:`brakesqueal.squeal_branch` builds it, and
        regularises the pads with ``pad_slope``, :func:`cycle_space`).
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
    contact : {"bilateral", "unilateral"}
        ``"bilateral"``: the smooth equations (the branch is valid up to the
        contact loss, which is located); ``"unilateral"``: shooting with the
        piecewise flow of :func:`model_piecewise_system`, so the branch goes
        on through lift-off and re-contact (the contact loss is a ``GR``
        point of the branch).
    ds, ds_max : float, optional
        Initial and largest step of :func:`~.continuation.continue_cycles` (scaled arclength).  The
        parameter scale is twenty times the distance from the onset to the contact loss predicted by the
        Hopf point (:func:`predicted_contact_loss`), not the width of the range, so the steps near the
        onset do not depend on the requested range.
    flow_method : {None, "DOP853", "Radau", "BDF"}
        The integrator of a unilateral branch's shooting (:class:`~.flow.ScipyFlow`; a bilateral branch
        always uses the compiled DOP853).  ``None`` (default): DOP853 at ``rtol = 1e-11``; when the
        linearization at the Hopf point is stiff (:func:`stiffness_ratio` above :data:`STIFF_RATIO`, e.g.
        pads with a tangential damper) with the monodromy's absolute tolerance relaxed to ``rtol``.  The
        implicit methods run at ``rtol = 1e-9`` with the augmented Jacobian.  The choice is stored in the
        data's attrs (``flow_method``, ``flow_choice``, ``stiffness_ratio``, ``flow_rtol``,
        ``flow_atol_monodromy``, ``integrator``).
    progress : callable, optional
        ``progress(fraction)``: passed to :func:`~.continuation.continue_cycles` (called after each
        accepted branch point with the fraction done in ``[0, 1]``, never decreasing), then called with the
        last fraction before each shooting of the location of the contact loss and the end of validity,
        and with 1.0 at the end.  An exception it raises stops the continuation and propagates (the
        explorer's Cancel).

    Notes
    -----
    The contact loss (first zero of the smallest normal force over a period) and, on a bilateral
    branch, the end of validity (first zero of the smallest sliding margin) are located between the two
    branch points that bracket them by the Illinois method on the parameter, each evaluation a periodic
    orbit shot at that parameter with 256 samples and the minimum over the period refined by a parabola:
    the located values do not depend on the steps or the range (to about ``1e-8`` relative).

    Returns
    -------
    SquealBranch
        With the engineer's :class:`SquealSummary` and its fields in ``data``:
        ``F_n_min`` (smallest bilateral normal force over the period; negative
        means a pad lifts off), ``F_n_max`` (largest acting force),
        ``duty_cycle``, ``tilt_amplitude``, ``sliding_reversal``, ``in_contact``.

    Raises
    ------
    ParameterError
        No Hopf point with a cycle prediction on the path, a bad ``contact``, ``flow_method`` or
        ``progress`` (not callable).
    """
    from ..errors import ParameterError
    from .continuation import _check_progress, _Progress, continue_cycles

    _check_progress(progress)
    if contact not in ("bilateral", "unilateral"):
        raise ParameterError(f"The option 'contact' must be bilateral or unilateral; got {contact!r}")
    _check_flow_method(flow_method)
    if flow_method is not None and contact != "unilateral":
        raise ParameterError("The option 'flow_method' applies to contact='unilateral' (a bilateral branch is "
                             "shot with the compiled DOP853)")
    from ..model.options import stick_slip_everywhere

    stick = stick_slip_everywhere(space.resolve({}).model)  # the simulation's rule (regularised stick-slip)
    pts = [hp for hp in hopf_points(engine, space, axis, use_cache=use_cache)
           if hp.branch_start is not None and hp.branch_start.side]
    if not pts:
        raise ParameterError(f"no Hopf point with a limit-cycle prediction for {axis.name} in "
                             f"({axis.start:g}, {axis.stop:g}); see brakesqueal hopf")
    hp = pts[0]
    h = hp.branch_start
    assert h is not None
    predicted = predicted_contact_loss(engine, space, axis.name, h)
    p_scale = 20 * abs(predicted - h.p0) if predicted is not None else None
    tracker = _Progress(progress, max_points)  # relays the continuation's fractions and keeps the last
    opts: dict[str, Any] = {"max_points": max_points, "tol": tol, "p_scale": p_scale, "ds_max": ds_max,
                            "ds": min(0.02, ds_max) if ds is None else ds, "progress": tracker.report}
    system = model_system(engine, space, axis.name, use_cache=use_cache)
    sim = system.simulation_model  # type: ignore[attr-defined]
    flow_info: dict[str, Any] = {}
    if contact == "unilateral":
        pw = model_piecewise_system(engine, space, axis.name, use_cache=use_cache)
        flow, flow_info = _shooting_flow(pw, h, flow_method)
        br = continue_cycles(pw, h, (axis.start, axis.stop), flow=flow, **opts)
    else:
        br = continue_cycles(system, h, (axis.start, axis.stop), **opts)
    data = br.data
    p = data["p"].values
    orbits = data["orbit"].values
    npad = len(sim.pads)
    fmin = np.full((p.size, npad), np.nan)
    fmax = np.full((p.size, npad), np.nan)
    duty = np.full((p.size, npad), np.nan)
    reversal = np.zeros(p.size, dtype=bool)
    margin = np.full(p.size, np.nan)
    for i in range(p.size):
        params = space.resolve({axis.name: float(p[i])})
        st = sim.silent(params)
        cq = np.array([sim.contact_at(params, y, st) for y in orbits[i]])  # (phase, pad, 7)
        F = cq[:, :, 0]
        fmin[i] = _periodic_min(F)
        pressed = F > 0
        fmax[i] = np.where(pressed, F, 0.0).max(axis=0)
        vr0 = st.vr0.reshape(npad, 3)
        slide = np.einsum("spk,pk->sp", cq[:, :, 1:4], vr0)
        reversal[i] = bool(np.any((slide <= 0) & pressed))
        margin[i] = float(_periodic_min(slide).min())
        if contact == "unilateral" and i < len(br.orbits) and br.orbits[i].events:
            o = br.orbits[i]
            duty[i] = _duty_cycle(o, int(o.sample_modes[0]) if o.sample_modes.size else 0, npad)
        elif np.all(fmin[i] > 0):
            duty[i] = 1.0
    worst = fmin.min(axis=1)

    def guess(i: int) -> tuple[np.ndarray, float]:
        if i == 0:  # the Hopf row: the predicted cycle just past the onset
            g = h.cycle_guess(float(p[0]) + h.side * 1e-6 * abs(float(p[1]) - float(p[0])))
            return g.x[0], g.period
        return br.orbits[i].x[0], float(br.orbits[i].period)

    def located(values: np.ndarray, which: int) -> float | None:
        bad = np.flatnonzero(~(values > 0))
        if not (bad.size and bad[0] > 0):
            return None
        i = int(bad[0])

        def indicator(o: Any, q: float) -> float:
            return float(_contact_indicators(sim, space.resolve({axis.name: q}), o.samples)[which].min())

        ptol = 1e-9 * max(1.0, abs(float(p[i])))
        return _refine_event(system, indicator, float(p[i - 1]), float(values[i - 1]), guess(i - 1),
                             float(p[i]), float(values[i]), guess(i), ptol=ptol, tick=tracker.again)

    loss = located(worst, 0)  # the grazing orbit is a bilateral orbit: shot with the smooth system
    end = located(margin, 1) if contact == "bilateral" and not stick else None
    import xarray as xr

    pad_c = {"pad": list(sim.pads)}
    data["F_n_min"] = xr.DataArray(fmin, dims=("point", "pad"), coords=pad_c,
                                 attrs={"units": "N", "long_name": "smallest normal force over one period "
                                                                   "(bilateral: negative where a pad lifts off)"})
    data["F_n_max"] = xr.DataArray(fmax, dims=("point", "pad"), coords=pad_c,
                                 attrs={"units": "N", "long_name": "largest acting normal force over one period"})
    data["duty_cycle"] = xr.DataArray(duty, dims=("point", "pad"), coords=pad_c,
                                    attrs={"long_name": "fraction of the period the pad is pressed (NaN: the "
                                                        "bilateral branch is not valid there)"})
    tilt = [c for c in ("q1", "q2") if c in [str(v) for v in data["coord"].values]]
    amp = data["amplitude"].sel(coord=tilt).max("coord").values if tilt else np.full(p.size, np.nan)
    data["tilt_amplitude"] = xr.DataArray(amp, dims=("point",), attrs={"units": "rad", "long_name":
                                        "largest first-harmonic amplitude of the disk tilt"})
    data["sliding_reversal"] = xr.DataArray(reversal, dims=("point",), attrs={"long_name": "a pressed pad's sliding "
                                          "velocity reverses on the cycle " + ("(regularised stick-slip)" if stick
                                                                               else "(outside the model's validity)")})
    data["in_contact"] = xr.DataArray(worst > 0, dims=("point",),
                                    attrs={"long_name": "every pad pressed over the whole period (bilateral "
                                                        "equations valid)"})
    data.attrs["contact_loss"] = np.nan if loss is None else loss
    data.attrs["contact_loss_predicted"] = np.nan if predicted is None else predicted
    data.attrs["validity_end"] = np.nan if end is None else end
    data.attrs["contact"] = contact
    data.attrs.update(flow_info)
    data.attrs["stick_slip"] = "regularised" if stick else "none"
    out = SquealBranch(hp, br, loss, tuple(sim.pads), contact)
    summ = squeal_summary(out)
    data.attrs["summary"] = json.dumps(summ.to_dict(), default=float)
    tracker.done()
    return SquealBranch(hp, br, loss, tuple(sim.pads), contact, summ)


def squeal_summary(branch: SquealBranch) -> SquealSummary:
    """The engineer's summary of a squeal branch (see :class:`SquealSummary`).

    Parameters
    ----------
    branch : SquealBranch
        From :func:`squeal_branch` (its ``data`` has the contact fields).

    Returns
    -------
    SquealSummary
        The squeal range is the span of the stable points that are valid
        (every pad pressed for a bilateral branch); the hysteresis range is
        the branch's (fold to Hopf point; on a bilateral branch only if every
        pad is pressed up to the fold), or, for any fold of cycles on the
        far side of the onset from the cycles' birth, the range between it
        and the onset.
    """
    ds = branch.data
    p = ds["p"].values
    stable = ds["stable"].values.astype(bool)
    valid = np.ones(p.size, dtype=bool) if branch.contact == "unilateral" else ds["in_contact"].values.astype(bool)
    # an orbit whose Floquet verdict is undecided (a multiplier within the accuracy of the unit circle, not at a
    # located crossing) counts as neither stable nor unstable: the range spans the orbits certified stable; the
    # Hopf point and the located folds (a multiplier on the unit circle by construction) bound it as before
    decided = ds["verdict"].values.astype(str) != "undecided" if "verdict" in ds else np.ones(p.size, dtype=bool)
    decided[[int(i) for i in ds["special_index"].values if 0 <= int(i) < p.size]] = True
    ok = stable & valid & decided
    h = branch.hopf.branch_start  # the normal form of the continued (simulated) equations
    onset = float(h.p0) if h is not None else float(branch.hopf.value)
    rng = (float(p[ok].min()), float(p[ok].max())) if ok.any() else None
    loss = branch.contact_loss
    if rng is not None and branch.contact == "bilateral" and loss is not None:
        last = int(np.flatnonzero(ok)[-1])
        if last + 1 < p.size and stable[last + 1] and decided[last + 1] and not valid[last + 1] \
                and min(p[last], p[last + 1]) <= loss:
            rng = (min(rng[0], loss), max(rng[1], loss))  # stable up to the located contact loss
    folds = [float(v) for k, v in zip(ds["special_kind"].values, ds["special_p"].values) if str(k) == "LPC"]
    hyst = branch.branch.hysteresis_range
    if hyst is not None and branch.contact == "bilateral":
        lpc = [int(i) for k, i in zip(ds["special_kind"].values, ds["special_index"].values) if str(k) == "LPC"]
        if lpc and not valid[:lpc[0] + 1].all():
            hyst = None  # the fold lies past the first contact loss: the bilateral branch does not describe it
    if hyst is None and folds and h is not None and h.side:
        beyond = [f for f in folds if (f - onset) * h.side < 0]  # a fold on the linearly stable side
        if beyond and ok.any():
            f = max(beyond, key=lambda v: abs(v - onset))  # the farthest fold bounds the coexistence range
            hyst = (min(f, onset), max(f, onset))
    rev = ds["sliding_reversal"].values.astype(bool)
    located_end = float(ds.attrs.get("validity_end", np.nan))
    stick = ds.attrs.get("stick_slip") == "regularised"  # a sliding reversal is then ordinary motion
    validity_end = located_end if math.isfinite(located_end) else (float(p[np.flatnonzero(rev)[0]])
                                                                    if rev.any() and not stick else None)
    located = {int(i) for i in ds["special_index"].values}
    tab = []
    for i in range(p.size):
        tab.append({"p": float(p[i]), "frequency_hz": float(ds["frequency"].values[i]),
                    "tilt_amplitude": float(ds["tilt_amplitude"].values[i]),
                    "F_n_max": [float(v) for v in ds["F_n_max"].values[i]],
                    "F_n_min": [float(max(v, 0.0)) if branch.contact == "unilateral" else float(v)
                                for v in ds["F_n_min"].values[i]],
                    "duty_cycle": [float(v) if math.isfinite(v) else None for v in ds["duty_cycle"].values[i]],
                    "stable": bool(stable[i]), "sliding_reversal": bool(rev[i]),
                    "verdict": str(ds["verdict"].values[i]) if "verdict" in ds else None,
                    "located": bool(i in located)})
    crit = h.criticality if h is not None else "unknown"
    return SquealSummary(str(ds.attrs.get("parameter", branch.hopf.parameter)), onset, crit, rng, hyst, folds,
                         branch.contact, branch.contact_loss, validity_end, tab, branch.pads)
