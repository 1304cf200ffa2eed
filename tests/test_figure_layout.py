"""Every figure command at one publication style: the gallery test of issue 29.

Each command that draws a figure (``--plot``) runs in-process as a user types it; its figure is captured at
``savefig`` and measured, not looked at: every text inside the figure (nothing clipped), no title or suptitle over
a legend or another title, no two labels on top of each other, both axes labelled (with a unit in brackets, or a
dimensionless quantity named as such), and no internal identifier (``contact_loss``, ``max_points``) as text.
"""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

from matplotlib.figure import Figure  # noqa: E402
from matplotlib.legend import Legend  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from brakesqueal.cli import main  # noqa: E402

#: command lines (``{out}`` is the figure's path, ``{tmp}`` a scratch directory)
COMMANDS = {
    "map": ["map", "--x", "k_ip=1e5:1e10:40:log", "--y", "mu=0.05:1:30", "--out", "{tmp}/m.nc", "--plot", "{out}"],
    "map-max-real": ["map", "--x", "k_ip=1e5:1e10:40:log", "--y", "mu=0.05:1:30", "--out", "{tmp}/m2.nc",
                     "--plot", "{out}", "--color", "max_real"],
    "map-pad-only": ["map", "--x", "mu1=0:1:25", "--y", "mu2=0:1:25", "--out", "{tmp}/m3.nc", "--plot", "{out}"],
    "crossings": ["crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.5", "--plot", "{out}"],
    "critical-speed": ["critical-speed", "--preset", "paper-fig3", "--set", "mu1=0.6", "--set", "mu2=0.4",
                       "--range", "1:1e5", "--plot", "{out}"],
    "modes": ["modes", "--along", "mu=0.05:1", "--plot", "{out}"],
    "simulate": ["simulate", "--preset", "paper-fig2", "--set", "mu=1", "--t-end", "0.05", "--plot", "{out}"],
    "cycles": ["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--along",
               "Omega=30:40", "--plot", "{out}"],
    "reproduce": ["reproduce", "all", "--out", "{tmp}/paper", "--no-progress"],
    "plot-map": ["plot", "{tmp}/grid3.zarr", "--at", "Omega=50", "--out", "{out}"],
    "plot-slice": ["plot", "{tmp}/line.zarr", "--out", "{out}"],
    "plot-hist": ["plot", "{tmp}/lhs.zarr", "--out", "{out}"],
    "region": ["region", "--preset", "paper-fig3", "--set", "k_ip=inf", "--set", "mu2=0.5", "--x", "mu1=0:1",
               "--y", "Omega=10:20000:log", "--grid", "21", "--plot", "{out}"],
    "uq": ["uq", str(Path(__file__).resolve().parents[1] / "examples" / "study-uq-mu.toml"), "--plot", "{out}"],
}

#: the sweep stores the ``plot`` commands draw (small studies, made by the library before the commands run)
STORES = {
    "grid3": {"preset": "paper-fig2", "axes": {"Omega": {"values": [20.0, 50.0]}, "k_ip": "1e5:1e10:9:log",
                                               "mu": "0.05:1:7"}, "compute": {"quantities": ["stable", "max_real"]}},
    "line": {"preset": "paper-fig2", "parameters": {"k_ip": 1e7}, "axes": {"mu": "0.05:1:40"},
             "compute": {"quantities": ["stable", "max_real", "frequency"]}},
    "lhs": {"preset": "paper-fig2", "samples": {"method": "lhs", "n": 200, "seed": 3,
                                                "ranges": {"k_ip": "1e5:1e10:log", "mu": {"start": 0.05, "stop": 1}}},
            "compute": {"quantities": ["stable", "max_real", "frequency"]}},
}

#: an internal identifier shown as text: snake_case words outside mathtext ($...$)
_IDENT = re.compile(r"\b[a-z]+_[a-z]+(?:_[a-z]+)*\b")
_TOL = 1.0  # pixels
DPI = 300  # the resolution figure commands write (brakesqueal.plotting.save)
#: a unit in brackets (``[rad/s]``, ``[1/s]``); a label of mathtext symbols only (``$\mu$``) is dimensionless
_UNIT = re.compile(r"\[[^\]]+\]")


def _texts(fig: Figure) -> list[Text]:
    """The texts drawn: every visible non-empty text, tick labels only of the ticks inside the view."""
    tick_labels, drawn = set(), set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                tick_labels.update((id(tick.label1), id(tick.label2)))
            for tick in axis._update_ticks():  # the ticks matplotlib draws (inside the view interval)
                drawn.update(id(t) for t in (tick.label1, tick.label2) if t.get_visible())
    out = []
    for t in fig.findobj(Text):
        if not (t.get_visible() and t.get_text().strip()):
            continue
        if id(t) in tick_labels and id(t) not in drawn:
            continue
        out.append(t)
    return out


