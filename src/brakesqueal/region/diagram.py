"""The squeal region diagram in two parameters: every Hopf curve in a box, with the certified stability map.

:func:`hopf_curves` seeds the curves at the exact stability crossings
(:func:`~brakesqueal.analysis.crossings.crossings`) along ``y`` at a few ``x``
values and along ``x`` at a few ``y`` values, continues each curve through a
seed not yet on a computed curve (:func:`~.curves.continue_hopf_curve`), and
skips crossings of a real eigenvalue (static divergence, not Hopf).
:func:`region_diagram` adds the certified linear stability map with its refined
boundary (:func:`~brakesqueal.analysis.maps.stability_map`) and returns a
:class:`RegionResult` (JSON, text, xarray/NetCDF, figure).

Fold-of-cycles curves (issue 28 item 2) are not computed: the region where
squeal is possible although the silent motion is linearly stable (between the
fold-of-cycles curve and a subcritical Hopf curve) is not shaded, and the
results say so (``fold_of_cycles = "not computed"``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..validation import Range, validated
from .curves import SPECIAL_TYPES, HopfCurve, continue_hopf_curve

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    import xarray as xr

    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..results import StabilityMap

__all__ = ["RegionResult", "hopf_curves", "region_diagram", "FOLD_OF_CYCLES"]

#: What the results say about fold-of-cycles curves (issue 28 item 2, not built).
FOLD_OF_CYCLES = "not computed"
_NOT_SHADED = ("squeal possible although linearly stable: not shaded (needs the fold-of-cycles curves, not "
               "computed)")


def _check(engine: Engine, space: ParameterSpace, x: Axis, y: Axis) -> None:
    """The one place that refuses bad axes and models without nonlinear equations (one-line messages)."""
    if x.name == y.name:
        raise ParameterError(f"The options --x and --y must vary two different parameters; got {x.name!r} for both",
                             parameter="--y")
    for ax, opt in ((x, "--x"), (y, "--y")):
        try:
            space.check_axis(ax.name)
        except ParameterError as exc:
            raise ParameterError(f"{opt}: {exc}", parameter=opt) from None
    try:
        engine.require_nonlinear("region (Hopf curves with l1)")
    except ParameterError as exc:
        raise ParameterError(f"--model: {exc}", parameter="--model") from None


def _seeds(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, n: int) -> list[tuple[float, float]]:
    from ..analysis.crossings import crossings
    from ..analysis.maps import Axis as _Axis

    out: list[tuple[float, float]] = []
    for outer, inner, swap in ((x, y, False), (y, x, True)):
        for k in range(n):
            f = (k + 0.5) / n
            v = (10 ** (math.log10(outer.start) + f * (math.log10(outer.stop) - math.log10(outer.start)))
                 if outer.log else outer.start + f * (outer.stop - outer.start))
            try:
                r = crossings(engine, space.with_values({outer.name: v}),
                              _Axis(inner.name, inner.start, inner.stop, 2, inner.log))
            except (BrakesquealError, ValueError):
                continue
            for value, _direction in r.crossings:
                out.append((float(value), v) if swap else (v, float(value)))
    return out


def _unit(ax: Axis, v: float) -> float:
    if ax.log:
        return (math.log10(v) - math.log10(ax.start)) / (math.log10(ax.stop) - math.log10(ax.start))
    return (v - ax.start) / (ax.stop - ax.start)


def _covered(curves: list[HopfCurve], x: Axis, y: Axis, seed: tuple[float, float], omega: float) -> bool:
    s = np.array([_unit(x, seed[0]), _unit(y, seed[1])])
    for c in curves:
        u = np.array([[_unit(x, p.x), _unit(y, p.y)] for p in c.points])
        w = np.array([p.omega for p in c.points])
        if len(u) == 1:
            d = np.linalg.norm(u - s, axis=1)
            if d[0] < 1e-3 and abs(w[0] - omega) <= 0.02 * abs(omega):
                return True
            continue
        a, b = u[:-1], u[1:]
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", s - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        d = np.linalg.norm(a + t[:, None] * ab - s, axis=1)
        wi = w[:-1] + t * (w[1:] - w[:-1])
        # within the chords' sagitta (steps <= 0.05 of the box) and at the interpolated frequency
        if np.any((d < 1e-2) & (np.abs(wi - omega) <= 0.05 * abs(omega))):
            return True
    return False


def _critical(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, seed: tuple[float, float]
              ) -> complex | None:
    """The eigenvalue nearest the imaginary axis at a seed, or None if it is real (static divergence)."""
    from ..analysis.linear import linearize

    try:
        lm = linearize(engine, space.resolve({x.name: seed[0], y.name: seed[1]}))
        try:
            lams = np.linalg.eigvals(lm.A)
        except np.linalg.LinAlgError:
            lams = np.asarray(lm.eigenvalues)
    except (BrakesquealError, ValueError):
        return None
    lam = complex(lams[np.argmin(np.abs(lams.real))])
    if abs(lam.imag) <= 1e-9 * max(float(np.max(np.abs(lams))), 1e-300):
        return None
    return complex(lam.real, abs(lam.imag))


def _hopf_curves(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, *, seeds: int, max_points: int,
                 ds_max: float, lyapunov: bool, use_cache: bool) -> tuple[list[HopfCurve], list[str]]:
    _check(engine, space, x, y)
    curves: list[HopfCurve] = []
    notes: list[str] = []
    static = 0
    for seed in _seeds(engine, space, x, y, seeds):
        lam = _critical(engine, space, x, y, seed)
        if lam is None:
            static += 1
            continue
        if _covered(curves, x, y, seed, lam.imag):
            continue
        try:
            curves.append(continue_hopf_curve(engine, space, x, y, seed[0], seed[1], omega=lam.imag,
                                              ds_max=ds_max, max_points=max_points, lyapunov=lyapunov,
                                              use_cache=use_cache))
        except BrakesquealError as exc:
            notes.append(f"no Hopf curve through the crossing {x.name} = {seed[0]:.10g}, {y.name} = "
                         f"{seed[1]:.10g}: {exc}")
    if static:
        notes.append(f"{static} stability crossings of a real eigenvalue (static divergence, not Hopf) skipped")
    return curves, notes


@validated
def hopf_curves(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, *, seeds: Annotated[int, Range(1, 100)] = 5,
                max_points: Annotated[int, Range(2, 10000)] = 200,
                ds_max: Annotated[float, Range(1e-4, 0.5)] = 0.05, lyapunov: bool = True,
                use_cache: bool = True) -> list[HopfCurve]:
    """Every Hopf curve of the silent motion in the box of two settable parameters.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller: :func:`brakesqueal.engine`).
    space : ParameterSpace
        The model (with nonlinear equations), preset and overrides.
    x, y : Axis
        The two parameters and their ranges (``num`` is ignored; ``log`` scales the continuation).
    seeds : int
        Number of paths in each direction whose exact crossings seed the curves.
    max_points : int
        Largest number of points in each direction from a seed.
    ds_max : float
        Largest step, in units of the box (its sides scaled to 1).
    lyapunov : bool
        Compute ``l1`` at every point and locate generalised-Hopf points.
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    list of HopfCurve

    Raises
    ------
    ParameterError
        Equal, unknown or tied axes, or a model without nonlinear equations (one line naming the option).
    """
    curves, _notes = _hopf_curves(engine, space, x, y, seeds=seeds,
                                  max_points=max_points, ds_max=ds_max,
                                  lyapunov=lyapunov, use_cache=use_cache)
    return curves


@dataclass
class RegionResult:
    """The squeal region diagram of two parameters.

    Attributes
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        The axes.
    curves : list of HopfCurve
        The Hopf curves.
    stability_map : StabilityMap or None
        The certified linear stability map with its refined boundary.
    notes : list of str
        What was skipped and why.
    seconds : float
        Wall time of the computation.
    """

    space: ParameterSpace
    x: Axis
    y: Axis
    curves: list[HopfCurve]
    stability_map: StabilityMap | None
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def _units(self) -> tuple[str, str]:
        from ..labels import unit

        return unit(self.x.name, self.space), unit(self.y.name, self.space)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``hopf_curves`` (``points`` with both axis values by name, ``l1``, ``omega_hz``),
        ``special_points`` (``type`` and location by axis name), ``fold_of_cycles``."""
        xn, yn = self.x.name, self.y.name
        ux, uy = self._units()

        def num(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)

        curves, specials = [], []
        for i, c in enumerate(self.curves):
            pts = [{xn: p.x, yn: p.y, "l1": num(p.l1), "l1_error": num(p.l1_error), "criticality": p.criticality,
                    "omega_hz": p.omega_hz, "residual": p.residual, **({"message": p.message} if p.message else {})}
                   for p in c.points]
            sps = [{"type": s.type, xn: s.x, yn: s.y, "omega_hz": s.omega / (2 * math.pi), "curve": i,
                    "description": SPECIAL_TYPES[s.type], "detail": s.detail} for s in c.special_points]
            specials += sps
            curves.append({"points": pts, "special_points": sps, "ends": list(c.ends),
                           "criticality": sorted({p.criticality for p in c.points})})
        d: dict[str, Any] = {
            "space": self.space.label,
            "x": {"name": xn, "start": self.x.start, "stop": self.x.stop, "log": self.x.log, "unit": ux},
            "y": {"name": yn, "start": self.y.start, "stop": self.y.stop, "log": self.y.log, "unit": uy},
            "hopf_curves": curves,
            "special_points": specials,
            "fold_of_cycles": FOLD_OF_CYCLES,
            "shaded": _NOT_SHADED,
            "method": ("Hopf curves: pseudo-arclength continuation of Re lambda_c = 0 on the exact linearization "
                       "(every mode), seeded at the exact stability crossings; l1: exact_lyapunov (pads' true "
                       "rates, MatCont normalisation: l1 < 0 supercritical); codim-2 points located by bisection "
                       "on the curve"),
            "notes": list(self.notes),
            "seconds": self.seconds,
        }
        if self.stability_map is not None:
            ds = self.stability_map.data
            d["linear_stability_map"] = {"points": int(ds["stable"].size),
                                         "stable_fraction": float(np.mean(ds["stable"].values)),
                                         "method": str(ds.attrs.get("method", ""))}
        return d

    def text(self) -> str:
        """A summary for people."""
        xn, yn = self.x.name, self.y.name
        ux, uy = self._units()
        lines = [f"Hopf curves in ({xn}, {yn}) for {self.space.label}: {len(self.curves)} curve(s)"]
        for i, c in enumerate(self.curves):
            crit = ", ".join(sorted({p.criticality for p in c.points}))
            a, b = c.points[0], c.points[-1]
            lines.append(f"curve {i + 1}: {len(c.points)} points from {xn} = {a.x:.8g} {ux}, {yn} = {a.y:.8g} {uy} "
                         f"({c.ends[0]}) to {xn} = {b.x:.8g}, {yn} = {b.y:.8g} ({c.ends[1]}); {crit}; "
                         f"{min(p.omega_hz for p in c.points):.6g}-{max(p.omega_hz for p in c.points):.6g} Hz")
            for s in c.special_points:
                lines.append(f"  {s.type} ({SPECIAL_TYPES[s.type].split(':')[0]}) at {xn} = {s.x:.10g}, "
                             f"{yn} = {s.y:.10g}")
        if not any(c.special_points for c in self.curves):
            lines.append("no codimension-2 point (generalised Hopf, Bogdanov-Takens, zero-Hopf, double Hopf) found")
        lines.append(f"fold-of-cycles curves: {FOLD_OF_CYCLES}; {_NOT_SHADED}")
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines) + "\n"

    def to_dataset(self) -> xr.Dataset:
        """The curves as an :class:`xarray.Dataset` (dimension ``point``: every curve's points in order with
        ``curve`` their index; dimension ``special``: the codimension-2 points)."""
        import xarray as xr

        xn, yn = self.x.name, self.y.name
        ux, uy = self._units()
        rows = [(i, p) for i, c in enumerate(self.curves) for p in c.points]
        sps = [(i, s) for i, c in enumerate(self.curves) for s in c.special_points]

        def arr(vals: list[Any]) -> np.ndarray:
            return np.array([np.nan if v is None else v for v in vals], dtype=float)

        ds = xr.Dataset(
            {
                "curve": ("point", np.array([i for i, _ in rows], dtype=np.int32)),
                xn: ("point", arr([p.x for _, p in rows]), {"units": ux}),
                yn: ("point", arr([p.y for _, p in rows]), {"units": uy}),
                "l1": ("point", arr([p.l1 for _, p in rows]),
                       {"long_name": "first Lyapunov coefficient (pads' true rates; MatCont normalisation)"}),
                "l1_error": ("point", arr([p.l1_error for _, p in rows])),
                "frequency": ("point", arr([p.omega_hz for _, p in rows]), {"units": "Hz"}),
                "criticality": ("point", np.array([p.criticality for _, p in rows], dtype="S")),
                "special_type": ("special", np.array([s.type for _, s in sps], dtype="S")),
                "special_curve": ("special", np.array([i for i, _ in sps], dtype=np.int32)),
                f"special_{xn}": ("special", arr([s.x for _, s in sps]), {"units": ux}),
                f"special_{yn}": ("special", arr([s.y for _, s in sps]), {"units": uy}),
            },
            attrs={"space": self.space.label, "x": xn, "y": yn, "fold_of_cycles": FOLD_OF_CYCLES,
                   "shaded": _NOT_SHADED, "notes": "; ".join(self.notes)},
        )
        return ds

    def plot(self) -> Figure:
        """The region figure: the certified stability map and boundary, Hopf curves coloured by criticality
        (supercritical solid blue, subcritical dashed red), codimension-2 points marked."""
        from matplotlib.lines import Line2D

        from ..plotting import new_figure, plot_map, styled

        @styled
        def draw() -> Figure:
            fig, ax = new_figure(size=(4.2, 3.4))
            handles: list[Any] = []
            if self.stability_map is not None:
                plot_map(self.stability_map, ax, x=self.x.name, title="")
                leg = ax.get_legend()
                if leg is not None:
                    handles += list(leg.legend_handles)
            else:
                from ..labels import axis_label

                ux, uy = self._units()
                ax.set_xlabel(axis_label(self.x.name, ux))
                ax.set_ylabel(axis_label(self.y.name, uy))
                ax.set_xlim(self.x.start, self.x.stop)
                ax.set_ylim(self.y.start, self.y.stop)
            styles = {"supercritical": ("tab:blue", "-"), "subcritical": ("tab:red", "--"),
                      "degenerate": ("0.4", ":"), "unknown": ("0.4", ":")}
            seen: set[str] = set()
            for c in self.curves:
                xs, ys = c.arrays()
                crit = [p.criticality for p in c.points]
                for k in range(len(xs) - 1):
                    # a segment whose ends differ (a GH point inside) is drawn half in each style
                    xm, ym = 0.5 * (xs[k] + xs[k + 1]), 0.5 * (ys[k] + ys[k + 1])
                    halves = [((xs[k], xs[k + 1]), (ys[k], ys[k + 1]), crit[k])] if crit[k] == crit[k + 1] else \
                        [((xs[k], xm), (ys[k], ym), crit[k]), ((xm, xs[k + 1]), (ym, ys[k + 1]), crit[k + 1])]
                    for hx, hy, kind in halves:
                        col, ls = styles.get(kind, styles["unknown"])
                        ax.plot(hx, hy, color=col, ls=ls, lw=1.6)
                        seen.add(kind if kind in styles else "unknown")
            for kind in ("supercritical", "subcritical", "degenerate", "unknown"):
                if kind in seen:
                    col, ls = styles[kind]
                    handles.append(Line2D([], [], color=col, ls=ls, lw=1.6,
                                          label=f"Hopf, {kind}" if kind != "unknown" else "Hopf, l1 not computed"))
            markers = {"GH": "o", "BT": "s", "ZH": "^", "HH": "D"}
            for kind, mk in markers.items():
                pts = [s for c in self.curves for s in c.special_points if s.type == kind]
                if pts:
                    ax.plot([s.x for s in pts], [s.y for s in pts], mk, color="k", ms=5, mfc="w", zorder=5)
                    handles.append(Line2D([], [], marker=mk, color="k", mfc="w", ls="", label=kind))
            handles.append(Line2D([], [], ls="", label="fold of cycles: not computed (no hysteresis shading)"))
            ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False,
                      borderaxespad=0.0, handlelength=1.5, fontsize="x-small")
            return fig  # type: ignore[return-value]

        return draw()


