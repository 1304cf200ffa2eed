"""``brakesqueal plot STORE.zarr`` (issue 29): the figure of a sweep store is read off the store.

Small studies are run once per module; every figure is made through the command line (``main``) and
captured at :func:`brakesqueal.plotting.save`, then checked against the store: the map's cells are the
store's verdicts, the slice's curve and shaded stretches its values, the histograms' counts its values,
``--at`` takes the nearest grid value (on a log axis, in log distance), an incomplete store is drawn as
far as it is computed, and bad input is one line naming the option and what is allowed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")
pytest.importorskip("dask")
pytest.importorskip("matplotlib")

import brakesqueal.plotting as plotting  # noqa: E402
from brakesqueal.cli import main  # noqa: E402
from brakesqueal.labels import axis_label  # noqa: E402
from brakesqueal.sweep import open_sweep, sweep  # noqa: E402
from brakesqueal.sweep.plots import plot_sweep, sweep_view  # noqa: E402
from brakesqueal.sweep.store import MARKERS  # noqa: E402

EIGEN = ["stable", "margin", "max_real", "frequency"]
GRID2 = {"preset": "paper-fig2", "axes": {"mu": "0.05:1:7", "k_ip": "1e5:1e10:9:log"},
         "compute": {"quantities": EIGEN}, "execution": {"chunk_points": 20}}  # chunks of 2 x 9: 4 chunks
OMEGA = [20.0, 16 * math.pi, 100.0]
GRID3 = {"preset": "paper-fig2", "axes": {"Omega": {"values": OMEGA}, "k_ip": "1e5:1e10:9:log", "mu": "0.05:1:7"},
         "compute": {"quantities": ["stable"]}, "execution": {"chunks": {"Omega": 1, "k_ip": 4}}}
LINE = {"preset": "paper-fig2", "parameters": {"k_ip": 1e7}, "axes": {"mu": "0.05:1:40"},
        "compute": {"quantities": EIGEN}}
LHS = {"preset": "paper-fig2", "samples": {"method": "lhs", "n": 200, "seed": 3,
                                          "ranges": {"k_ip": "1e5:1e10:log", "mu": {"start": 0.05, "stop": 1}}},
       "compute": {"quantities": EIGEN}, "execution": {"chunk_points": 50}}


@pytest.fixture(scope="module")
def stores(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("stores")
    out = {}
    for name, study in (("grid2", GRID2), ("grid3", GRID3), ("line", LINE), ("lhs", LHS)):
        out[name] = d / f"{name}.zarr"
        sweep(study, store=out[name])
    return out


@pytest.fixture
def figures(monkeypatch) -> list:
    """The figures the command writes (through the shared save helper), in order."""
    seen: list = []
    orig = plotting.save

    def keep(fig, path, *args, **kwargs):
        seen.append(fig)
        return orig(fig, path, *args, **kwargs)

    monkeypatch.setattr(plotting, "save", keep)
    return seen


def plot(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(["plot", *map(str, args)])
    out = capsys.readouterr()
    return rc, out.out, out.err


def meshes(ax) -> list:
    from matplotlib.collections import QuadMesh

    return [c for c in ax.collections if isinstance(c, QuadMesh)]


def shown(mesh) -> np.ma.MaskedArray:
    """The cells a QuadMesh draws: its array (masked where nothing is drawn)."""
    return np.ma.masked_invalid(np.ma.asarray(mesh.get_array()))


def verdict_cells(stable: np.ndarray, status: np.ndarray) -> np.ma.MaskedArray:
    """What a map must draw: 1 stable, 0 unstable, nothing where there is no verdict."""
    return np.ma.masked_array(stable.astype(float), mask=status >= 2)


# ---------------------------------------------------------------- maps
def test_2d_store_is_map_plot_of_its_verdicts(stores, capsys, figures, tmp_path):
    out = tmp_path / "m.png"
    rc, stdout, err = plot(capsys, stores["grid2"], "--out", out)
    assert rc == 0, err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and len(figures) == 1
    ds = open_sweep(stores["grid2"]).load()
    ax = figures[0].axes[0]
    # as map --plot: the inner axis horizontal, labels with symbols and units, the title of map_title
    assert ax.get_xlabel() == axis_label("k_ip", "N/m") and ax.get_ylabel() == axis_label("mu", "")
    assert ax.get_xscale() == "log" and ax.get_yscale() == "linear"
    assert figures[0]._suptitle.get_text() == plotting.map_title("paper-fig2", "k_ip", "mu")
    mesh = meshes(ax)
    assert len(mesh) == 1 and mesh[0].get_array().shape == (7, 9)
    want = verdict_cells(ds["stable"].values, ds["status"].values)
    got = shown(mesh[0])
    assert np.array_equal(got.mask, want.mask) and np.array_equal(got.filled(-1), want.filled(-1))
    assert 0 < want.mean() < 1  # both verdicts are on the map
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[:2] == ["stable", "unstable (squeal)"] and "not computed yet" not in labels
    assert "63 points: 25 stable, 38 unstable" in stdout and stdout.startswith(f"wrote {out}: map of mu vs k_ip")
    assert err == ""


def test_map_coloured_by_a_quantity_shows_the_store_values(stores, capsys, figures, tmp_path):
    ds = open_sweep(stores["grid2"]).load()
    for q, label in (("max_real", axis_label("max_real")), ("margin", axis_label("damping_ratio"))):
        rc, _, err = plot(capsys, stores["grid2"], "--color", q, "--out", tmp_path / f"{q}.png")
        assert rc == 0, err
        fig = figures[-1]
        got = shown(meshes(fig.axes[0])[0])
        want = np.ma.masked_invalid(np.where(ds["status"].values >= 2, np.nan, ds[q].values))
        assert np.array_equal(got.mask, want.mask) and np.allclose(got.compressed(), want.compressed(), rtol=0)
        assert fig.axes[1].get_ylabel() == label  # the colour bar: symbol and unit, never the variable's name
        assert q not in label


def test_3d_store_map_at_the_nearest_grid_value(stores, capsys, figures, tmp_path):
    ds = open_sweep(stores["grid3"]).load()
    rc, stdout, err = plot(capsys, stores["grid3"], "--at", "Omega=40", "--out", tmp_path / "a.png")
    assert rc == 0, err
    # 40 rad/s lies between 20 and 16 pi = 50.27: the nearer grid value is drawn and named in the title
    ax = figures[-1].axes[0]
    title = figures[-1]._suptitle.get_text()
    assert "50.27 rad/s" in title and "$\\Omega$" in title and "Omega" not in title.replace("$\\Omega$", "")
    assert "nearest grid value Omega = 50.2655" in err and len(err.strip().splitlines()) == 1
    # the two longest axes are drawn (k_ip: 9, mu: 7 points); the later one, mu, horizontal
    assert ax.get_xlabel() == axis_label("mu", "") and ax.get_ylabel() == axis_label("k_ip", "N/m")
    sl = ds.sel(Omega=16 * math.pi)
    want = verdict_cells(sl["stable"].values, sl["status"].values)  # dims (k_ip, mu) = (y, x)
    assert np.array_equal(shown(meshes(ax)[0]).filled(-1), want.filled(-1))
    assert "at Omega = 50.2655" in stdout
    # the axes chosen: transposed, and at another value given as an expression
    rc, _, err = plot(capsys, stores["grid3"], "--x", "k_ip", "--y", "mu", "--at", "Omega=100*1", "--out",
                      tmp_path / "b.png")
    assert rc == 0 and err == ""  # exactly on the grid: no note
    sl = ds.sel(Omega=100.0)
    want = verdict_cells(sl["stable"].values.T, sl["status"].values.T)
    assert np.array_equal(shown(meshes(figures[-1].axes[0])[0]).filled(-1), want.filled(-1))
    # an axis not given with --at: its first value, said on stderr
    rc, _, err = plot(capsys, stores["grid3"], "--out", tmp_path / "c.png")
    assert rc == 0 and "Omega is drawn at its first grid value 20" in err
    assert "20 rad/s" in figures[-1]._suptitle.get_text()


def test_at_takes_the_nearest_grid_value_in_the_axis_scale(stores, rng):
    """Random values on a log axis (k_ip) and a linear one (mu): the index drawn is the nearest in log resp.
    linear distance (they differ for some values, e.g. k_ip = 4.5e6)."""
    ds = open_sweep(stores["grid3"])
    k, mu = ds["k_ip"].values, ds["mu"].values
    for _ in range(25):
        kv = float(10 ** rng.uniform(5, 10))
        mv = float(rng.uniform(mu[0], mu[-1]))
        v = sweep_view(stores["grid3"], kind="slice", x="Omega", at={"k_ip": kv, "mu": mv})
        assert v.index == {"k_ip": int(np.argmin(np.abs(np.log(k / kv)))), "mu": int(np.argmin(np.abs(mu - mv)))}
        assert v.at == {"k_ip": k[v.index["k_ip"]], "mu": mu[v.index["mu"]]}
    v = sweep_view(stores["grid3"], kind="slice", x="Omega", at={"k_ip": 4.5e6})
    assert v.at["k_ip"] == pytest.approx(10 ** 6.875)  # linear distance would take 10**6.25


# ---------------------------------------------------------------- slices
def spans(ax, cat: int) -> list[tuple[float, float]]:
    out = []
    for p in ax.patches:
        if p.get_gid() == f"verdict-{cat}":
            x0 = p.get_x() if hasattr(p, "get_x") else p.get_xy()[0][0]
            out.append((x0, x0 + p.get_width()) if hasattr(p, "get_width") else (x0, p.get_xy()[2][0]))
    return out


def test_1d_store_is_the_quantity_along_the_axis_with_unstable_stretches(stores, capsys, figures, tmp_path):
    rc, stdout, err = plot(capsys, stores["line"], "--out", tmp_path / "s.svg")
    assert rc == 0, err
    assert (tmp_path / "s.svg").read_text().lstrip().startswith("<?xml")
    ds = open_sweep(stores["line"]).load()
    ax = figures[-1].axes[0]
    assert ax.get_xlabel() == axis_label("mu", "") and ax.get_ylabel() == axis_label("max_real")
    line = [ln for ln in ax.get_lines() if ln.get_xydata().shape[0] == 40]
    assert len(line) == 1
    np.testing.assert_array_equal(line[0].get_xdata(), ds["mu"].values)
    np.testing.assert_array_equal(line[0].get_ydata(), ds["max_real"].values)
    stable = ds["stable"].values
    assert stable.any() and not stable.all()
    red, green = spans(ax, 1), spans(ax, 0)
    for x, s in zip(ds["mu"].values, stable):
        in_red = any(a < x < b for a, b in red)
        in_green = any(a < x < b for a, b in green)
        assert in_red == (not s) and in_green == bool(s), x
    assert "max_real along mu" in stdout and "16 stable, 24 unstable" in stdout


def test_slice_of_a_3d_store(stores, capsys, figures, tmp_path):
    ds = open_sweep(stores["grid3"]).load()
    rc, stdout, err = plot(capsys, stores["grid3"], "--kind", "slice", "--x", "k_ip", "--at", "mu=0.5",
                           "--at", "Omega=16*pi", "--out", tmp_path / "s.png")
    assert rc == 0, err
    ax = figures[-1].axes[0]
    sl = ds.sel(Omega=16 * math.pi).isel(mu=3)  # mu = 0.525 is the grid value nearest 0.5
    assert "nearest grid value mu = 0.525" in err
    red = spans(ax, 1)
    for x, s in zip(ds["k_ip"].values, sl["stable"].values):
        assert any(a < x < b for a, b in red) == (not s)
    assert "0.525" in figures[-1]._suptitle.get_text() and ax.get_yticks().size == 0  # verdict only: no curve


def test_long_titles_are_wrapped_inside_the_figure(stores, capsys, figures, tmp_path):
    """Two fixed axes and the preset do not fit one line of a journal column: the title wraps, never clipped."""
    rc, _, err = plot(capsys, stores["grid3"], "--kind", "slice", "--x", "mu", "--at", "Omega=16*pi", "--at",
                      "k_ip=1e6", "--out", tmp_path / "t.png")
    assert rc == 0, err
    fig = figures[-1]
    title = fig._suptitle
    renderer = fig.canvas.get_renderer()
    assert "\n" in title.get_text() and "(paper-fig2)" in title.get_text()
    box = title.get_window_extent(renderer)
    assert 0 <= box.x0 and box.x1 <= fig.bbox.width


# ---------------------------------------------------------------- samples
def bars(ax, cat: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Left edges, widths and heights of the bars of one verdict category."""
    ps = [p for p in ax.patches if p.get_gid() == f"verdict-{cat}"]
    return (np.array([p.get_x() for p in ps]), np.array([p.get_width() for p in ps]),
            np.array([p.get_height() for p in ps]))


