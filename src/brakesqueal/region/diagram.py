"""The squeal region diagram in two parameters: every Hopf curve in a box, with the certified stability map.

:func:`hopf_curves` seeds the curves at the exact stability crossings
(:func:`~brakesqueal.analysis.crossings.crossings`) along ``y`` at a few ``x``
values and along ``x`` at a few ``y`` values, continues each curve through a
seed not yet on a computed curve (:func:`~.curves.continue_hopf_curve`), and
skips crossings of a real eigenvalue (static divergence, not Hopf).
:func:`region_diagram` adds the certified linear stability map with its refined
boundary (:func:`~brakesqueal.analysis.maps.stability_map`) and returns a
:class:`RegionResult` (JSON, text, xarray/NetCDF, figure).

With ``folds=True`` (default) it also computes the fold-of-cycles curve born at
every generalised-Hopf point (:func:`~.folds.fold_curves`) and the regions it
bounds: "squeal possible although linearly stable" (between a fold-of-cycles
curve and its subcritical Hopf curve) and "contact lost" (between the subcritical
Hopf curve and the contact loss of its cycles, where the pads lose contact
before the branch folds).  With ``folds=False`` the results say
``fold_of_cycles = "not computed"``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from collections.abc import Callable
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..validation import Range, validated
from .curves import SPECIAL_TYPES, HopfCurve, continue_hopf_curve
from .folds import FOLD_KINDS, FoldCurve, fold_curves

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    import xarray as xr

    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..results import StabilityMap

__all__ = ["RegionResult", "hopf_curves", "region_diagram", "FOLD_OF_CYCLES", "REGIONS"]

#: What the results say about fold-of-cycles curves when they are not asked for (``folds=False``).
FOLD_OF_CYCLES = "not computed"
_NOT_SHADED = ("squeal possible although linearly stable: not shaded (needs the fold-of-cycles curves, not "
               "computed: --folds)")
_SHADED = ("squeal possible although linearly stable: shaded between each fold-of-cycles curve and its "
           "subcritical Hopf curve; contact lost: shaded between the subcritical Hopf curve and the contact loss "
           "of its cycles where the pads lose contact before the branch folds (the fold is not computed there)")
_NO_GH = "no generalised-Hopf point in the box: no fold-of-cycles curve, nothing shaded"
#: Names of the shaded regions (keys of ``regions`` in the JSON).
REGIONS = {"LPC": "squeal_possible_although_linearly_stable", "contact_loss": "contact_lost",
           "LPC_bilateral": "bilateral_equations_fold_band"}


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
    folds : list of FoldCurve or None
        The fold-of-cycles curves of the GH points (:func:`~.folds.fold_curves`); ``None``: not computed.
    """

    space: ParameterSpace
    x: Axis
    y: Axis
    curves: list[HopfCurve]
    stability_map: StabilityMap | None
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    folds: list[FoldCurve] | None = None

    @property
    def fold_status(self) -> str:
        """``"computed"`` or :data:`FOLD_OF_CYCLES` (``"not computed"``)."""
        return FOLD_OF_CYCLES if self.folds is None else "computed"

    @property
    def shaded(self) -> str:
        """What the figure shades (or why nothing)."""
        if self.folds is None:
            return _NOT_SHADED
        return _SHADED if self.folds else _NO_GH

    def regions(self) -> dict[str, list[list[tuple[float, float]]]]:
        """The shaded polygons ``[(x, y), ...]`` by region name (:data:`REGIONS`)."""
        return {name: [poly for f in (self.folds or []) for poly in f.regions(kind)]
                for kind, name in REGIONS.items()}

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
            "fold_of_cycles": self.fold_status,
            "fold_curves": [self._fold_dict(f) for f in (self.folds or [])],
            "regions": {k: [[{xn: a, yn: b} for a, b in poly] for poly in v] for k, v in self.regions().items()},
            "shaded": self.shaded,
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

    def _fold_dict(self, f: FoldCurve) -> dict[str, Any]:
        xn, yn = self.x.name, self.y.name
        pts = [{xn: p.x, yn: p.y, "kind": p.kind, "amplitude": p.amplitude, "period": p.period, "route": p.route,
                "contact_lost": p.contact_lost, "contact_loss": p.contact_loss, f"hopf_{f.along}": p.hopf,
                "description": FOLD_KINDS[p.kind],
                **({"message": p.message} if p.message else {})} for p in f.points]
        return {"curve": f.curve, "gh": {xn: f.gh[0], yn: f.gh[1]}, "along": f.along, "points": pts,
                "notes": list(f.notes),
                "method": (f"slices: at values of the other axis stepping away from the GH point, the cycle branch "
                           f"from the slice's subcritical Hopf point continued along {f.along} (the route of "
                           "`cycles`), its first fold before any contact loss, else its contact loss")}

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
        if self.folds is None:
            lines.append(f"fold-of-cycles curves: {FOLD_OF_CYCLES} (--folds computes them); {_NOT_SHADED}")
        elif not self.folds:
            lines.append(f"fold-of-cycles curves: {_NO_GH}")
        for f in self.folds or []:
            n_f = sum(p.kind == "LPC" for p in f.points)
            n_c = sum(p.kind in ("contact_loss", "LPC_bilateral") for p in f.points)
            n_b = sum(p.kind == "LPC_bilateral" for p in f.points)
            lines.append(f"fold-of-cycles curve from GH at {xn} = {f.gh[0]:.8g}, {yn} = {f.gh[1]:.8g} (branches along "
                         f"{f.along}): {n_f} fold(s), {n_c} slice(s) where contact is lost before the fold"
                         + (f" ({n_b} followed on to the fold of the bilateral equations)" if n_b else ""))
            for p in f.points[1:]:
                amp = max(p.amplitude.values(), default=float("nan"))
                what = {"LPC": "fold of cycles", "contact_loss": "contact lost (no fold before)",
                        "LPC_bilateral": f"fold of the bilateral equations (contact lost before it, at "
                                         f"{f.along} = {p.contact_loss:.10g})"}[p.kind]
                gap = abs((p.x if f.axis == "x" else p.y) - p.hopf)
                lines.append(f"  {what} at {xn} = {p.x:.10g}, {yn} = {p.y:.10g} ({gap:.3g} from the Hopf point "
                             f"{f.along} = {p.hopf:.10g}; amplitude {amp:.4g}, period {p.period:.6g} s; {p.route})")
        if self.folds is not None:
            lines.append(self.shaded)
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
            attrs={"space": self.space.label, "x": xn, "y": yn, "fold_of_cycles": self.fold_status,
                   "shaded": self.shaded, "notes": "; ".join(self.notes)},
        )
        fps = [(i, f, p) for i, f in enumerate(self.folds or []) for p in f.points]
        ds["fold_curve"] = ("fold_point", np.array([i for i, _, _ in fps], dtype=np.int32),
                            {"long_name": "index of the fold-of-cycles curve"})
        ds[f"fold_{xn}"] = ("fold_point", arr([p.x for _, _, p in fps]), {"units": ux})
        ds[f"fold_{yn}"] = ("fold_point", arr([p.y for _, _, p in fps]), {"units": uy})
        ds["fold_kind"] = ("fold_point", np.array([p.kind for _, _, p in fps], dtype="S"),
                           {"long_name": "GH, LPC (fold of cycles), contact_loss (contact lost before the fold) or "
                                         "LPC_bilateral (fold of the bilateral equations beyond the contact loss)"})
        ds["fold_hopf"] = ("fold_point", arr([p.hopf for _, _, p in fps]),
                           {"long_name": "the slice's subcritical Hopf point on the axis of fold_along"})
        ds["fold_along"] = ("fold_point", np.array([f.along for _, f, _ in fps], dtype="S"))
        ds["fold_amplitude"] = ("fold_point", arr([max(p.amplitude.values(), default=0.0) for _, _, p in fps]),
                                {"long_name": "largest first-harmonic amplitude of the displacement coordinates"})
        ds["fold_period"] = ("fold_point", arr([p.period for _, _, p in fps]), {"units": "s"})
        ds["fold_route"] = ("fold_point", np.array([p.route for _, _, p in fps], dtype="S"))
        ds["fold_contact_lost"] = ("fold_point", np.array([p.contact_lost for _, _, p in fps], dtype=np.int8))
        ds["fold_contact_loss"] = ("fold_point", arr([math.nan if p.contact_loss is None else p.contact_loss
                                                      for _, _, p in fps]),
                                   {"long_name": "where the slice's cycles lose contact, on the axis of fold_along "
                                                 "(NaN: they do not before the point)"})
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
            if self.folds is None:
                handles.append(Line2D([], [], ls="", label="fold of cycles: not computed (--folds)"))
            elif not self.folds:
                handles.append(Line2D([], [], ls="", label="fold of cycles: no GH point in the box"))
            else:
                from matplotlib.patches import Patch

                # the bilateral folds are drawn as a line only: their band interpolates between slices whose
                # first folds need not lie on one curve (it would bulge past the folds between far-apart slices)
                fills = {"LPC": ("tab:orange", "squeal possible although linearly stable"),
                         "contact_loss": ("tab:purple", "contact lost (before the fold)")}
                for kind, (col, label) in fills.items():
                    polys = [poly for f in self.folds for poly in f.regions(kind)]
                    for poly in polys:
                        ax.fill([a for a, _ in poly], [b for _, b in poly], color=col, alpha=0.35, lw=0.8,
                                ec=col, zorder=3)
                    if polys:
                        handles.append(Patch(fc=col, ec=col, alpha=0.35, label=label))
                drawn = set()
                for f in self.folds:
                    lpc = [p for p in f.points if p.kind in ("GH", "LPC")]
                    if len(lpc) > 1:
                        ax.plot([p.x for p in lpc], [p.y for p in lpc], color="tab:green", lw=1.6, zorder=4)
                        drawn.add("LPC")
                    bl = [p for p in f.points if p.kind in ("GH", "LPC_bilateral")]
                    if len(bl) > 1:
                        ax.plot([p.x for p in bl], [p.y for p in bl], color="tab:gray", lw=1.2, ls="--", zorder=4)
                        drawn.add("LPCB")
                    cl = [p for p in f.points if p.kind == "contact_loss"]
                    if cl:
                        ax.plot([p.x for p in cl], [p.y for p in cl], "x", color="tab:purple", ms=4, zorder=4)
                        drawn.add("CL")
                if "LPC" in drawn:
                    handles.append(Line2D([], [], color="tab:green", lw=1.6, label="fold of cycles"))
                if "LPCB" in drawn:
                    handles.append(Line2D([], [], color="tab:gray", lw=1.2, ls="--",
                                          label="fold of the bilateral equations (beyond contact loss)"))
                if "CL" in drawn:
                    handles.append(Line2D([], [], color="tab:purple", marker="x", ls="", ms=4,
                                          label="contact loss of the cycles (no fold before)"))
                if not drawn:
                    handles.append(Line2D([], [], ls="", label="fold of cycles: no slice converged"))
            ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False,
                      borderaxespad=0.0, handlelength=1.5, fontsize="x-small")
            return fig  # type: ignore[return-value]

        return draw()


