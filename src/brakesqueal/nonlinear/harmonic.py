r"""Limit cycles of a brake model with the exact massless Coulomb pads, by harmonic balance.

The model's equations are implicit, ``r(Q, Qdot, Qddot, L, Ldot) = 0`` (eq. 44 and the pads' balances
``G = (l - u_m) + c_ip (f_t + mu* N0) = 0``, eqs. 33-34; the generated residuals of
:class:`~brakesqueal.codegen.compiled.CompiledModel` with their exact Jacobian).  With Coulomb friction the
pad's rate ``Ldot`` enters ``G`` only through the friction direction and ``F_n``: at the silent motion it
drops out (``dG/dLdot = 0``), so the explicit simulation treats the pads as quasi-static (exact to first
order) or regularises them (``mu + S v``, error ``O(S)``).  Harmonic balance needs neither: the periodic
orbit is sought directly in the implicit equations,

.. math::

   u(t) = (Q, L)(t) = c_0 + \sum_{k=1}^{H} a_k \cos k\omega t + b_k \sin k\omega t,

with ``Qdot``, ``Qddot``, ``Ldot`` from the series, and the residuals ``r`` evaluated at ``M = 4H + 4``
equally spaced phases and projected on the same ``2H + 1`` harmonics (alternating frequency-time
Galerkin method).  Unknowns: the coefficients, ``omega`` and the parameter ``p``; equations: the
``(n + m)(2H + 1)`` projected residuals, the phase condition ``b_1 = 0`` of a reference coordinate and a
pseudo-arclength condition.  Newton's method uses the exact Jacobian of ``r`` (the generated code, chained
through the series); only ``d r / d p`` is a central difference (``p`` enters through the resolved parameter
vector).  The branch starts from the exact normal form (:func:`~.implicit.exact_lyapunov`: eigenvector
``phi`` of the pencil, ``|z|^2 = -mu' (p - p0) / Re c1``), corrected at a fixed first-harmonic amplitude
just past the Hopf point, and is continued until ``max_points``, the end of the range, a pad's normal force
reaching 0 over the period (contact loss: the bilateral equations end) or a pad's sliding velocity
reversing (Coulomb friction would stick: the end of the model's validity); both events are located by the
Illinois method on the parameter.

Truncation error: the largest of the two highest harmonics relative to the first (each coordinate in its
own scale); above ``harmonic_tol`` the number of harmonics is raised (up to ``max_harmonics``), beyond that
the branch stops with status ``truncation``.

Stability: Hill's method on the periodic pencil ``r_u(t) + (lambda + d/dt) r_udot(t) + (lambda + d/dt)^2
r_uddot(t)`` in the same Fourier basis (a quadratic eigenvalue problem, linearised); of every family
``lambda + i k omega`` the copy whose eigenvector is centred on ``k = 0`` is kept, ``2n`` exponents of the
mechanical states ``(Q, Qdot)`` within the band the harmonics resolve (``|lambda| <= H omega / 2``), the
smallest in modulus being the trivial one (the phase shift; returned as an accuracy check).  The pads' own
modes (a pad whose rate enters its balance on the orbit has a first-order mode of rate ``~ G_L / G_Ldot``,
``1e6``-``1e8`` 1/s on the paper's model, far outside that band) are not resolved and not judged.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import BrakesquealError, ParameterError

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..simulation import SimulationModel
    from .implicit import PadHopf

__all__ = ["HarmonicPoint", "HarmonicBranch", "harmonic_branch", "pad_mode_rates", "hill_accuracy",
           "shooting_flow"]



@dataclass(frozen=True, eq=False)
class HarmonicPoint:
    """One periodic orbit of the implicit equations.

    Attributes
    ----------
    p : float
        Parameter value.
    omega : float
        Angular frequency [rad/s].
    frequency_hz : float
        ``omega / (2 pi)``.
    amplitude : dict
        First-harmonic amplitude ``sqrt(a_1^2 + b_1^2)`` of every coordinate ``Q`` and pad deformation ``L`` (SI).
    tilt_amplitude : float or None
        Largest first-harmonic amplitude of the tilts ``q1``, ``q2`` [rad] (``None`` without them).
    F_n_min : tuple of float
        Per pad, the smallest normal force over the period [N].
    F_n_max : tuple of float
        Per pad, the largest normal force over the period [N].
    sliding_margin_min : float
        The smallest, over pads and the period, sliding velocity component along the silent motion's [m/s].
    residual : float
        Largest residual at 10x more (off-grid) phases, relative to the linear terms' magnitude.
    truncation_error : float
        Largest of the two highest harmonics relative to the first (per coordinate, largest over coordinates).
    harmonics : int
        Number of harmonics ``H``.
    coefficients : ndarray
        ``(n + m, 2H + 1)``: ``c_0, a_1, b_1, ..., a_H, b_H`` per coordinate (``Q`` then ``L``).
    floquet_exponents : ndarray or None
        Non-trivial Floquet exponents by decreasing real part (Hill's method), ``None`` if not computed.
    stable : bool or None
        Every non-trivial exponent in the resolved band with negative real part and no pad's own fast mode
        unstable (:func:`pad_mode_rates`); ``None`` if not computed or if fewer than ``2n`` exponents lie in
        the band (no verdict).
    trivial_exponent : float or None
        The smallest ``|exponent|`` (the phase shift's zero exponent; an accuracy check).
    stability_from : str or None
        What decided ``stable``: ``"Hill's method"``, or ``"normal form"`` where an exponent lies within
        :func:`hill_accuracy` of 0 (its printed sign is then not meaningful, e.g. a tiny positive radial
        exponent of a stable cycle next to a supercritical onset); ``None`` without a verdict.
    F_n_max : tuple of float
        Per pad, the largest normal force over the period [N].
    trivial_multiplier_error : float or None
        ``|exp(trivial_exponent T) - 1|``: the trivial (phase) multiplier's distance from 1 (``None`` without
        Hill's method).
    hill_verdict : str or None
        ``"stable"``, ``"unstable"`` or ``"undecided"`` from ``stable`` (Hill's method or the normal form).
    monodromy_verdict : str or None
        The verdict of the monodromy matrix of the simulated equations from the orbit's state at ``t = 0``
        (:func:`~.floquet.stability_verdict`), where the pads allow shooting (the simulated equations keep every
        pad's rate); ``None`` elsewhere.
    multipliers : ndarray or None
        Non-trivial multipliers of that monodromy, by decreasing modulus.
    shooting_mismatch : float or None
        ``max |phi(x(0), T) - x(0)|`` over the states' amplitudes: the harmonic-balance orbit integrated over one
        period by the simulated equations; ``None`` where the pads do not allow shooting.
    verdict : str
        The point's verdict: Hill's (or the normal form's) and the monodromy's where both exist
        (:func:`~.floquet.cross_check`: they must agree, else ``"undecided"``); ``"undecided"`` without one.
    """

    p: float
    omega: float
    frequency_hz: float
    amplitude: dict[str, float]
    tilt_amplitude: float | None
    F_n_min: tuple[float, ...]
    sliding_margin_min: float
    residual: float
    truncation_error: float
    harmonics: int
    coefficients: np.ndarray = field(repr=False)
    floquet_exponents: np.ndarray | None = field(default=None, repr=False)
    stable: bool | None = None
    trivial_exponent: float | None = None
    stability_from: str | None = None
    F_n_max: tuple[float, ...] = ()
    trivial_multiplier_error: float | None = None
    hill_verdict: str | None = None
    monodromy_verdict: str | None = None
    multipliers: np.ndarray | None = field(default=None, repr=False)
    shooting_mismatch: float | None = None
    verdict: str = "undecided"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (no coefficients)."""
        return {"p": self.p, "omega": self.omega, "frequency_hz": self.frequency_hz, "amplitude": self.amplitude,
                "tilt_amplitude": self.tilt_amplitude, "F_n_min": list(self.F_n_min), "F_n_max": list(self.F_n_max),
                "sliding_margin_min": self.sliding_margin_min, "residual": self.residual,
                "truncation_error": self.truncation_error, "harmonics": self.harmonics,
                "stable": self.stable, "trivial_exponent": self.trivial_exponent,
                "stability_from": self.stability_from,
                "hill_accuracy": None if self.trivial_exponent is None else hill_accuracy(self.omega,
                                                                                          self.trivial_exponent),
                "floquet_exponents": None if self.floquet_exponents is None else
                [[float(v.real), float(v.imag)] for v in self.floquet_exponents],
                "trivial_multiplier_error": self.trivial_multiplier_error, "hill_verdict": self.hill_verdict,
                "monodromy_verdict": self.monodromy_verdict, "shooting_mismatch": self.shooting_mismatch,
                "multipliers": None if self.multipliers is None else
                [[float(v.real), float(v.imag)] for v in self.multipliers],
                "verdict": self.verdict}

    def series(self, t: np.ndarray) -> np.ndarray:
        """``u(t) = (Q, L)(t)`` at times ``t`` [s] (``t = 0``: the phase where ``b_1`` of the reference is 0).

        Parameters
        ----------
        t : ndarray
            Times [s].

        Returns
        -------
        ndarray
            Shape ``(len(t), n + m)``: ``Q`` then ``L``.
        """
        th = self.omega * np.asarray(t, dtype=float)
        return _basis(th, (self.coefficients.shape[1] - 1) // 2, 0) @ self.coefficients.T


@dataclass(frozen=True)
class HarmonicBranch:
    """Limit cycles of the implicit equations (exact Coulomb pads) from a Hopf point.

    Attributes
    ----------
    parameter : str
        The path parameter.
    hopf : PadHopf
        The exact normal form where the branch starts.
    points : tuple of HarmonicPoint
        The orbits, in continuation order.
    status : str
        ``"max_points"``, ``"range"``, ``"contact_loss"``, ``"sliding_reversal"``, ``"truncation"`` or
        ``"step_underflow"``.
    message : str
        Why the branch ends.
    contact_loss : float or None
        Parameter value where a pad's smallest normal force over the period reaches 0 (located).
    sliding_reversal : float or None
        Parameter value where a pad's sliding velocity first reverses on the cycle (located): the end of the
        model's validity (Coulomb friction would stick).
    coords, pads : tuple of str
        Names of ``(Q, L)`` and of the pads.
    stability : str
        ``"Hill's method"`` or ``"not computed"``.
    """

    parameter: str
    hopf: Any
    points: tuple[HarmonicPoint, ...]
    status: str
    message: str
    contact_loss: float | None
    sliding_reversal: float | None
    coords: tuple[str, ...]
    pads: tuple[str, ...]
    stability: str = "not computed"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: Hopf point, status, events, the engineer's summary and every point."""
        h = self.hopf.hopf
        summ = self.summary
        pressed = [pt for pt, row in zip(self.points, summ.table) if row["duty_cycle"][0] is not None]
        last = pressed[-1] if pressed else None
        return {"parameter": self.parameter, "route": "harmonic balance", "n_points": len(self.points),
                "method": "harmonic balance on the implicit equations "
                "(exact massless Coulomb pads, tangential rates kept)",
                "hopf": {"p0": h.p0, "omega0": h.omega0, "frequency_hz": h.frequency0_hz, "l1": h.l1,
                         "l1_error": h.l1_error, "criticality": h.criticality, "side": h.side},
                "status": self.status, "message": self.message, "contact_loss": self.contact_loss,
                "sliding_reversal": self.sliding_reversal, "stability": self.stability,
                "coords": list(self.coords), "pads": list(self.pads), "folds": self.folds,
                "summary": summ.to_dict(), "points": [pt.to_dict() for pt in self.points],
                # the keys of the shooting route's JSON (SquealBranch.to_dict) that mean the same here
                "contact": "bilateral", "hysteresis_range": summ.hysteresis_range,
                "special_points": [{"kind": "H", "p": h.p0}] + [{"kind": "LPC", "p": f} for f in self.folds],
                "in_contact_up_to": last.p if last is not None else h.p0,
                "amplitude_at_last_contact_point": dict(last.amplitude) if last is not None else None,
                "frequency_hz_at_last_contact_point": last.frequency_hz if last is not None else None}

    @property
    def folds(self) -> list[float]:
        """Folds of cycles (``LPC``): where the branch turns back in the parameter.

        Located to the step: the vertex of the parabola through the three branch points around each turn
        (:func:`turning_points`); harmonic balance has no located fold test.
        """
        return turning_points([self.hopf.hopf.p0] + [pt.p for pt in self.points])

    @property
    def valid(self) -> list[bool]:
        """Per point, whether the bilateral equations hold there: the first run of orbits on which every pad stays
        pressed (a normal force ``>= 0`` over the whole period); points past a contact loss are not valid."""
        valid: list[bool] = []
        for pt in self.points:
            pressed = min(pt.F_n_min) >= -1e-6 * max(max(pt.F_n_max, default=0.0), 1e-300)
            valid.append(pressed and (not valid or valid[-1]))
        return valid

    @property
    def summary(self) -> Any:
        """The engineer's summary (:class:`~.models.SquealSummary`) of the branch, as for shooting.

        The branch is valid (bilateral contact) from the onset up to its first orbit on which a pad lifts off:
        every pad's smallest normal force at least ``-1e-6`` times that orbit's largest (the located contact-loss
        orbit, at ``F_n = 0`` to rounding, included).  The squeal range spans the stable valid orbits; orbits
        without a stability verdict, or whose verdict is undecided, count as neither.  The hysteresis range, as
        for shooting, lies between a subcritical Hopf point and the first fold (:attr:`folds`) where the unstable
        cycles turn into stable ones (the first orbit with a verdict after the turn is stable; right at the fold an
        exponent crosses 0 and the orbits have no verdict), here only if the branch is valid up to there.
        """
        from .squeal import SquealSummary

        h = self.hopf.hopf
        pts = self.points
        valid = self.valid
        ok = [pt.p for pt, v in zip(pts, valid) if v and pt.stable and pt.verdict != "undecided"]
        rng = (min(ok), max(ok)) if ok else None
        folds = self.folds
        hyst = None
        pv = np.array([h.p0] + [pt.p for pt in pts])
        turns = _turns(pv)
        if h.criticality == "subcritical" and turns:  # unstable cycles turning into stable ones (as shooting)
            # points[turns[0]] is the first orbit after the turn; take the first one with a verdict
            j = next((k for k in range(turns[0], len(pts)) if pts[k].stable is not None), None)
            if j is not None and pts[j].stable and valid[j]:
                hyst = (min(folds[0], h.p0), max(folds[0], h.p0))
        table = [{"p": pt.p, "frequency_hz": pt.frequency_hz,
                  "tilt_amplitude": math.nan if pt.tilt_amplitude is None else pt.tilt_amplitude,
                  "F_n_max": list(pt.F_n_max), "F_n_min": list(pt.F_n_min),
                  "duty_cycle": [1.0 if v else None] * len(self.pads), "stable": pt.stable,
                  "sliding_reversal": pt.sliding_margin_min <= 0, "verdict": pt.verdict}
                 for pt, v in zip(pts, valid)]
        return SquealSummary(self.parameter, float(h.p0), h.criticality, rng, hyst, folds, "bilateral",
                             self.contact_loss, self.sliding_reversal, table, self.pads)

    @property
    def data(self) -> Any:
        """The branch as an :class:`xarray.Dataset` (dimensions ``point``, ``coord``, ``pad``).

        Variables ``p``, ``frequency`` [Hz], ``amplitude`` (first harmonic of every ``Q`` and ``L``),
        ``tilt_amplitude`` [rad], ``F_n_min`` [N], ``sliding_margin_min`` [m/s], ``residual``,
        ``truncation_error``, ``harmonics``, ``stable`` (1 stable, 0 unstable, -1 not computed),
        ``trivial_multiplier_error``, ``shooting_mismatch`` (NaN where not computed) and ``verdict``; the
        attributes hold the parameter, the status and message, the located events and the Hopf point.
        """
        import xarray as xr

        pts = self.points
        nan = math.nan
        stab = np.array([-1 if pt.stable is None else int(pt.stable) for pt in pts], dtype=np.int8)
        amp = np.array([[pt.amplitude.get(c, nan) for c in self.coords] for pt in pts], dtype=float)
        h = self.hopf.hopf
        return xr.Dataset(
            {"p": ("point", np.array([pt.p for pt in pts], dtype=float), {"long_name": self.parameter}),
             "frequency": ("point", np.array([pt.frequency_hz for pt in pts], dtype=float), {"units": "Hz"}),
             "amplitude": (("point", "coord"), amp.reshape(len(pts), len(self.coords)),
                           {"long_name": "first-harmonic amplitude"}),
             "tilt_amplitude": ("point", np.array([nan if pt.tilt_amplitude is None else pt.tilt_amplitude
                                                   for pt in pts], dtype=float), {"units": "rad"}),
             "F_n_min": (("point", "pad"), np.array([pt.F_n_min for pt in pts], dtype=float).reshape(
                 len(pts), len(self.pads)), {"units": "N", "long_name": "smallest normal force over the period"}),
             "sliding_margin_min": ("point", np.array([pt.sliding_margin_min for pt in pts], dtype=float),
                                    {"units": "m/s"}),
             "residual": ("point", np.array([pt.residual for pt in pts], dtype=float)),
             "truncation_error": ("point", np.array([pt.truncation_error for pt in pts], dtype=float)),
             "harmonics": ("point", np.array([pt.harmonics for pt in pts], dtype=np.int32)),
             "stable": ("point", stab, {"flag_values": [-1, 0, 1],
                                        "flag_meanings": "not_computed unstable stable"}),
             "trivial_multiplier_error": ("point", np.array([nan if pt.trivial_multiplier_error is None else
                                                             pt.trivial_multiplier_error for pt in pts], dtype=float)),
             "shooting_mismatch": ("point", np.array([nan if pt.shooting_mismatch is None else pt.shooting_mismatch
                                                      for pt in pts], dtype=float)),
             "verdict": ("point", np.array([pt.verdict for pt in pts], dtype=object).astype(str),
                         {"long_name": "stable, unstable or undecided (Hill's and the monodromy's verdicts "
                                       "cross-checked)"})},
            coords={"coord": list(self.coords), "pad": list(self.pads)},
            attrs={"parameter": self.parameter, "status": self.status, "message": self.message,
                   "method": "harmonic balance on the implicit equations (exact massless Coulomb pads)",
                   "stability": self.stability,
                   "contact_loss": nan if self.contact_loss is None else self.contact_loss,
                   "sliding_reversal": nan if self.sliding_reversal is None else self.sliding_reversal,
                   "hopf_p0": h.p0, "hopf_frequency_hz": h.frequency0_hz, "hopf_l1": h.l1,
                   "criticality": h.criticality})

    def plot(self, coord: str | None = None) -> Any:
        """Bifurcation diagram: first-harmonic amplitude and frequency against the parameter.

        Stable orbits solid, unstable dashed, not judged grey; the Hopf point, the folds (located to the step,
        :attr:`folds`) and a located contact loss or sliding reversal are marked.

        Parameters
        ----------
        coord : str, optional
            Coordinate whose amplitude is drawn (default: the first tilt, else the first coordinate).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from ..plotting import new_figure

        names = list(self.coords)
        if coord is None:
            coord = "q1" if "q1" in names else names[0]
        if coord not in names:
            raise ParameterError(f"The option 'coord' must be one of {names}; got {coord!r}")
        fig, a0 = new_figure(size=(6.4, 6.4))
        a0.remove()
        axes = fig.subplots(2, 1, sharex=True)
        h = self.hopf.hopf
        p = np.array([h.p0] + [pt.p for pt in self.points])
        amp = np.array([0.0] + [pt.amplitude.get(coord, math.nan) for pt in self.points])
        fr = np.array([h.frequency0_hz] + [pt.frequency_hz for pt in self.points])
        # past a contact loss the bilateral equations do not hold: those orbits are drawn grey, whatever their
        # stability (the explorer greys them too)
        st: list[bool | str | None] = [None] + [pt.stable if ok else "invalid"
                                               for pt, ok in zip(self.points, self.valid)]
        style = {True: ("-", "C0"), False: ("--", "C3"), None: (":", "0.5"), "invalid": ("-", "0.75")}
        for a, yv in ((axes[0], amp), (axes[1], fr)):
            for i in range(1, len(p)):
                ls, col = style[st[i]]
                a.plot(p[i - 1:i + 1], yv[i - 1:i + 1], ls, color=col, lw=1.5)
        axes[0].plot([h.p0], [0.0], "s", color="k", ms=7, label="Hopf point", zorder=5)
        turns = _turns(p)
        for k, (i, f) in enumerate(zip(turns, self.folds)):  # at the fold's parameter, the turning orbit's amplitude
            axes[0].plot([f], [amp[i]], "o", color="C1", ms=7, zorder=5, label="fold (LPC)" if k == 0 else None)
        for at, lab, col in ((self.contact_loss, "contact loss", "C6"), (self.sliding_reversal, "sliding reversal",
                                                                          "C5")):
            if at is not None:
                for a in axes:
                    a.axvline(at, color=col, ls="-.", lw=1, label=lab if a is axes[0] else None)
        present = set(st[1:])
        for key, lab in ((True, "stable"), (False, "unstable"), (None, "stability not computed"),
                         ("invalid", "contact lost (not valid)")):
            if key in present:
                axes[0].plot([], [], style[key][0], color=style[key][1], label=lab)
        axes[0].legend(loc="best", fontsize="small")
        from ..labels import axis_label, branch_status_text, unit
        from ..model.components import coordinate_unit

        axes[0].set_ylabel(f"first-harmonic amplitude of {coord} [{coordinate_unit(coord)}]")
        axes[1].set_ylabel("frequency [Hz]")
        axes[1].set_xlabel(axis_label(self.parameter, unit(self.parameter) or None))
        fig.suptitle(f"limit cycles, exact Coulomb pads (harmonic balance):\n{branch_status_text(self.status)}")
        for a in axes:
            a.ticklabel_format(axis="y", useOffset=False)
        return fig


def turning_points(p: Any) -> list[float]:
    """Where a sequence of branch points turns back in the parameter: one value per turn.

    At an interior extreme ``p[i]`` (``p[i] - p[i-1]`` and ``p[i+1] - p[i]`` of opposite signs) the vertex of the
    parabola through ``p[i-1], p[i], p[i+1]`` against the point index, kept within one step of them (exact for
    a branch whose parameter is quadratic in the index near the fold; otherwise accurate to the step).

    Parameters
    ----------
    p : sequence of float
        Parameter values along the branch, in continuation order.

    Returns
    -------
    list of float
    """
    v = np.asarray(p, dtype=float)
    out = []
    for i in _turns(v):
        curv = v[i + 1] - 2 * v[i] + v[i - 1]
        top = v[i] - (v[i + 1] - v[i - 1]) ** 2 / (8 * curv) if curv != 0 else v[i]
        lo, hi = min(v[i - 1:i + 2]), max(v[i - 1:i + 2])
        out.append(float(min(max(top, lo - (hi - lo)), hi + (hi - lo))))
    return out


def _turns(v: np.ndarray) -> list[int]:
    """Indices of the interior extremes of ``v`` (where the sequence turns back)."""
    return [i for i in range(1, v.size - 1) if (v[i] - v[i - 1]) * (v[i + 1] - v[i]) < 0]


def _basis(theta: np.ndarray, H: int, order: int) -> np.ndarray:
    """``d^order/dtheta^order`` of ``(1, cos theta, sin theta, ..., cos H theta, sin H theta)``: ``(len, 2H+1)``."""
    th = np.asarray(theta, dtype=float)
    E = np.zeros((th.size, 2 * H + 1))
    E[:, 0] = 1.0 if order == 0 else 0.0
    for k in range(1, H + 1):
        c, s = np.cos(k * th), np.sin(k * th)
        # derivatives of (cos, sin): (cos, sin) -> (-k sin, k cos) -> (-k^2 cos, -k^2 sin)
        fc, fs = [(c, s), (-k * s, k * c), (-k * k * c, -k * k * s)][order]
        E[:, 2 * k - 1], E[:, 2 * k] = fc, fs
    return E


def _project(P: np.ndarray, B: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``einsum("at,ikt,tb->iakb", P, B, F)``: the Galerkin blocks of the phase-sampled Jacobian ``B``.

    One batched matrix product per row ``i`` (BLAS; with 200-400 harmonics the
    three-operand ``einsum`` took about 10 s per call, uninterruptible): Ctrl-C
    acts between the rows, and the whole is many times faster.
    """
    out = np.empty((B.shape[0], P.shape[0], B.shape[1], F.shape[1]))
    for i in range(B.shape[0]):
        out[i] = np.matmul(P[None, :, :] * B[i][:, None, :], F).transpose(1, 0, 2)
    return out


class _Balance:
    """The harmonic-balance equations of one model with ``H`` harmonics."""

    def __init__(self, space: ParameterSpace, name: str, sim: SimulationModel, H: int, ref: int,
                 scale: np.ndarray) -> None:
        cm = sim.compiled
        self.space, self.name, self.sim, self.cm = space, name, sim, cm
        self.n, self.m = cm.n, cm.m
        self.N = self.n + self.m
        self.ref, self.scale = ref, scale
        self._pv: dict[float, list[float]] = {}
        self.check: _ShootingCheck | None = None  # the simulated equations' flow, where the pads allow shooting
        self.set_harmonics(H)

    def set_harmonics(self, H: int) -> None:
        self.H, self.K = H, 2 * H + 1
        M = 4 * H + 4
        th = 2 * np.pi * np.arange(M) / M
        self.E = [_basis(th, H, k) for k in range(3)]
        Pr = self.E[0].T * (2.0 / M)
        Pr[0] *= 0.5
        self.Pr = Pr

    def pvec(self, p: float) -> list[float]:
        if p not in self._pv:
            params = self.space.resolve({self.name: float(p)})
            self._pv = {p: [float(v) for v in self.sim.parameter_vector(params)]}
        return self._pv[p]

    def states(self, C: np.ndarray, omega: float, E: list[np.ndarray]) -> list[np.ndarray]:
        """The rows of ``x = (Q, Qdot, Qddot, L, Ldot)`` at the phases of ``E``."""
        n = self.n
        U, Ud, Udd = (E[0] @ C.T).T, omega * (E[1] @ C.T).T, omega * omega * (E[2] @ C.T).T
        return [*U[:n], *Ud[:n], *Udd[:n], *U[n:], *Ud[n:]]

    def residual_time(self, C: np.ndarray, omega: float, p: float, E: list[np.ndarray]) -> np.ndarray:
        x = self.states(C, omega, E)
        M = E[0].shape[0]
        r = self.cm.vectorized.residuals(x, self.pvec(p))
        return np.array([np.broadcast_to(np.asarray(v, dtype=float), (M,)) for v in r])

    def jac_time(self, C: np.ndarray, omega: float, p: float, E: list[np.ndarray]) -> np.ndarray:
        x = self.states(C, omega, E)
        M = E[0].shape[0]
        J = self.cm.vectorized.jacobians(x, self.pvec(p))
        J = np.array([np.broadcast_to(np.asarray(v, dtype=float), (M,)) for v in J])
        return J.reshape(self.N, self.cm.nx, M)

    def F(self, y: np.ndarray) -> np.ndarray:
        C, omega, p = self.unpack(y)
        R = self.residual_time(C, omega, p, self.E) @ self.Pr.T
        return np.concatenate([R.ravel(), [C[self.ref, 2] / self.scale[self.ref]]])

    def unpack(self, y: np.ndarray) -> tuple[np.ndarray, float, float]:
        NK = self.N * self.K
        return y[:NK].reshape(self.N, self.K), float(y[NK]), float(y[NK + 1])

    def jacobian(self, y: np.ndarray) -> np.ndarray:
        """``dF/dy`` with ``y = (C, omega, p)`` (exact in ``C``, ``omega``; central difference in ``p``)."""
        C, omega, p = self.unpack(y)
        n, m, N, K = self.n, self.m, self.N, self.K
        J = self.jac_time(C, omega, p, self.E)
        JQ, JdQ, JddQ = J[:, :n], J[:, n:2 * n], J[:, 2 * n:3 * n]
        JL, JdL = J[:, 3 * n:3 * n + m], J[:, 3 * n + m:]
        K0 = np.concatenate([JQ, JL], axis=1)
        K1 = omega * np.concatenate([JdQ, JdL], axis=1)
        K2 = omega * omega * np.concatenate([JddQ, np.zeros_like(JL)], axis=1)
        E0, E1, E2 = self.E
        D = (_project(self.Pr, K0, E0) + _project(self.Pr, K1, E1) + _project(self.Pr, K2, E2)).reshape(N * K, N * K)
        U1, U2 = (E1 @ C.T).T, (E2 @ C.T).T  # d/dtheta, d^2/dtheta^2
        dw = (np.einsum("ikj,kj->ij", np.concatenate([JdQ, JdL], axis=1), U1)
              + 2 * omega * np.einsum("ikj,kj->ij", JddQ, U2[:n]))
        dw = (dw @ self.Pr.T).ravel()
        hp = 1e-6 * max(abs(p), 1e-3)
        try:
            rp = self.residual_time(C, omega, p + hp, self.E) - self.residual_time(C, omega, p - hp, self.E)
            dp = ((rp / (2 * hp)) @ self.Pr.T).ravel()
        except ParameterError:  # at a bound of the parameter's range: one-sided
            rp = self.residual_time(C, omega, p, self.E) - self.residual_time(C, omega, p - hp, self.E)
            dp = ((rp / hp) @ self.Pr.T).ravel()
        out = np.zeros((N * K + 1, N * K + 2))
        out[:N * K, :N * K] = D
        out[:N * K, N * K] = dw
        out[:N * K, N * K + 1] = dp
        out[N * K, self.ref * K + 2] = 1.0 / self.scale[self.ref]
        return out


class _Continuation:
    """Newton and pseudo-arclength continuation in scaled unknowns."""

    def __init__(self, bal: _Balance, omega0: float, p_scale: float, tol: float) -> None:
        self.bal, self.omega0, self.p_scale, self.tol = bal, omega0, p_scale, tol

    def yscale(self) -> np.ndarray:
        b = self.bal
        return np.concatenate([np.repeat(b.scale, b.K), [self.omega0, self.p_scale]])

    def newton(self, y: np.ndarray, extra: Any, max_iter: int = 15) -> tuple[np.ndarray, int]:
        """Solve ``F(y) = 0`` plus the one equation ``extra(y) -> (value, gradient)`` (unscaled gradient)."""
        s = self.yscale()
        prev = math.inf
        for it in range(1, max_iter + 1):
            J = self.bal.jacobian(y)
            F = self.bal.F(y)
            g, dg = extra(y)
            A = np.vstack([J, dg]) * s[None, :]
            b = np.concatenate([F, [g]])
            rs = np.max(np.abs(A), axis=1)
            rs[rs == 0] = 1.0
            try:
                dx = np.linalg.solve(A / rs[:, None], -b / rs)
            except np.linalg.LinAlgError:
                raise BrakesquealError("singular harmonic-balance Jacobian") from None
            if not np.all(np.isfinite(dx)):
                raise BrakesquealError("harmonic-balance Newton step is not finite")
            step = float(np.max(np.abs(dx)))
            if step > 0.5:  # trust region in the scaled unknowns
                dx *= 0.5 / step
            y = y + dx * s
            if step <= self.tol:
                return y, it
            if step <= 1e-6 and step > 0.5 * prev:  # no longer contracting: at the noise floor of the residual
                return y, it  # (the larger models stall at 1e-8..1e-7; each point reports its off-grid residual)
            prev = step
        raise BrakesquealError(f"harmonic-balance Newton did not converge in {max_iter} iterations "
                               f"(last scaled step {step:.3g})")

    def tangent(self, y: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
        s = self.yscale()
        A = self.bal.jacobian(y) * s[None, :]
        rs = np.max(np.abs(A), axis=1)
        rs[rs == 0] = 1.0
        t = np.linalg.svd(A / rs[:, None])[2][-1]
        if prev is not None and float(t @ prev) < 0:
            t = -t
        return t / np.linalg.norm(t)


def _first_hopf(engine: Engine, space: ParameterSpace, axis: Axis, use_cache: bool) -> PadHopf:
    from ..analysis.crossings import crossings
    from .implicit import exact_lyapunov

    r = crossings(engine, space, axis)
    errors = []
    for value, _direction in r.crossings:  # type: ignore[attr-defined]
        try:
            ex = exact_lyapunov(engine, space, axis.name, float(value), use_cache=use_cache)
        except (BrakesquealError, np.linalg.LinAlgError) as exc:
            errors.append(f"{value:.10g}: {exc}")
            continue
        if ex.hopf.side and axis.start <= ex.hopf.p0 <= axis.stop:
            return ex
    extra = f" (crossings without a cycle prediction: {'; '.join(errors)})" if errors else ""
    raise ParameterError(f"no Hopf point with a limit-cycle prediction for {axis.name} in "
                         f"({axis.start:g}, {axis.stop:g}){extra}; see brakesqueal hopf")


def harmonic_branch(engine: Engine, space: ParameterSpace, axis: Axis, *, harmonics: int = 6, max_harmonics: int = 60,
                    max_points: int = 40, harmonic_tol: float = 1e-6, tol: float = 1e-10,
                    ds: float = 0.05, ds_max: float = 0.2, start_offset: float = 1e-4,
                    stability: bool = True, use_cache: bool = True,
                    stop_at_contact_loss: bool = True,
                    progress: Callable[[float], None] | None = None, residual_tol: float | None = None,
                    mismatch_tol: float = 1e-6, shooting_check: bool = True) -> HarmonicBranch:
    """Limit cycles of the implicit equations (exact massless Coulomb pads) by harmonic balance.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller; :func:`brakesqueal.harmonic_branch` builds it).
    space : ParameterSpace
        The model, preset and overrides (any model).
    axis : Axis
        The path: the first Hopf point with a cycle prediction in ``[start, stop]`` is continued within it.
    harmonics : int
        Initial number of harmonics ``H`` (>= 1); raised (by half, at least 2) while the truncation error exceeds
        ``harmonic_tol``, the residual of the truncated series in the equations at 10x more off-grid phases
        exceeds ``residual_tol`` or, where the pads allow shooting, the shooting mismatch exceeds
        ``mismatch_tol``.
    max_harmonics : int
        Largest number of harmonics (>= ``harmonics``).
    max_points : int
        Largest number of branch points (>= 2).
    harmonic_tol : float
        Largest accepted truncation error (relative size of the highest harmonics), in ``(0, 1)``.
    tol : float
        Newton tolerance on the scaled update, in ``(0, 1e-3]``.
    ds, ds_max : float
        Initial and largest pseudo-arclength step in scaled unknowns (coefficients over the amplitude
        predicted at the first event or the end of the range, ``p`` over the distance to it).
    start_offset : float
        The first orbit has the first-harmonic amplitude predicted at ``start_offset`` times that distance
        past the Hopf point, in ``(0, 0.5]``.
    stability : bool
        Compute Floquet exponents by Hill's method.
    use_cache : bool
        Use the on-disk code cache.
    stop_at_contact_loss : bool
        ``True`` (default): the branch ends at the located contact loss, where the bilateral equations stop
        describing the brake.  ``False``: the contact loss is located and recorded, and the continuation goes on
        along the bilateral equations (a study of the smooth model, as shooting's bilateral branches do).
    progress : callable, optional
        ``progress(fraction)`` is called after each accepted branch point with the fraction done in
        ``[0, 1]``, never decreasing (the running maximum of ``points / max_points`` and of the distance
        covered in the parameter from the Hopf point towards the far end of the range: a branch can turn
        at a fold), with the last fraction before each orbit of the location of the contact loss or the
        sliding reversal, and with 1.0 at the end.  An exception it raises stops the continuation and
        propagates (the explorer's Cancel).
    residual_tol : float, optional
        Largest accepted residual (:attr:`HarmonicPoint.residual`, relative to the linear terms), in ``(0, 1)``;
        default ``harmonic_tol``.
    mismatch_tol : float
        Largest accepted shooting mismatch (:attr:`HarmonicPoint.shooting_mismatch`: the orbit's state integrated
        over one period by the simulated equations, relative to the states' amplitudes), in ``(0, 1)``; only
        where the pads allow shooting (the simulated equations keep every pad's rate, :func:`~.models.cycle_route`
        would shoot).  At least ``1e3`` times the integrator's ``rtol`` (its floor); a mismatch that a raise of
        the harmonics does not halve is accepted (the integration's error, not the series', dominates).
    shooting_check : bool
        Where the pads allow shooting, integrate every orbit over one period: the mismatch, and the monodromy's
        verdict cross-checked with Hill's (:attr:`HarmonicPoint.verdict`).

    Returns
    -------
    HarmonicBranch

    Raises
    ------
    ParameterError
        A bad option (naming it; ``progress`` not callable), an axis outside the parameter's allowed range,
        or no Hopf point with a cycle prediction on the path.
    BrakesquealError
        The first orbit cannot be found.
    """
    from ..simulation import simulation_model
    from .continuation import _check_progress, _Progress

    _check_progress(progress)
    for nm, v, lo in (("harmonics", harmonics, 1), ("max_points", max_points, 2)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or v < lo:
            raise ParameterError(f"The option '{nm}' must be an integer >= {lo}; got {v!r}")
    if not isinstance(max_harmonics, (int, np.integer)) or max_harmonics < harmonics:
        raise ParameterError(f"The option 'max_harmonics' must be an integer >= harmonics = {harmonics}; "
                             f"got {max_harmonics!r}")
    for nm, fv, lo_, hi_ in (("harmonic_tol", harmonic_tol, 0.0, 1.0), ("tol", tol, 0.0, 1e-3),
                             ("ds", ds, 0.0, 1.0), ("ds_max", ds_max, 0.0, 1.0),
                             ("start_offset", start_offset, 0.0, 0.5), ("mismatch_tol", mismatch_tol, 0.0, 1.0),
                             ("residual_tol", harmonic_tol if residual_tol is None else residual_tol, 0.0, 1.0)):
        if not (isinstance(fv, (int, float)) and math.isfinite(fv) and lo_ < fv <= hi_):
            raise ParameterError(f"The option '{nm}' must be in ({lo_:g}, {hi_:g}]; got {fv!r}")
    if axis.name not in space.settable():
        space.resolve({axis.name: axis.start})  # the one message for unknown or tied names
    for bound in (axis.start, axis.stop):
        space.resolve({axis.name: float(bound)})  # ParameterError naming the parameter and its range
    ex = _first_hopf(engine, space, axis, use_cache)
    h = ex.hopf
    from .implicit import _Point, _vectors

    sim = simulation_model(engine, use_cache=use_cache)
    pt = _Point(space, sim, axis.name, h.p0)
    cm = pt.cm
    n = cm.n
    phi, _psi, _q, _pv = _vectors(pt, h.omega0)
    ratio = abs(h.dRe_lambda_dp / h.c1.real)
    # the distance to the first predicted event (or the end of the range): the continuation's scales
    ends = [v for v in (ex.contact_loss, ex.sliding_reversal) if v is not None]
    far = axis.stop if h.side > 0 else axis.start
    dist = min([abs(v - h.p0) for v in ends] + [abs(far - h.p0)])
    if dist <= 0:
        raise ParameterError(f"the Hopf point {axis.name} = {h.p0:.10g} is at the end of the range "
                             f"({axis.start:g}, {axis.stop:g}); extend it past the onset")
    z_far = math.sqrt(ratio * dist)
    amp_far = 2 * np.abs(phi) * z_far
    scale = np.maximum(amp_far, 1e-9 * float(np.max(amp_far)))
    ref = int(np.argmax(np.abs(phi[:n]) / scale[:n]))
    phi = phi * (abs(phi[ref]) / phi[ref])  # the reference's first harmonic a cosine: b_1 = 0
    coords = tuple(cm.coords) + tuple(cm.algebraic)
    pads = tuple(p.name for p in space.resolve({}).model.pads)
    bal = _Balance(space, axis.name, sim, harmonics, ref, scale)
    if shooting_check:
        bal.check = shooting_flow(engine, space, axis, coords, use_cache)
    cont = _Continuation(bal, h.omega0, dist, tol)
    rtol_ = harmonic_tol if residual_tol is None else float(residual_tol)
    met = [True]  # whether the last adapt() met every tolerance
    why = [""]
    K = bal.K

    def pack(C: np.ndarray, omega: float, p: float) -> np.ndarray:
        return np.concatenate([C.ravel(), [omega, p]])

    def resized(y: np.ndarray, Hold: int, Hnew: int) -> np.ndarray:
        C, w, p = y[:-2].reshape(bal.N, 2 * Hold + 1), y[-2], y[-1]
        Cn = np.zeros((bal.N, 2 * Hnew + 1))
        k = min(Hold, Hnew)
        Cn[:, :2 * k + 1] = C[:, :2 * k + 1]
        return pack(Cn, w, p)

    # the first orbit: the normal form's prediction, corrected at its first-harmonic amplitude of `ref`
    p1 = h.p0 + h.side * start_offset * dist
    z1 = math.sqrt(ratio * abs(p1 - h.p0))
    sm1 = _Point(space, sim, axis.name, p1).sm
    C = np.zeros((bal.N, K))
    C[:, 0] = np.concatenate([sm1.q0, sm1.l0])
    C[:, 1], C[:, 2] = 2 * z1 * phi.real, -2 * z1 * phi.imag
    omega1 = h.omega0 + h.frequency_slope * (p1 - h.p0)
    A1 = float(C[ref, 1])

    def amp_eq(y: np.ndarray) -> tuple[float, np.ndarray]:
        g = np.zeros(y.size)
        g[ref * bal.K + 1] = 1.0 / scale[ref]
        return (y[ref * bal.K + 1] - A1) / scale[ref], g

    y, _ = cont.newton(pack(C, omega1, p1), amp_eq)

    def fixed_p(pv: float) -> Any:
        def eq(yy: np.ndarray) -> tuple[float, np.ndarray]:
            g = np.zeros(yy.size)
            g[-1] = 1.0 / dist
            return (yy[-1] - pv) / dist, g
        return eq

    def adapt(y: np.ndarray, extra: Any) -> tuple[np.ndarray, float]:
        """Raise the harmonics until the truncation error, the off-grid residual and (where the pads allow
        shooting) the shooting mismatch meet their tolerances (re-solving).  The mismatch's tolerance is at least
        ``1e3`` times the flow's ``rtol`` (its integration floor), and a mismatch that more harmonics do not halve
        is accepted (the floor, e.g. an unstable orbit amplifying the integration error)."""
        prev_mis = math.inf
        while True:
            Cy, wy, py = bal.unpack(y)
            err = _truncation(Cy, scale, bal.H)
            why[0] = f"the truncation error {err:.3g} exceeds harmonic_tol = {harmonic_tol:g}"
            ok = err <= harmonic_tol
            if ok:
                res = _fine_residual(bal, Cy, wy, py)[0]
                ok = res <= rtol_
                why[0] = f"the residual {res:.3g} exceeds residual_tol = {rtol_:g}"
            if ok and bal.check is not None:
                mis = bal.check.mismatch(Cy, wy, py)
                mtol = max(mismatch_tol, 1e3 * bal.check.rtol)
                ok = mis <= mtol or mis > 0.5 * prev_mis
                prev_mis = mis
                why[0] = f"the shooting mismatch {mis:.3g} exceeds {mtol:g} (mismatch_tol or 1e3 rtol)"
            met[0] = ok
            if ok or bal.H >= max_harmonics:
                return y, err
            Hold, Hnew = bal.H, min(max_harmonics, max(bal.H + 2, int(1.5 * bal.H)))
            bal.set_harmonics(Hnew)
            y, _ = cont.newton(resized(y, Hold, Hnew), extra)

    y, err = adapt(y, fixed_p(float(y[-1])))
    stop_tol = None if met[0] else why[0]

    def point(y: np.ndarray, err: float) -> HarmonicPoint:
        C, omega, p = bal.unpack(y)
        return _make_point(bal, sim, C, omega, p, err, coords, stability)

    tracker = _Progress(progress, max_points, h.p0, far)
    points: list[HarmonicPoint] = []

    def accept(P: HarmonicPoint) -> None:
        points.append(P)
        tracker.point(len(points), P.p)

    accept(point(y, err))
    status, message = "max_points", f"reached max_points = {max_points}"
    loss = rev = None
    t_prev: np.ndarray | None = None
    step = ds
    lo_p, hi_p = axis.start, axis.stop

    def indicators(P: HarmonicPoint) -> tuple[float, float]:
        return min(P.F_n_min), P.sliding_margin_min

    if stop_tol is not None:
        status = "truncation"
        message = f"{stop_tol} with max_harmonics = {max_harmonics} at the first orbit"

    while status == "max_points" and len(points) < max_points:
        t = cont.tangent(y, t_prev)
        if t_prev is None and len(points) == 1 and t[ref * bal.K + 1] < 0:  # away from the Hopf point
            t = -t
        s = cont.yscale()
        Hcur = bal.H
        try:
            y_pred = y + step * t * s

            def arc(yy: np.ndarray, _yp: np.ndarray = y_pred, _t: np.ndarray = t) -> tuple[float, np.ndarray]:
                return float(_t @ ((yy - _yp) / s)), _t / s

            y_new, its = cont.newton(y_pred, arc)
        except (BrakesquealError, ParameterError):
            step /= 2
            if step < 1e-6:
                status, message = "step_underflow", f"the step fell below 1e-6 at {axis.name} = {y[-1]:.10g}"
            continue
        p_new = float(y_new[-1])
        if not (lo_p <= p_new <= hi_p):  # the end of the range: the orbit there
            pe = hi_p if p_new > hi_p else lo_p
            frac = (pe - y[-1]) / (p_new - y[-1])
            y_new, _ = cont.newton(y + frac * (y_new - y), fixed_p(pe))
            y_new, err = adapt(y_new, fixed_p(pe))
            P = point(y_new, err)
            g_prev = indicators(points[-1])
            if all(v > 0 for v in indicators(P)) or not all(v > 0 for v in g_prev):
                accept(P)
                status, message = "range", f"reached the end of the range at {axis.name} = {pe:.10g}"
                break
        else:
            y_new, err = adapt(y_new, fixed_p(p_new))
            P = point(y_new, err)
        g_prev, g_new = indicators(points[-1]), indicators(P)
        events = [(i, nm) for i, nm in ((0, "contact_loss"), (1, "sliding_reversal"))
                  if g_prev[i] > 0 >= g_new[i]]
        if events:
            # the first event along the branch: locate each by Illinois on p between the two orbits
            found = []
            for i, nm in events:
                pv, Pe = _locate(bal, cont, sim, coords, points[-1], P, y, y_new, i, fixed_p, adapt, stability,
                                 tick=tracker.again)
                found.append((abs(pv - points[-1].p), pv, nm, Pe))
            found.sort(key=lambda r: r[0])
            ended = False
            for _, pv, nm, Pe in found:
                accept(Pe)
                if nm == "contact_loss":
                    loss = pv
                    if not stop_at_contact_loss:
                        continue  # recorded; the bilateral equations are continued
                    message = (f"a pad loses contact at {axis.name} = {pv:.10g}: the bilateral equations do not "
                               "hold beyond")
                else:
                    rev = pv
                    message = (f"a pad's sliding velocity reverses at {axis.name} = {pv:.10g}: Coulomb friction "
                               "would stick (end of the model's validity)")
                status, ended = nm, True
                break
            if ended:
                break
            K_new = (y_new.size - 2) // bal.N
            if K_new != bal.K:  # the location raised the harmonics: carry the new orbit over
                y_new = resized(y_new, (K_new - 1) // 2, bal.H)
        if bal.H == max_harmonics and not met[0]:
            accept(P)
            status = "truncation"
            message = f"{why[0]} with max_harmonics = {max_harmonics} at {axis.name} = {P.p:.10g}; raise max_harmonics"
            break
        accept(P)
        t_prev = t if bal.H == Hcur else _resize_vec(t, bal.N, 2 * Hcur + 1, bal.K)
        y = y_new
        if its <= 3:
            step = min(ds_max, 1.5 * step)
    if stability:
        points = [_with_verdict(pt, stability) for pt in _near_onset_verdicts(points, ex.hopf, coords)]
    tracker.done()
    return HarmonicBranch(axis.name, ex, tuple(points), status, message, loss, rev, coords, pads,
                          "Hill's method" if stability else "not computed")


def shooting_flow(engine: Engine, space: ParameterSpace, axis: Axis, coords: tuple[str, ...],
                  use_cache: bool) -> _ShootingCheck | None:
    """The simulated equations' flow where the pads allow shooting (no massless Coulomb pad the simulation would
    make quasi-static, :func:`~.models.soft_quasi_static_pads`) and their states are values or rates of the
    series; else ``None``.

    The result checks a harmonic-balance orbit by integration (its mismatch over one period and its monodromy)
    and converts its Fourier coefficients into the simulated state at ``t = 0`` (``.state(coefficients,
    omega)``), from which a shooting continuation can start (:mod:`brakesqueal.region.folds`).
    """
    from .models import model_system, soft_quasi_static_pads
    from .periodic import _make_flow

    if soft_quasi_static_pads(space, axis):
        return None
    system = model_system(engine, space, axis.name, use_cache=use_cache)
    try:
        return _ShootingCheck(system, coords, _make_flow(system, None))
    except KeyError:
        return None


def _near_onset_verdicts(points: list[HarmonicPoint], h: Any, coords: tuple[str, ...]) -> list[HarmonicPoint]:
    """Orbits whose Hill exponent near 0 has no reliable sign (:func:`hill_accuracy`) take the normal form's
    verdict where they are in its regime: the tilt amplitude within 5 % of ``a_j sqrt(|p - p0|)``.  There the
    radial exponent is ``-2 mu' (p - p0)`` with the sign of the criticality (supercritical: stable cycles) and
    the other exponents are those of the remaining modes, decided by Hill's method (all clearly negative)."""
    from dataclasses import replace

    names = list(h.state_names)
    ref = next((c for c in ("q1", "q2", *coords) if c in names and c in coords), None)
    if ref is None or h.criticality not in ("supercritical", "subcritical"):
        return points
    a = float(h.amplitude_coefficients[names.index(ref)])
    out = []
    for pt in points:
        if pt.stable is None and pt.floquet_exponents is not None and pt.trivial_exponent is not None and a > 0:
            pred = a * math.sqrt(abs(pt.p - h.p0))
            others = pt.floquet_exponents.real
            others = others[np.abs(others) > hill_accuracy(pt.omega, pt.trivial_exponent)]
            if pred > 0 and abs(pt.amplitude[ref] / pred - 1.0) <= 0.05 and np.all(others < 0):
                pt = replace(pt, stable=h.criticality == "supercritical", stability_from="normal form")
        out.append(pt)
    return out


def _resize_vec(v: np.ndarray, N: int, Kold: int, Knew: int) -> np.ndarray:
    """A vector ``(C, omega, p)`` with ``C`` cut or padded with zeros from ``Kold`` to ``Knew`` columns."""
    C = v[:-2].reshape(N, Kold)
    Cn = np.zeros((N, Knew))
    k = min(Kold, Knew)
    Cn[:, :k] = C[:, :k]
    return np.concatenate([Cn.ravel(), v[-2:]])


def _truncation(C: np.ndarray, scale: np.ndarray, H: int) -> float:
    """Largest of the two highest harmonics relative to the first, per coordinate in its own scale."""
    first = np.hypot(C[:, 1], C[:, 2])
    hi = [np.hypot(C[:, 2 * k - 1], C[:, 2 * k]) for k in range(max(1, H - 1), H + 1)]
    top = np.max(np.array(hi), axis=0)
    den = np.maximum(first, 1e-3 * float(np.max(first / scale)) * scale)
    if H == 1:  # no harmonic above the first: nothing to estimate from
        return 1.0
    return float(np.max(top / np.maximum(den, 1e-300)))


class _ShootingCheck:
    """The simulated equations' flow from a harmonic-balance orbit's state at ``t = 0`` (where the pads allow
    shooting): the shooting mismatch over one period and the monodromy's verdict."""

    def __init__(self, system: Any, coords: tuple[str, ...], flow: Any) -> None:
        self.system, self.flow = system, flow
        cols: list[tuple[int, int]] = []
        for nm in system.state_names:  # Q, dQ, the dynamic pads' L: values or rates of the series
            if nm in coords:
                cols.append((coords.index(nm), 0))
            elif nm.startswith("d") and nm[1:] in coords:
                cols.append((coords.index(nm[1:]), 1))
            else:
                raise KeyError(nm)
        self.cols = cols
        rt = getattr(flow, "rtol", None)
        self.rtol = float(rt) if isinstance(rt, (int, float)) else 1e-11

    def state(self, C: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """The state at ``t = 0`` and a per-state scale (half its range over the period, floored)."""
        H = (C.shape[1] - 1) // 2
        th = 2 * np.pi * np.arange(64) / 64
        U, Ud = _basis(th, H, 0) @ C.T, omega * (_basis(th, H, 1) @ C.T)
        X = np.column_stack([(U if d == 0 else Ud)[:, i] for i, d in self.cols])
        half = 0.5 * (X.max(axis=0) - X.min(axis=0))
        top = float(np.max(half)) if half.size and np.max(half) > 0 else 1.0
        return X[0].copy(), np.maximum(half, 1e-6 * top)

    def mismatch(self, C: np.ndarray, omega: float, p: float) -> float:
        """``max |phi(x0, T) - x0| / scale`` (``inf`` if the flow fails)."""
        from .flow import FlowError

        x0, sc = self.state(C, omega)
        try:
            fr = self.flow(x0, 2 * np.pi / omega, p, sensitivities=False, scale=sc)
        except FlowError:
            return math.inf
        return float(np.max(np.abs(fr.x - x0) / sc))

    def verdict(self, C: np.ndarray, omega: float, p: float) -> tuple[float, np.ndarray | None, str | None]:
        """``(mismatch, non-trivial multipliers, verdict)``; the accuracy bound includes ``10 mismatch``."""
        from .floquet import multiplier_accuracy, stability_verdict
        from .flow import FlowError
        from .periodic import ShootingError, floquet_multipliers

        x0, sc = self.state(C, omega)
        try:
            fr = self.flow(x0, 2 * np.pi / omega, p, sensitivities=True, scale=sc)
            _, red, terr = floquet_multipliers(fr.monodromy, self.system.rhs(x0, p))
        except (FlowError, ShootingError):
            return math.inf, None, None
        mis = float(np.max(np.abs(fr.x - x0) / sc))
        acc = max(multiplier_accuracy(terr, getattr(self.flow, "rtol", None), method=fr.monodromy_method),
                  10 * mis)
        return mis, red, stability_verdict(red, acc)


def _fine_residual(bal: _Balance, C: np.ndarray, omega: float, p: float) -> tuple[float, list[np.ndarray], int]:
    """The largest residual of the truncated series in the equations at 10x more (off-grid) phases than the
    collocation grid, relative to the linear terms' magnitude; with the states there and their number."""
    n = bal.n
    H = (C.shape[1] - 1) // 2
    Mf = 10 * (4 * H + 4)
    thf = 2 * np.pi * (np.arange(Mf) + 0.5) / Mf
    Ef = [_basis(thf, H, k) for k in range(3)]
    r = bal.residual_time(C, omega, p, Ef)
    x = bal.states(C, omega, Ef)
    J0 = bal.jac_time(C, omega, p, [e[:1] for e in Ef])[:, :, 0]
    amp = np.hypot(C[:, 1], C[:, 2])
    a = np.maximum(amp, 1e-6 * bal.scale)  # a coordinate that does not move (rigid pads: L = 0) keeps a scale
    xs = np.concatenate([a[:n], omega * a[:n], omega * omega * a[:n], a[n:], omega * a[n:]])
    rowscale = np.abs(J0) @ xs
    rowscale[rowscale == 0] = 1.0
    return float(np.max(np.abs(r) / rowscale[:, None])), x, Mf


def _with_verdict(pt: HarmonicPoint, stability: bool) -> HarmonicPoint:
    """``pt`` with its Hill verdict (from ``stable``) and the cross-checked verdict."""
    from dataclasses import replace

    from .floquet import cross_check

    hv = None if not stability else ("undecided" if pt.stable is None else "stable" if pt.stable else "unstable")
    return replace(pt, hill_verdict=hv, verdict=cross_check(hv, pt.monodromy_verdict))


def _make_point(bal: _Balance, sim: SimulationModel, C: np.ndarray, omega: float, p: float, err: float,
                coords: tuple[str, ...], stability: bool) -> HarmonicPoint:
    cm, n = bal.cm, bal.n
    H = bal.H
    # fine grid (10x the collocation grid), off-grid by half a step, for the residual check
    resid, x, Mf = _fine_residual(bal, C, omega, p)
    pv = bal.pvec(p)
    amp = np.hypot(C[:, 1], C[:, 2])
    ct = cm.vectorized.contact(x, pv)
    npad = len(ct) // 7
    ct = np.array([np.broadcast_to(np.asarray(v, dtype=float), (Mf,)) for v in ct]).reshape(npad, 7, Mf)
    # the silent motion's sliding velocity: the contact at the orbit's mean (Qdot = 0) is not it; take
    # the silent motion at p
    from ..analysis.equilibrium import silent_motion

    sm = silent_motion(sim.engine, bal.space.resolve({bal.name: p}))
    x0 = np.asarray(sm.state(), dtype=float)
    vr0 = cm.contact_table(x0, pv)[:, 1:4]
    slide = np.einsum("pkt,pk->pt", ct[:, 1:4, :], vr0 / np.linalg.norm(vr0, axis=1)[:, None])
    fmin = tuple(float(v) for v in _pmin(ct[:, 0, :]))
    fmax = tuple(float(-v) for v in _pmin(-ct[:, 0, :]))
    smin = float(np.min(_pmin(slide)))
    tilts = [i for i, c in enumerate(coords[:n]) if c in ("q1", "q2")]
    tilt = float(max(amp[i] for i in tilts)) if tilts else None
    ampd = {c: float(a) for c, a in zip(coords, amp)}
    fl = st = tr = None
    terr = None
    if stability:
        fl, st, tr = _hill(bal, C, omega, p)
        terr = float(abs(math.expm1(tr * 2 * math.pi / omega)))
    mis = red = mv = None
    if bal.check is not None:
        mis, red, mv = bal.check.verdict(C, omega, p)
    pt = HarmonicPoint(float(p), float(omega), float(omega / (2 * np.pi)), ampd, tilt, fmin, smin, resid,
                       float(err), H, C.copy(), fl, st, tr, None if st is None else "Hill's method", fmax,
                       trivial_multiplier_error=terr, monodromy_verdict=mv, multipliers=red, shooting_mismatch=mis)
    return _with_verdict(pt, stability)


def _pmin(v: np.ndarray) -> np.ndarray:
    """Smallest value over the periodic last axis, refined by a parabola through the smallest sample."""
    k = np.argmin(v, axis=-1)
    rows = np.arange(v.shape[0])
    Mv = v.shape[-1]
    y0, ym, yp = v[rows, k], v[rows, (k - 1) % Mv], v[rows, (k + 1) % Mv]
    curv = ym - 2 * y0 + yp
    with np.errstate(divide="ignore", invalid="ignore"):
        fine = y0 - (yp - ym) ** 2 / (8 * curv)
    return np.where(curv > 0, np.minimum(fine, y0), y0)


def pad_mode_rates(J: np.ndarray, n: int, m: int) -> np.ndarray:
    """Floquet exponent of every pad's own first-order mode, from the frozen coefficients (a fast scalar mode).

    Where a pad's rate enters its balance, ``G_L l + G_Ldot ldot + ... = 0`` gives the mode ``ldot = a(t) l``,
    ``a = -G_L / G_Ldot``, much faster than the orbit; the exponent of ``x' = a(t) x`` over a period is the mean
    of ``a``.  Phases where ``G_Ldot = 0`` (the rate does not enter: no mode there) are left out.

    Parameters
    ----------
    J : ndarray, shape (n + m, 3 n + 2 m, phases)
        Jacobian of the residuals ``(R, G)`` in ``(Q, Qdot, Qddot, L, Ldot)`` at equally spaced phases.
    n, m : int
        Numbers of coordinates and of pad unknowns.

    Returns
    -------
    ndarray, shape (m,)
        Mean ``-G_L / G_Ldot`` per pad (0 where the rate never enters).
    """
    out = np.zeros(m)
    for j in range(m):
        GL, GdL = J[n + j, 3 * n + j, :], J[n + j, 3 * n + m + j, :]
        live = GdL != 0.0
        if live.any():
            out[j] = float(np.mean(-GL[live] / GdL[live]))
    return out


def _hill(bal: _Balance, C: np.ndarray, omega: float, p: float) -> tuple[np.ndarray, bool | None, float]:
    """Floquet exponents by Hill's method: the quadratic eigenproblem of the periodic pencil in the Fourier basis."""
    n, m, N, H = bal.n, bal.m, bal.N, bal.H
    Mt = 4 * H + 4
    th = 2 * np.pi * np.arange(Mt) / Mt
    E = [_basis(th, H, k) for k in range(3)]
    J = bal.jac_time(C, omega, p, E)
    lam, V = hill_pencil_eigen(J, n, m, H, omega)
    ks = np.arange(-H, H + 1)
    ok = np.isfinite(lam) & (np.abs(lam) < 1e3 * omega * H)
    lam, V = lam[ok], V[:, :, ok]
    # one exponent per state (Q, Qdot) of the mechanical DOF: the copies with the most centred eigenvectors
    Vr = V.reshape(N, ks.size, -1)
    w = (np.abs(Vr) ** 2).sum(axis=0)
    w /= w.sum(axis=0, keepdims=True)
    centre = np.abs((ks[:, None] * w).sum(axis=0))  # |mean k| of the eigenvector: 0 for the centred copy
    order = np.argsort(centre)
    strip = lam - 1j * omega * np.round(lam.imag / omega)  # the exponent in the strip |Im| <= omega/2
    # the mechanical states (Q, Qdot): exponents within the band the harmonics resolve (|lambda| <= H omega / 2);
    # a pad whose rate enters its balance on the orbit adds a fast mode (rate ~ G_L / G_Ldot, far beyond it)
    nstate = 2 * n
    acc: list[int] = []
    for j in order:
        if abs(lam[j]) > 0.5 * H * omega:
            continue
        dup = False
        for i in acc:  # a copy lambda + i k omega of an accepted exponent: the same eigenvector shifted by k
            if abs(strip[j] - strip[i]) > 1e-6 * omega:
                continue
            s = int(round((lam[j] - lam[i]).imag / omega))
            if s == 0:  # two eigenvalues in the same copy of the strip are distinct exponents, not copies (the
                continue  # trivial and the radial exponent near a Hopf point have nearly parallel eigenvectors)
            a, b = Vr[:, :, i], Vr[:, :, j]
            if abs(s) < ks.size:
                a = np.roll(a, -s, axis=1)
            cos = abs(np.vdot(a, b)) / (np.linalg.norm(a) * np.linalg.norm(b))
            if cos > 0.9:
                dup = True
                break
        if not dup:
            acc.append(int(j))
        if len(acc) == nstate:
            break
    chosen = strip[acc]
    j0 = int(np.argmin(np.abs(chosen)))
    trivial = float(abs(chosen[j0]))
    rest = np.delete(chosen, j0)
    rest = rest[np.argsort(-rest.real)]
    # the pads' own fast modes are outside the band: an unstable one (e.g. falling friction) makes the orbit
    # unstable whatever the band says; too few exponents in the band: no verdict.  Only pads with a
    # rate-dependent law are judged: a Coulomb pad's dG/dldot = c dF/dldot >= 0 (the friction force is monotone
    # in the sliding velocity), its mode is stable, and near w = 0 its dG/dldot is at rounding level (any sign)
    judged = np.array([k == "dynamic" for k in bal.sim.pad_kinds], dtype=bool)
    if judged.size == m and np.any(pad_mode_rates(J, n, m)[judged] > 0):
        return rest, False, trivial
    delta = hill_accuracy(omega, trivial)
    if np.any(rest.real > delta):
        return rest, False, trivial  # an exponent clearly in the right half-plane
    if len(acc) < nstate or np.any(np.abs(rest.real) <= delta):
        return rest, None, trivial  # an exponent missing or within the method's accuracy of 0: no verdict here
    return rest, True, trivial


def hill_pencil_eigen(J: np.ndarray, n: int, m: int, H: int, omega: float) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and eigenvectors of Hill's pencil of a periodic orbit of the implicit equations.

    ``u = e^{lambda t} sum_k c_k e^{i k omega t}`` in the linearized residual ``r_Q u_Q + r_Qdot u_Q' + r_Qddot
    u_Q'' + r_L u_L + r_Ldot u_L' = 0`` (Galerkin on ``2H + 1`` harmonics, ``4H + 4`` equally spaced phases):
    ``(A0 + lambda A1 + lambda^2 A2) c = 0``.  Solved in the real Fourier basis as the real generalized
    eigenproblem of the linearization ``x = (c, lambda c_Q)`` (``A2`` acts on ``Q`` only, so the pads' ``L``
    need no second block): size ``(2n + m)(2H + 1)``, about 10x cheaper than the complex companion form of
    size ``2(n + m)(2H + 1)`` with the same finite eigenvalues (``tests/nonlinear/test_nl_cycle_route.py``).

    Parameters
    ----------
    J : ndarray
        ``(n + m, 3n + 2m, 4H + 4)``: the Jacobian columns ``r_Q, r_Qdot, r_Qddot, r_L, r_Ldot`` at the phases
        ``2 pi j / (4H + 4)``.
    n, m, H : int
        Coordinates, pad unknowns and harmonics.
    omega : float
        The orbit's angular frequency.

    Returns
    -------
    lam : ndarray
        Eigenvalues (``inf`` where the pencil is singular).
    V : ndarray
        ``(n + m, 2H + 1, len(lam))``: each eigenvector's coefficients on ``e^{i k theta}``, ``k = -H..H``.
    """
    from ._lapack import eig_pencil

    N, K = n + m, 2 * H + 1
    Mt = J.shape[-1]
    th = 2 * np.pi * np.arange(Mt) / Mt
    Phi = [_basis(th, H, d) * omega**d for d in range(3)]  # (Mt, K): d^d/dt^d of the real basis
    w = np.full(K, 2.0 / Mt)
    w[0] = 1.0 / Mt
    P = (Phi[0] * w[None, :]).T  # (K, Mt): the discrete Fourier projection on the same basis
    JQ, JdQ, JddQ = J[:, :n], J[:, n:2 * n], J[:, 2 * n:3 * n]
    JL, JdL = J[:, 3 * n:3 * n + m], J[:, 3 * n + m:]
    B0 = np.concatenate([JQ, JL], axis=1)
    B1 = np.concatenate([JdQ, JdL], axis=1)

    def op(B: np.ndarray, F: np.ndarray) -> np.ndarray:
        return _project(P, B, F).reshape(B.shape[0] * K, B.shape[1] * K)

    S, SQ = N * K, n * K
    A0 = op(B0, Phi[0]) + op(B1, Phi[1])
    A1 = op(B1, Phi[0])
    A0[:, :SQ] += op(JddQ, Phi[2])
    A1[:, :SQ] += 2 * op(JddQ, Phi[1])
    A2Q = op(JddQ, Phi[0])
    Lm = np.zeros((S + SQ, S + SQ))
    Rm = np.zeros((S + SQ, S + SQ))
    Lm[:S, :S] = -A0
    Rm[:S, :S] = A1
    Rm[:S, S:] = A2Q
    Lm[S:, S:] = np.eye(SQ)
    Rm[S:, :SQ] = np.eye(SQ)
    lam, X = eig_pencil(Lm, Rm)  # scipy.linalg.eig's dggev without holding the interpreter lock (Ctrl-C)
    Xr = X[:S].reshape(N, K, -1)  # real-basis coefficients (c0, a1, b1, ..., aH, bH) of each eigenvector
    V = np.zeros((N, K, lam.size), dtype=complex)  # on e^{i k theta}, k = -H..H (index k + H)
    V[:, H] = Xr[:, 0]
    a, b = Xr[:, 1::2], Xr[:, 2::2]
    V[:, H + 1:] = 0.5 * (a - 1j * b)
    V[:, :H][:, ::-1] = 0.5 * (a + 1j * b)
    return lam, V


def hill_accuracy(omega: float, trivial: float) -> float:
    """Below this ``|Re lambda|`` an exponent of Hill's method has no reliable sign.

    ``max(1e3 |trivial|, 1e-6 omega)``: the trivial exponent (exactly 0) as computed measures the rounding, and
    the small exponents of a truncated Hill matrix carry errors of about ``1e-7..1e-6 omega`` (seen as imaginary
    parts of real exponents near a Hopf point, where the radial exponent ``-2 mu' (p - p0)`` is that small).
    """
    return max(1e3 * abs(trivial), 1e-6 * abs(omega))


def _locate(bal: _Balance, cont: _Continuation, sim: SimulationModel, coords: tuple[str, ...], Pa: HarmonicPoint,
            Pb: HarmonicPoint, ya: np.ndarray, yb: np.ndarray, which: int, fixed_p: Any, adapt: Any,
            stability: bool, tick: Callable[[], None] | None = None) -> tuple[float, HarmonicPoint]:
    """Where indicator ``which`` (0: smallest F_n, 1: sliding margin) reaches 0 between two orbits (Illinois).

    ``tick()`` is called before each orbit (whatever it raises propagates: the explorer's Cancel).
    """
    def g(P: HarmonicPoint) -> float:
        return min(P.F_n_min) if which == 0 else P.sliding_margin_min

    def resize(y: np.ndarray) -> np.ndarray:
        K_old = (y.size - 2) // bal.N
        if K_old == bal.K:
            return y
        C = y[:-2].reshape(bal.N, K_old)
        Cn = np.zeros((bal.N, bal.K))
        k = min(K_old, bal.K)
        Cn[:, :k] = C[:, :k]
        return np.concatenate([Cn.ravel(), y[-2:]])

    pa, pb, ga, gb = Pa.p, Pb.p, g(Pa), g(Pb)
    ya, yb = resize(ya), resize(yb)
    side = 0
    best = (pb, Pb)
    for _ in range(60):
        if tick is not None:
            tick()
        pc = pb - gb * (pb - pa) / (gb - ga) if gb != ga else 0.5 * (pa + pb)
        fr = (pc - pa) / (pb - pa) if pb != pa else 0.5
        yc, _ = cont.newton(resize(ya) + fr * (resize(yb) - resize(ya)), fixed_p(pc))
        yc, err = adapt(yc, fixed_p(pc))
        C, w, p = bal.unpack(yc)
        Pc = _make_point(bal, sim, C, w, p, err, coords, stability)
        gc = g(Pc)
        best = (pc, Pc)
        if abs(gc) <= 1e-10 * max(abs(ga), abs(gb)) or abs(pb - pa) <= 1e-11 * max(1.0, abs(pc)):
            break
        if (gc > 0) == (ga > 0):
            pa, ga, ya = pc, gc, yc
            if side == -1:
                gb /= 2
            side = -1
        else:
            pb, gb, yb = pc, gc, yc
            if side == 1:
                ga /= 2
            side = 1
    return best