def test_sampled_store_histograms_count_the_store_values(stores, capsys, figures, tmp_path):
    rc, stdout, err = plot(capsys, stores["lhs"], "--out", tmp_path / "h.pdf")
    assert rc == 0, err
    assert (tmp_path / "h.pdf").read_bytes()[:5] == b"%PDF-"
    ds = open_sweep(stores["lhs"]).load()
    fig = figures[-1]
    assert [ax.get_xlabel() for ax in fig.axes] == [axis_label(q) for q in ("max_real", "frequency",
                                                                            "damping_ratio")]
    stable = ds["stable"].values
    unstable = int((~stable).sum())
    assert f"{100 * unstable / 200:.1f} % unstable ({unstable} of the 200 samples" in fig._suptitle.get_text()
    for ax, q in zip(fig.axes, ("max_real", "frequency", "margin")):
        v = ds[q].values
        x0, w, _ = bars(ax, 0)
        edges = np.append(x0, x0[-1] + w[-1])
        assert edges[0] <= v.min() and edges[-1] >= v.max()
        for cat, sel in ((0, stable), (1, ~stable)):
            _, _, h = bars(ax, cat)
            want = np.histogram(v[sel], bins=edges)[0]
            np.testing.assert_array_equal(h, want)
            assert h.sum() == sel.sum()
    # the samples over a sampled parameter, stacked by verdict: the fraction unstable per bin
    rc, _, err = plot(capsys, stores["lhs"], "--x", "mu", "--out", tmp_path / "mu.png")
    assert rc == 0, err
    ax = figures[-1].axes[0]
    assert ax.get_xlabel() == axis_label("mu", "")
    x0, w, h1 = bars(ax, 1)
    edges = np.append(x0, x0[-1] + w[-1])
    np.testing.assert_array_equal(h1, np.histogram(ds["mu"].values[~stable], bins=edges)[0])


