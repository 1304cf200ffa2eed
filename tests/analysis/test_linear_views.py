"""LinearModel's views for notebooks and other tools: ``plot``, ``to_xarray``, ``input_matrices``,
``to_statespace`` (python-control) and ``_repr_html_``.

The input/output matrices are checked against an independent route: the transfer function ``C (sI - A)^-1 B``
must equal the coordinate block of the inverse of the second-order system (with the kept pads' balance as extra
rows) at random complex ``s``, assembled here from ``M, D, K`` and the pad blocks directly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brakesqueal as bs


def _models():
    yield "trivial", bs.linearize(bs.get_preset("paper-fig2").resolve({"mu": 0.4, "k_ip": 1e8}))
    # asymmetric friction: a tilted silent motion, the pads keep first-order states
    space = bs.resolve_space(preset="paper-fig2", sets={"mu": 0.5, "mu1": 0.3})
    yield "pad-states", bs.linearize(space.resolve({}))


@pytest.fixture(scope="module", params=["trivial", "pad-states"])
def lm(request):
    return dict(_models())[request.param]


def _direct_transfer(lm, s: complex) -> np.ndarray:
    """Q(s) = G(s) F(s) from the second-order equations and the pads' balance, without the state matrix."""
    n = lm.n
    Z = s * s * lm.M + s * lm.D + lm.K
    if not lm.pad_states:
        return np.linalg.inv(Z)
    top = np.hstack([Z, s * lm.R_dL + lm.R_L])
    bot = np.hstack([s * s * lm.G_ddQ + s * lm.G_dQ + lm.G_Q, s * lm.G_dL + lm.G_L])
    full = np.linalg.inv(np.vstack([top, bot]))
    return full[:n, :n]


def test_input_matrices_give_the_second_order_transfer_function(lm):
    A, B, C, D = lm.input_matrices()
    assert A.shape[0] == B.shape[0] == C.shape[1] and B.shape[1] == C.shape[0] == lm.n
    rng = np.random.default_rng(3)
    scale = float(np.abs(lm.eigenvalues).max()) if not lm.pad_states else 1e4
    for _ in range(4):
        s = complex(rng.uniform(0.1, 1.0) * scale, rng.uniform(-1.0, 1.0) * scale)
        G = C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B) + D
        ref = _direct_transfer(lm, s)
        assert np.allclose(G, ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max())
    # the poles are the model's eigenvalues
    assert np.allclose(np.sort_complex(np.linalg.eigvals(A)), np.sort_complex(lm.eigenvalues),
                       rtol=1e-6, atol=1e-6 * np.abs(lm.eigenvalues).max())


def test_to_statespace_is_python_control(lm):
    control = pytest.importorskip("control")
    sys = lm.to_statespace()
    assert isinstance(sys, control.StateSpace)
    assert sys.ninputs == sys.noutputs == lm.n
    assert list(sys.output_labels) == list(lm.coords)
    if not lm.pad_states:  # static gain of M q'' + D q' + K q = F is K^-1
        assert np.allclose(sys.dcgain(), np.linalg.inv(lm.K), rtol=1e-8)


def test_to_xarray_holds_the_matrices_and_eigenvalues(lm):
    ds = lm.to_xarray()
    assert np.array_equal(ds["M"].values, lm.M) and np.array_equal(ds["K"].values, lm.K)
    assert np.array_equal(ds["D"].values, lm.D)
    assert np.array_equal(ds["real"].values, lm.eigenvalues.real)
    assert np.allclose(ds["frequency"].values, np.abs(lm.eigenvalues.imag) / (2 * math.pi))
    assert list(ds["dof"].values) == list(lm.coords) and ds.attrs["model"] == lm.model.name
    assert ds.attrs["max_real"] == lm.max_real


def test_plot_and_html_show_the_verdict(lm):
    import matplotlib

    matplotlib.use("Agg")
    v = bs.eigen_analysis(lm).verdict()
    fig = lm.plot()
    ax = fig.axes[0]
    assert v.status in ax.get_title()
    assert sum(len(line.get_xdata()) for line in ax.lines if len(line.get_xdata()) > 2) == lm.eigenvalues.size
    html = lm._repr_html_()
    assert f"verdict: <b>{v.status}</b>" in html and lm.model.name in html
    assert html.count("<tr>") == 1 + min(8, lm.eigenvalues.size)


def test_results_render_as_html_in_notebooks(lm):
    """Every result a notebook shows has an HTML view, escaped text (never markup from values)."""
    space = bs.ParameterSpace.from_preset("paper-fig2")
    m = bs.stability_map(space, bs.Axis("k_ip", 1e5, 1e10, 5, log=True), bs.Axis("mu", 0.05, 1.0, 4))
    assert "xr-wrap" in m._repr_html_()  # xarray's own view of the Dataset
    r = bs.critical_speeds(bs.resolve_space(preset="paper-fig3", sets={"mu1": 0.5, "mu2": 0.5}), 1.0, 1e3)
    assert r._repr_html_() == "<pre>" + r.text().replace("&", "&amp;").replace("<", "&lt;").replace(
        ">", "&gt;").replace('"', "&quot;").replace("'", "&#x27;") + "</pre>"
    assert bs.eigen_analysis(lm)._repr_html_() == lm._repr_html_()
