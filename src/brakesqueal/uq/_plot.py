"""The figure of a UQ study: histograms of max Re λ and of the squeal frequency, and the Sobol' indices."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..labels import symbol
from ..plotting import new_figure, styled
from ..validation import validated

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_uq"]


@validated
@styled
def plot_uq(ds: Any) -> Figure:
    """Histograms of max Re λ (points of ``A`` and ``B`` with a verdict; P(squeal) in the title) and of the
    frequency of the squealing ones, and a bar chart of the first-order and total Sobol' indices of every output
    with their confidence intervals.

    Parameters
    ----------
    ds : xarray.Dataset
        ``run_uq(...).dataset``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax0 = new_figure(size=(7.0, 5.2))
    ax0.remove()
    (ax_re, ax_f), (ax_s, ax_t) = fig.subplots(2, 2)
    status = np.asarray(ds["status"].values)
    ok = (status == 0) | (status == 1)
    re = np.asarray(ds["max_real"].values)[ok]
    sq = np.asarray(ds["squeal"].values)[ok].astype(bool)
    if re.size:
        ax_re.hist(re, bins=50, color="0.6")
    ax_re.axvline(0.0, color="C3", lw=1.0)
    lo, hi = (float(x) for x in ds["p_squeal_ci"].values)
    ax_re.set_title(f"P(squeal) = {float(ds['p_squeal']):.3g} (95 %: {lo:.3g} to {hi:.3g})", fontsize="small")
    ax_re.set_xlabel(r"max Re $\lambda$ [1/s]")
    ax_re.set_ylabel("samples [count]")
    f = np.asarray(ds["frequency"].values)[ok][sq]
    if f.size:
        ax_f.hist(f, bins=50, color="C3")
    from matplotlib.ticker import MaxNLocator

    ax_f.ticklabel_format(axis="x", useOffset=False)  # absolute frequencies, never "+1.739e3"
    ax_f.xaxis.set_major_locator(MaxNLocator(4))
    ax_f.set_xlabel("squeal frequency [Hz]")
    ax_f.set_ylabel("samples [count]")
    ax_f.set_title(f"{f.size} squealing samples", fontsize="small")
    names = [f"${symbol(str(x))}$" for x in ds["input"].values]
    shown = {"max_real": r"max Re $\lambda$", "squeal": "squeal (0/1)", "frequency": "frequency"}
    x = np.arange(len(names))
    shown_q = [q for q in ds["quantity"].values if str(q) in shown]  # per-mode indices: in the JSON and dataset
    width = 0.8 / len(shown_q)
    for ax, var in ((ax_s, "first"), (ax_t, "total")):
        for k, q in enumerate(shown_q):
            val = np.asarray(ds[var].sel(quantity=q).values, dtype=float)
            ci = np.asarray(ds[f"{var}_ci"].sel(quantity=q).values, dtype=float)
            err = np.abs(np.stack([val - ci[:, 0], ci[:, 1] - val]))
            ax.bar(x + (k - (len(shown_q) - 1) / 2) * width, np.nan_to_num(val), width,
                   yerr=np.nan_to_num(err), capsize=2, label=shown.get(str(q), str(q)))
        ax.set_xticks(x, names)
        ax.set_xlabel("input parameter [-]")
        ax.set_ylabel(f"{var}-order Sobol' index [-]" if var == "first" else "total Sobol' index [-]")
        ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
    ax_s.legend(fontsize="x-small")
    return fig