def test_sampled_store_map_draws_each_sample_by_verdict(stores, capsys, figures, tmp_path):
    rc, _, err = plot(capsys, stores["lhs"], "--kind", "map", "--out", tmp_path / "m.png")
    assert rc == 0, err
    ds = open_sweep(stores["lhs"]).load()
    ax = figures[-1].axes[0]
    assert ax.get_xlabel() == axis_label("k_ip", "N/m") and ax.get_xscale() == "log"
    pts = {c.get_gid(): c.get_offsets() for c in ax.collections}
    stable = ds["stable"].values
    want = np.column_stack([ds["k_ip"].values, ds["mu"].values])
    assert np.array_equal(np.asarray(pts["verdict-1"]), want[~stable])
    assert np.array_equal(np.asarray(pts["verdict-0"]), want[stable])


# ---------------------------------------------------------------- an incomplete store
@pytest.fixture(scope="module")
def partial(tmp_path_factory) -> Path:
    """GRID2 stopped after two of its four chunks (as a killed run leaves it)."""
    import brakesqueal.sweep.runner as runner

    store = tmp_path_factory.mktemp("partial") / "p.zarr"
    orig, calls = runner.compute_chunk, []

    def stop(spec, coords):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return orig(spec, coords)

    mp = pytest.MonkeyPatch()
    mp.setattr(runner, "compute_chunk", stop)
    try:
        with pytest.raises(KeyboardInterrupt):
            sweep(GRID2, store=store)
    finally:
        mp.undo()
    assert len(list((store / MARKERS).glob("[0-9]*.json"))) == 2
    return store