@validated
def region_diagram(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, *, seeds: Annotated[int, Range(1, 100)] = 5,
           max_points: Annotated[int, Range(2, 10000)] = 200, ds_max: Annotated[float, Range(1e-4, 0.5)] = 0.05,
           grid: Annotated[int, Range(2, 2000)] | None = 41, lyapunov: bool = True,
           use_cache: bool = True, folds: bool = True, fold_points: Annotated[int, Range(1, 50)] = 6,
           fold_contact: str = "stop", progress: Callable[[float], None] | None = None) -> RegionResult:
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
    folds : bool
        Compute the fold-of-cycles curve of every generalised-Hopf point (needs ``lyapunov``) and the shaded
        regions (:func:`~.folds.fold_curves`).
    fold_points : int
        Slices (cycle branches) per GH point.
    fold_contact : {"stop", "bilateral"}
        ``"stop"``: a slice whose cycles lose contact before folding ends at the contact loss (the brake);
        ``"bilateral"``: it is followed on to the fold of the smooth bilateral equations (as AUTO-07p does;
        ``LPC_bilateral``, a fold of the model rather than of the brake) (:func:`~.folds.fold_curves`).
    progress : callable, optional
        ``progress(fraction)`` while the fold-of-cycles curves are computed.

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
    fc = None
    if folds and lyapunov:
        fc, fnotes = fold_curves(eng, space, x, y, curves, points=fold_points, progress=progress,
                                 contact=fold_contact)
        notes = notes + fnotes
    return RegionResult(space, x, y, curves, m, notes, time.perf_counter() - t0, fc)