def layout_problems(fig: Figure) -> list[str]:
    """What is wrong with the layout of ``fig``: clipped or overlapping texts, unlabelled axes, identifiers."""
    fig.set_dpi(DPI)  # measured as written (text metrics depend on the resolution)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    problems = []
    texts = _texts(fig)
    for t in texts:
        b = t.get_window_extent(r)
        if b.x0 < -_TOL or b.y0 < -_TOL or b.x1 > W + _TOL or b.y1 > H + _TOL:
            problems.append(f"clipped: {t.get_text()!r} at {tuple(round(v) for v in b.extents)} in {W:.0f}x{H:.0f}")
        plain = re.sub(r"\$[^$]*\$", "", t.get_text())
        if _IDENT.search(plain):
            problems.append(f"internal identifier as text: {t.get_text()!r}")
    # titles (axes titles, suptitle) against legends and each other
    titles = [t for t in texts if t is getattr(fig, "_suptitle", None)
              or any(t in (ax.title, ax._left_title, ax._right_title) for ax in fig.axes)]
    legends = [lg for lg in fig.findobj(Legend) if lg.get_visible()]
    boxes = [(f"title {t.get_text()!r}", t.get_window_extent(r)) for t in titles]
    boxes += [(f"legend of {len(lg.get_texts())} entries", lg.get_window_extent(r)) for lg in legends]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            (na, a), (nb, b) = boxes[i], boxes[j]
            if a.x0 < b.x1 - _TOL and b.x0 < a.x1 - _TOL and a.y0 < b.y1 - _TOL and b.y0 < a.y1 - _TOL:
                problems.append(f"overlap: {na} and {nb}")
    # axis labels must not overlap titles or other axes' labels
    labels = [(f"label {ax.xaxis.label.get_text()!r}", ax.xaxis.label.get_window_extent(r)) for ax in fig.axes
              if ax.xaxis.label.get_text()]
    labels += [(f"label {ax.yaxis.label.get_text()!r}", ax.yaxis.label.get_window_extent(r)) for ax in fig.axes
               if ax.yaxis.label.get_text()]
    for na, a in labels:
        for nb, b in boxes + [lb for lb in labels if lb[0] != na]:
            if a.x0 < b.x1 - _TOL and b.x0 < a.x1 - _TOL and a.y0 < b.y1 - _TOL and b.y0 < a.y1 - _TOL:
                problems.append(f"overlap: {na} and {nb}")
    # every data axes labelled on both axes (colour bars are labelled on their long side)
    for ax in fig.axes:
        if not ax.get_visible() or not ax.axison:
            continue
        if ax.get_label() == "<colorbar>":
            if not (ax.get_ylabel() or ax.get_xlabel()):
                problems.append("colour bar without a label")
            continue
        shared_x = [o for o in ax.get_shared_x_axes().get_siblings(ax) if o is not ax and o.get_xlabel()]
        if not (ax.get_xlabel() or shared_x) or not ax.get_ylabel():
            problems.append(f"axes {ax.get_title()!r} without an axis label: x={ax.get_xlabel()!r}, "
                            f"y={ax.get_ylabel()!r}")
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            if label and not _UNIT.search(label) and re.search(r"[A-Za-z]", re.sub(r"\$[^$]*\$", "", label)):
                problems.append(f"axis label without a unit: {label!r}")
    return sorted(set(problems))


@pytest.fixture(scope="module")
def figures(tmp_path_factory) -> dict[str, list[Figure]]:
    captured: dict[str, list[Figure]] = {}
    orig = Figure.savefig
    tmp = tmp_path_factory.mktemp("figs")
    current = {"name": ""}

    def spy(self, fname, *a, **k):
        captured.setdefault(current["name"], []).append(self)
        return orig(self, fname, *a, **k)

    from brakesqueal.sweep import sweep

    for store, study in STORES.items():
        sweep(study, store=tmp / f"{store}.zarr")
    Figure.savefig = spy  # type: ignore[method-assign]
    try:
        for name, args in COMMANDS.items():
            current["name"] = name
            out = tmp / f"{name}.png"
            rc = main([a.format(out=out, tmp=tmp) for a in args])
            assert rc == 0, name
            assert "{out}" not in args or Path(out).stat().st_size > 0
    finally:
        Figure.savefig = orig  # type: ignore[method-assign]
    return captured


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_figure_layout(figures, name):
    assert figures.get(name), f"{name} drew no figure"
    for fig in figures[name]:
        assert layout_problems(fig) == []


def test_the_checker_finds_a_title_over_a_legend_and_clipping():
    """The checker itself: a figure with its title over the legend and a label outside the canvas fails."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1], label="a long legend entry")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, 1.25))
    ax.set_title("a title")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("contact_loss")  # an identifier, and no unit
    fig.text(1.05, 0.5, "outside")
    p = layout_problems(fig)
    assert any(s.startswith("overlap: title") for s in p)
    assert any(s.startswith("clipped: 'outside'") for s in p)
    assert any("internal identifier" in s for s in p)
    assert "axis label without a unit: 'contact_loss'" in p
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
    ax.plot([0, 1], [0, 1], label="a")
    ax.legend()
    ax.set_title("fine")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    assert layout_problems(fig) == []
    plt.close(fig)