def test_incomplete_store_draws_what_is_computed(partial, stores, capsys, figures, tmp_path):
    from matplotlib.contour import ContourSet

    rc, stdout, err = plot(capsys, partial, "--out", tmp_path / "p.png")
    assert rc == 0, err
    note = err.strip().splitlines()
    assert len(note) == 1 and "incomplete: 2 of 4 chunks computed" in note[0] and "drawn grey" in note[0]
    assert f"--out {partial}" in note[0]
    part = open_sweep(partial).load()
    done = part["status"].values != 8
    assert done[:4].all() and not done[4:].any()  # rows 0-3 (chunks 0 and 1) computed
    ax = figures[-1].axes[0]
    main_mesh, grey = meshes(ax)
    full = open_sweep(stores["grid2"]).load()  # the uninterrupted run: the computed part is the same
    want = verdict_cells(full["stable"].values, np.where(done, full["status"].values, 8))
    assert np.array_equal(shown(main_mesh).filled(-1), want.filled(-1))
    assert np.array_equal(shown(grey).mask, done)  # grey exactly where nothing is computed
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "not computed yet" in labels and "no verdict (see status)" not in labels
    # the grid's stability boundary stays among the computed rows (mu <= 0.525), never along their edge
    mu_last = part["mu"].values[3]
    lines = [c for c in ax.collections if isinstance(c, ContourSet) and not c.filled]
    verts = np.concatenate([p.vertices for c in lines for p in c.get_paths()])
    assert verts.size and verts[:, 1].max() <= mu_last + 1e-12
    # ... which the map figure alone (not computed = no verdict) would draw there: the check can fail
    bare = plotting.plot_map_arrays(("k_ip", part["k_ip"].values, "N/m", True), ("mu", part["mu"].values, "", False),
                                    part["stable"].values, part["status"].values)
    bare_lines = [c for c in bare.axes[0].collections if isinstance(c, ContourSet) and not c.filled]
    assert np.concatenate([p.vertices for c in bare_lines for p in c.get_paths()])[:, 1].max() > mu_last
    assert "27 without a verdict (not_computed 27)" in stdout