@validated
def region_diagram(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, *, seeds: Annotated[int, Range(1, 100)] = 5,
           max_points: Annotated[int, Range(2, 10000)] = 200, ds_max: Annotated[float, Range(1e-4, 0.5)] = 0.05,
           grid: Annotated[int, Range(2, 2000)] | None = 41, lyapunov: bool = True,
           use_cache: bool = True) -> RegionResult:
    """The squeal region diagram: Hopf curves with ``l1`` and codimension-2 points, and the certified map.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller: :func:`brakesqueal.engine`).
    space : ParameterSpace
        The model (with nonlinear equations), preset and overrides.
    x, y : Axis
        The two parameters and their ranges (``num`` is ignored: ``grid`` sets the map).
    seeds : int
        Number of paths in each direction whose crossings seed the curves.
    max_points : int
        Largest number of points in each direction from a seed.
    ds_max : float
        Largest continuation step in units of the box.
    grid : int or None
        Points per axis of the certified linear stability map (``None``: no map).
    lyapunov : bool
        Compute ``l1`` along the curves.
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    RegionResult

    Raises
    ------
    ParameterError
        Equal, unknown or tied axes, or a model without nonlinear equations.
    """
    from ..analysis.maps import Axis as _Axis
    from ..analysis.maps import stability_map
    t0 = time.perf_counter()
    eng = engine
    curves, notes = _hopf_curves(eng, space, x, y, seeds=seeds, max_points=max_points, ds_max=ds_max,
                                 lyapunov=lyapunov, use_cache=use_cache)
    m = None
    if grid is not None:
        m = stability_map(eng, space, _Axis(x.name, x.start, x.stop, grid, x.log),
                          _Axis(y.name, y.start, y.stop, grid, y.log), boundary=True)
    return RegionResult(space, x, y, curves, m, notes, time.perf_counter() - t0)
