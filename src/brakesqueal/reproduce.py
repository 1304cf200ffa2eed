"""Reproduce the paper's Figures 2 and 3 (PNG, NetCDF, CSV, JSON summary).

* Fig. 2 — stability map over ``k_ip`` (log) and ``mu`` for ``paper-fig2``
  (``N0 = 1800/mu``) with a dashed line of decreasing ``k_ip`` at fixed
  ``mu`` and its exact points A (unstable → stable) and B (stable → unstable).
* Fig. 3 — ``Ω_crit`` versus ``mu1 - mu2`` (``mu1 + mu2 = 1``) for
  ``paper-fig3`` and several ``k_ip`` including ``inf``; the re-stabilising
  speed the model also predicts is stored alongside.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .model.parameters import ParameterSpace

__all__ = ["reproduce_fig2", "reproduce_fig3", "FIG2_MU", "FIG3_KIP"]

#: mu of the dashed line in Fig. 2 (the preset's default; the line crosses the boundary twice there).
FIG2_MU = 0.5
#: k_ip values of Fig. 3 [N/m].
FIG3_KIP = ("1e7", "1e8", "1e9", "inf")


def _noop(frac: float) -> None:
    pass


def reproduce_fig2(out: str | Path, *, n_kip: int = 301, n_mu: int = 241, mu_line: float = FIG2_MU,
                   progress: Callable[[float], None] = _noop) -> dict[str, Any]:
    """Reproduce the paper's Fig. 2: write ``fig2.png``, ``fig2.nc``, ``fig2.csv``, ``fig2.json`` to ``out``
    (``brakesqueal reproduce fig2``).

    Parameters
    ----------
    out : str or Path
        Output directory (created; files in it are replaced atomically).
    n_kip, n_mu : int
        Grid points along ``k_ip`` (1e5 … 1e10 N/m, logarithmic) and ``mu`` (0.05 … 1).
    mu_line : float
        The friction coefficient of the dashed line on which points A and B are located.
    progress : callable
        Called with the completed fraction.

    Returns
    -------
    dict
        The summary written to ``fig2.json`` (``A_k_ip``, ``B_k_ip``, ``mu_line``, the map's counts, ...).
    """
    from .analysis.maps import Axis
    from .api import crossings, stability_map
    from .model.parameters import ParameterSpace
    from .plotting import save

    from .outputs import check_output_dir, write_set

    out = check_output_dir(out, what="--out")
    space = ParameterSpace.from_preset("paper-fig2")
    kip = Axis("k_ip", 1e5, 1e10, n_kip, True)
    m = stability_map(space, kip, Axis("mu", 0.05, 1.0, n_mu), progress=lambda f: progress(0.8 * f))
    line = crossings(ParameterSpace.from_preset("paper-fig2", {"mu": mu_line}), kip)
    progress(0.9)
    # walking along decreasing k_ip: a "destabilizing" crossing in increasing k_ip is A (unstable -> stable)
    pts = sorted(line.crossings, key=lambda c: -c[0])
    A = next((v for v, d in pts if d == "destabilizing"), None)
    B = next((v for v, d in pts if d == "stabilizing" and (A is None or v < A)), None)
    fig = m.plot(x="k_ip", title=f"Fig. 2: paper-fig2 (N0 = 1800/mu), dashed: mu = {mu_line:g}")
    ax = fig.axes[0]
    ax.plot([kip.stop, kip.start], [mu_line, mu_line], "k--", lw=1)
    ax.annotate("", xy=(kip.start * 3, mu_line), xytext=(kip.start * 10, mu_line),
                arrowprops={"arrowstyle": "->"})
    for label, v in (("A", A), ("B", B)):
        if v is not None:
            ax.plot([v], [mu_line], "ko", ms=5)
            ax.annotate(label, (v, mu_line), textcoords="offset points", xytext=(4, 6))
    st = m.data["stable"].values
    summary = {"figure": "fig2", "preset": "paper-fig2", "mu_line": mu_line, "A_k_ip": A, "B_k_ip": B,
               "line_crossings": line.to_dict(), "grid": {"k_ip": [kip.start, kip.stop, n_kip, "log"],
                                                          "mu": [0.05, 1.0, n_mu, "linear"]},
               "stable_fraction": float(st.mean()),
               "files": [str(out / f"fig2.{e}") for e in ("png", "nc", "csv", "json")]}
    with write_set(out, what="--out") as tmp:  # all four files replace the previous ones, or none does
        save(fig, str(tmp / "fig2.png"))
        m.to_netcdf(str(tmp / "fig2.nc"))
        m.to_csv(str(tmp / "fig2.csv"))
        (tmp / "fig2.json").write_text(json.dumps(summary, indent=2) + "\n")
    progress(1.0)
    return summary


def fig3_tips(space: ParameterSpace, diff: np.ndarray, onset: np.ndarray, certain: np.ndarray,
              omega_range: tuple[float, float], iterations: int = 48) -> list[tuple[float, float]]:
    """Where the squeal region of Fig. 3 closes: ``(mu1 - mu2, Omega)`` at which onset and re-stabilisation meet.

    Between two neighbours of ``diff`` of which one has an onset and the other
    none (both certain), the friction asymmetry is bisected (``mu1 + mu2 = 1``)
    until the bracket is ``2^-iterations`` of the grid step; the tip's speed
    is the mean of the last onset and re-stabilisation speeds found.

    Parameters
    ----------
    space : ParameterSpace
        The paper-fig3 space at one ``k_ip``.
    diff : ndarray
        The grid of ``mu1 - mu2``.
    onset : ndarray
        Onset speeds on the grid (NaN: stable throughout).
    certain : ndarray of bool
        Whether each grid point's crossings are established.
    omega_range : tuple of float
        The Ω range searched.
    iterations : int
        Bisection steps.

    Returns
    -------
    list of (float, float)
        The tips, in increasing ``mu1 - mu2``.
    """
    from .api import critical_speeds_many

    has = np.isfinite(onset)
    out = []
    for i in np.flatnonzero((has[:-1] != has[1:]) & certain[:-1] & certain[1:]):
        inside, outside = (diff[i], diff[i + 1]) if has[i] else (diff[i + 1], diff[i])
        w = float("nan")
        for _ in range(iterations):
            d = 0.5 * (inside + outside)
            roots, dirs, counts, _ = critical_speeds_many(space, {"mu1": np.array([(1 + d) / 2]),
                                                                  "mu2": np.array([(1 - d) / 2])}, *omega_range)
            r = roots[0, :min(int(counts[0]), roots.shape[1])]
            down = r[dirs[0, :r.size] < 0]
            if down.size:
                up = r[(dirs[0, :r.size] > 0) & (r > down[0])]
                w = 0.5 * (down[0] + up[0]) if up.size else float(down[0])
                inside = d
            else:
                outside = d
        out.append((float(0.5 * (inside + outside)), float(w)))
    return sorted(out)


def reproduce_fig3(out: str | Path, *, n_diff: int = 393, omega_range: tuple[float, float] = (1.0, 1e5),
                   progress: Callable[[float], None] = _noop) -> dict[str, Any]:
    """Reproduce the paper's Fig. 3: write ``fig3.png``, ``fig3.nc``, ``fig3.csv``, ``fig3.json`` to ``out``
    (``brakesqueal reproduce fig3``).

    Parameters
    ----------
    out : str or Path
        Output directory (created; files in it are replaced atomically).
    n_diff : int
        Points along the friction difference ``mu1 - mu2`` (at ``mu1 + mu2 = 1``).
    omega_range : (float, float)
        The spin range [rad/s] searched for critical speeds.
    progress : callable
        Called with the completed fraction.

    Returns
    -------
    dict
        The summary written to ``fig3.json`` (the minimum critical speed and where it is, ...).
    """
    import xarray as xr

    from .api import critical_speeds_many
    from .model.parameters import ParameterSpace
    from .plotting import plot_critical_curves, save

    from .outputs import check_output_dir, write_set

    out = check_output_dir(out, what="--out")
    diff = np.linspace(-0.98, 0.98, n_diff)
    mu1, mu2 = (1 + diff) / 2, (1 - diff) / 2
    crit: dict[str, np.ndarray] = {}
    restab: dict[str, np.ndarray] = {}
    ncross: dict[str, np.ndarray] = {}
    certain: dict[str, np.ndarray] = {}
    tips: dict[str, list[tuple[float, float]]] = {}
    for q, kip in enumerate(FIG3_KIP):
        space = ParameterSpace.from_preset("paper-fig3", {"k_ip": kip})
        roots, dirs, counts, start, status = critical_speeds_many(space, {"mu1": mu1, "mu2": mu2}, *omega_range,
                                                                  return_status=True)
        certain[kip] = status == 0
        first = np.full(diff.size, np.nan)
        second = np.full(diff.size, np.nan)
        for i in range(diff.size):
            down = [j for j in range(min(int(counts[i]), roots.shape[1])) if dirs[i, j] < 0]
            if down:
                first[i] = roots[i, down[0]]
                later = [j for j in range(down[0] + 1, min(int(counts[i]), roots.shape[1])) if dirs[i, j] > 0]
                if later:
                    second[i] = roots[i, later[0]]
        crit[kip], restab[kip], ncross[kip] = first, second, counts.copy()
        tips[kip] = fig3_tips(space, diff, first, certain[kip], omega_range)
        progress((q + 1) / len(FIG3_KIP))
    fig = plot_critical_curves(diff, crit, restab=restab, tips=tips, title="Fig. 3: squeal region (paper-fig3)")
    fig_lin = plot_critical_curves(diff, crit, tips=tips, title="Fig. 3: onset of squeal (paper-fig3)")
    kvals = [math.inf if k == "inf" else float(k) for k in FIG3_KIP]
    ds = xr.Dataset(
        {"Omega_crit": (("k_ip", "mu_diff"), np.array([crit[k] for k in FIG3_KIP]), {"units": "rad/s"}),
         "Omega_restab": (("k_ip", "mu_diff"), np.array([restab[k] for k in FIG3_KIP]), {"units": "rad/s"}),
         "n_crossings": (("k_ip", "mu_diff"), np.array([ncross[k] for k in FIG3_KIP], dtype=np.int32)),
         "certain": (("k_ip", "mu_diff"), np.array([certain[k] for k in FIG3_KIP], dtype=np.int8),
                     {"long_name": "every crossing in the range established (1) or a part undecided (0)"})},
        coords={"k_ip": ("k_ip", kvals, {"units": "N/m"}), "mu_diff": ("mu_diff", diff, {"long_name": "mu1 - mu2"})},
        attrs={"preset": "paper-fig3", "constraint": "mu1 + mu2 = 1", "omega_range": list(omega_range)})
    mid = int(np.argmin(np.abs(diff)))
    summary: dict[str, Any] = {"figure": "fig3", "preset": "paper-fig3", "omega_range": list(omega_range),
                               "files": [str(out / f) for f in ("fig3.png", "fig3_onset.png",
                                                                "fig3.nc", "fig3.csv", "fig3.json")],
                               "curves": {}}
    for k in FIG3_KIP:
        c = crit[k]
        fin = np.isfinite(c)
        summary["curves"][k] = {
            "Omega_crit_at_equal_mu": float(c[mid]),
            "min_Omega_crit": float(np.nanmin(c)) if fin.any() else None,
            "argmin_mu_diff": float(diff[np.nanargmin(c)]) if fin.any() else None,
            "stable_throughout_for_abs_mu_diff_above": (float(np.min(np.abs(diff[~fin & certain[k]])))
                                                        if (~fin & certain[k]).any() else None),
            "undecided_points": int(np.count_nonzero(~certain[k])),
            "Omega_restab_at_equal_mu": float(restab[k][mid]),
            "tips": [{"mu_diff": d, "Omega": w} for d, w in tips[k]],
        }
    with write_set(out, what="--out") as tmp:  # all five files replace the previous ones, or none does
        save(fig, str(tmp / "fig3.png"))
        save(fig_lin, str(tmp / "fig3_onset.png"))
        ds.to_netcdf(str(tmp / "fig3.nc"), engine="scipy")
        ds.to_dataframe().reset_index().to_csv(str(tmp / "fig3.csv"), index=False)
        (tmp / "fig3.json").write_text(json.dumps(summary, indent=2) + "\n")
    return summary