def test_incomplete_store_histograms_and_chunk_without_marker(partial, capsys, figures, tmp_path):
    rc, _, err = plot(capsys, partial, "--kind", "hist", "--out", tmp_path / "h.png")
    assert rc == 0 and "left out of the histograms" in err
    part = open_sweep(partial).load()
    done = part["status"].values != 8
    ax = figures[-1].axes[0]
    total = sum(bars(ax, c)[2].sum() for c in range(4))
    assert total == done.sum() == 36
    assert "27 not computed yet" in figures[-1]._suptitle.get_text()
    # data written without its completion marker (a run killed between the two) is not counted as computed
    import shutil

    copy = tmp_path / "copy.zarr"
    shutil.copytree(partial, copy)
    (copy / MARKERS / "1.json").unlink()
    res = plot_sweep(copy)
    assert res.chunks == (1, 4) and res.not_computed == 45 and res.stable + res.unstable == 18


# ---------------------------------------------------------------- bad input, default output
BAD = [
    (["{tmp}/nothing.zarr"], ["STORE", "does not exist"]),
    (["{tmp}/file.zarr"], ["STORE", "is not a sweep store"]),
    (["{tmp}"], ["STORE", "is not a sweep store"]),
    (["{grid2}", "--color", "colour"], ["--color", "verdict, max_real, frequency, margin", "'colour'"]),
    (["{grid2}", "--color", "critical_speed"], ["--color critical_speed", "not computed", "allowed: verdict"]),
    (["{grid2}", "--x", "kip"], ["--x", "mu, k_ip", "'kip'", "did you mean 'k_ip'"]),
    (["{grid2}", "--x", "mu", "--y", "mu"], ["--x and --y", "'mu'"]),
    (["{grid2}", "--kind", "slice", "--y", "mu"], ["--y", "--kind map"]),
    (["{grid2}", "--at", "Omega=20"], ["--at", "none"]),
    (["{grid3}", "--at", "Omega=500"], ["--at Omega=500", "outside", "[20, 100] rad/s"]),
    (["{grid3}", "--at", "Omega=5"], ["--at Omega=5", "outside", "[20, 100]"]),
    (["{grid3}", "--at", "Omega"], ["--at", "NAME=VALUE"]),
    (["{grid3}", "--at", "Omega=20", "--at", "Omega=100"], ["--at Omega", "twice"]),
    (["{grid3}", "--at", "mu=0.5"], ["--at mu", "axis of the figure", "Omega"]),
    (["{grid3}", "--at", "speed=3"], ["--at", "Omega", "'speed'"]),
    (["{grid3}", "--at", "Omega=fast"], ["--at Omega"]),
    (["{line}", "--kind", "map"], ["--kind", "slice, hist", "one axis (mu)"]),
    (["{lhs}", "--kind", "slice"], ["--kind", "hist, map", "sampled"]),
    (["{lhs}", "--at", "mu=0.5"], ["--at", "sampled"]),
    (["{grid2}", "--kind", "pie"], ["--kind", "map", "slice", "hist"]),
    (["{grid2}", "--out", "{tmp}/fig.jpg"], ["--out", ".png or .svg or .pdf"]),
    (["{grid3}", "--kind", "hist"], ["--kind hist", "only the verdict", "[compute] quantities", "map or slice"]),
    (["{grid2}", "--out", "{tmp}/no/fig.png"], ["--out", "does not exist"]),
]


@pytest.mark.parametrize(("args", "needles"), BAD, ids=[" ".join(a[1:]) or a[0] for a, _ in BAD])
def test_bad_input_is_one_line_naming_the_option(stores, capsys, tmp_path, args, needles):
    (tmp_path / "file.zarr").write_text("not a store")
    names = {k: str(v) for k, v in stores.items()}
    rc, stdout, err = plot(capsys, *[a.format(tmp=tmp_path, **names) for a in args])
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("brakesqueal: error: "), err
    for n in needles:
        assert n in lines[0], (n, lines[0])
    assert stdout == "" and not list(tmp_path.glob("*.png")) and not list(tmp_path.glob("*.jpg"))


def test_default_output_is_the_store_name_with_png(stores, capsys, tmp_path):
    import shutil

    copy = tmp_path / "results.zarr"
    shutil.copytree(stores["line"], copy)
    rc, stdout, _ = plot(capsys, copy)
    assert rc == 0 and (tmp_path / "results.png").read_bytes()[:4] == b"\x89PNG"
    assert stdout.startswith(f"wrote {tmp_path / 'results.png'}: ")
