"""The tutorial notebooks in ``examples/``: committed without outputs, and they run and tell the truth.

Each notebook is executed once with :mod:`nbclient` in a kernel that runs
this interpreter (``sys.executable``, so the venv of ``make test``) with
``MPLBACKEND=Agg`` and the test session's ``BRAKESQUEAL_CACHE_DIR``.  The kernel spec
is written to a temporary ``JUPYTER_PATH`` directory, so no kernel has to be registered
and a user's own ``python3`` kernel cannot be picked up by mistake.

Every notebook ends with a cell tagged ``summary`` that prints a JSON object.  The
tests compare its numbers with values computed here, independently of the notebook
(and, where they exist, with the numbers documented in ``docs/``).  The notebooks also
contain ``assert`` cells for their own claims; a failing cell fails the test.
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest

try:  # the test extra of pyproject.toml; missing packages must fail the run, not skip it
    import ipykernel  # noqa: F401  (provides the kernel)
    import nbclient
    import nbformat
except ImportError as exc:  # pragma: no cover
    raise ImportError(f"{exc}; the notebook tests need the test extra: pip install -e '.[test]'") from exc

import brakesqueal as bs
from brakesqueal.analysis.stability import parse_axis

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
NOTEBOOKS = {
    "01": "01-derive-and-linearize.ipynb",
    "02": "02-stability-maps-and-critical-speed.ipynb",
    "03": "03-simulation.ipynb",
    "04": "04-custom-model.ipynb",
    "05": "05-fe-matrices.ipynb",
}
KERNEL = "brakesqueal-notebook-test"
CELL_TIMEOUT = 300  # s; a whole notebook takes a few seconds with a warm cache


# ------------------------------------------------------------------ committed form
def test_every_notebook_is_tested():
    assert sorted(p.name for p in EXAMPLES.glob("*.ipynb")) == sorted(NOTEBOOKS.values())


@pytest.mark.parametrize("name", sorted(NOTEBOOKS.values()))
def test_committed_notebook_has_no_outputs(name):
    """Outputs are produced by running the notebook (here and by readers), never committed."""
    nb = nbformat.read(EXAMPLES / name, as_version=4)
    nbformat.validate(nb)
    dirty = [i for i, c in enumerate(nb.cells)
             if c.cell_type == "code" and (c.outputs or c.execution_count is not None)]
    assert not dirty, f"{name}: code cells {dirty} have outputs or execution counts; clear them before committing"
    assert nb.metadata.get("kernelspec", {}).get("name") == "python3"
    tagged = [c for c in nb.cells if "summary" in c.metadata.get("tags", [])]
    assert len(tagged) == 1 and tagged[0] is nb.cells[-1], f"{name}: the last cell must be the one tagged 'summary'"


# ------------------------------------------------------------------ execution
@pytest.fixture(scope="module")
def kernel_dir():
    """A kernel spec for this interpreter with MPLBACKEND=Agg, on a private JUPYTER_PATH."""
    with tempfile.TemporaryDirectory(prefix="brakesqueal-kernel-") as root:
        spec = Path(root, "kernels", KERNEL)
        spec.mkdir(parents=True)
        (spec / "kernel.json").write_text(json.dumps({
            "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "brakesqueal tests", "language": "python",
            "env": {"MPLBACKEND": "Agg", "PYDEVD_DISABLE_FILE_VALIDATION": "1"},
        }))
        old = os.environ.get("JUPYTER_PATH")
        os.environ["JUPYTER_PATH"] = root + (os.pathsep + old if old else "")
        try:
            yield root
        finally:
            if old is None:
                os.environ.pop("JUPYTER_PATH", None)
            else:
                os.environ["JUPYTER_PATH"] = old


def run(key: str, kernel_dir: str):
    """Execute a notebook in a scratch working directory; returns the executed notebook."""
    nb = nbformat.read(EXAMPLES / NOTEBOOKS[key], as_version=4)
    with tempfile.TemporaryDirectory(prefix="brakesqueal-nb-") as cwd:
        nbclient.NotebookClient(nb, kernel_name=KERNEL, timeout=CELL_TIMEOUT,
                                resources={"metadata": {"path": cwd}}).execute()
    return nb


def summary(nb) -> dict:
    """The JSON printed by the cell tagged ``summary``."""
    cell = next(c for c in nb.cells if "summary" in c.metadata.get("tags", []))
    text = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream" and o.name == "stdout")
    return json.loads(text)


def outputs_with(nb, mime: str) -> list[str]:
    return [o.data[mime] for c in nb.cells if c.cell_type == "code" for o in c.outputs
            if o.output_type in ("display_data", "execute_result") and mime in o.get("data", {})]


def rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b)


# ------------------------------------------------------------------ 01
@pytest.mark.slow
def test_01_derive_and_linearize(kernel_dir):
    nb = run("01", kernel_dir)
    s = summary(nb)
    ea = bs.eigen_analysis(bs.linearize(bs.get_preset("paper-fig2").resolve()))
    got = np.array([complex(*z) for z in s["eigenvalues"]])
    assert np.max(np.abs(got - ea.eigenvalues)) <= 1e-10 * np.max(np.abs(ea.eigenvalues))
    assert s["max_real"] == pytest.approx(0.18386885, rel=1e-6)  # docs/simulation.md: Re λ = 0.184 1/s
    assert s["frequencies_hz"][0] == pytest.approx(1739.111, rel=1e-6)
    assert np.allclose(s["damping_ratios"], ea.damping_ratios, rtol=1e-8)
    assert s["verdict"] == ea.verdict().status == "unstable"
    assert s["closed_form_error"] < 1e-12
    # docs/stability.md: the k_ip effect passes through K21, not D11
    assert s["k_ip_dominant_entry"] == "K21" and abs(s["k_ip_share"]["D11"]) < 0.01
    # the closed forms are shown as rendered LaTeX matrices
    latex = outputs_with(nb, "text/latex")
    assert len(latex) >= 5 and any(r"\bar{\mathbf{K}}" in t and r"\left[\begin{matrix}" in t for t in latex)
    cf = bs.closed_form("minimal")
    import sympy as sp

    assert any(sp.latex(cf.K, mat_delim="[") in t for t in latex)


# ------------------------------------------------------------------ 02
@pytest.mark.slow
def test_02_stability_maps_and_critical_speed(kernel_dir):
    nb = run("02", kernel_dir)
    s = summary(nb)
    # exact crossings on mu = 0.5, recomputed here, and the values documented in README/docs
    line = bs.crossings(bs.ParameterSpace.from_preset("paper-fig2", {"mu": 0.5}),
                        parse_axis("k_ip=1e5:1e10:log", with_num=False))
    A = next(v for v, d in line.crossings if d == "destabilizing")
    B = next(v for v, d in line.crossings if d == "stabilizing")
    assert rel(s["A_k_ip"], A) < 1e-9 and rel(s["B_k_ip"], B) < 1e-9
    assert s["A_k_ip"] == pytest.approx(1.866013e6, rel=1e-6)
    assert s["B_k_ip"] == pytest.approx(2.308813e5, rel=1e-6)
    assert s["A_K21_share"] > 0.99 and abs(s["A_D11_share"]) < 0.01
    # the map's verdicts on the mu = 0.5 row agree with eigenvalues of the numeric linearization
    row = s["map_row_mu_0_5"]
    assert s["map_shape"] == [96, 121] and len(row["k_ip"]) == 121
    preset = bs.get_preset("paper-fig2")
    checked = 0
    for kip, stable in zip(row["k_ip"], row["stable"]):
        v = bs.eigen_analysis(bs.linearize(preset.resolve({"mu": row["mu"], "k_ip": kip}))).verdict()
        if v.status == "undecided":  # ill-conditioned eigenvalues close to A or B (docs/stability.md)
            assert min(abs(math.log(kip / A)), abs(math.log(kip / B))) < 0.1, kip
            continue
        assert v.stable == stable, kip
        checked += 1
    assert checked >= 115
    assert 0.3 < s["map_stable_fraction"] < 0.5
    # Fig. 3: the critical speed at mu1 = mu2 = 0.5, recomputed here; U shape; docs/stability.md values
    for kip, documented in (("1e7", 37.065), ("inf", 35.601)):
        r = bs.critical_speeds(bs.ParameterSpace.from_preset("paper-fig3", {"k_ip": kip, "mu1": 0.5, "mu2": 0.5}))
        assert rel(s["fig3"][kip]["Omega_crit_at_equal_mu"], r.Omega_crit) < 1e-9
        assert r.Omega_crit == pytest.approx(documented, abs=1e-3)
        assert s["fig3"][kip]["argmin_mu_diff"] == 0.0
    assert 0.68 <= s["fig3"]["inf"]["stable_beyond_abs_mu_diff"] <= 0.72
    assert len(outputs_with(nb, "image/png")) >= 3


# ------------------------------------------------------------------ 03
@pytest.mark.slow
def test_03_simulation(kernel_dir):
    nb = run("03", kernel_dir)
    s = summary(nb)
    lam = bs.linearize(bs.get_preset("paper-fig2").resolve({"mu": 1.0, "h": 0.05})).eigenvalues[0]
    lam_stable = bs.linearize(bs.get_preset("paper-fig2").resolve({"mu": 0.5, "d1": 20.0, "d2": 20.0})).eigenvalues[0]
    assert complex(*s["lambda"]) == pytest.approx(lam, rel=1e-12)
    # nonlinear simulation from a modal start follows the linear eigenvalue (docs/simulation.md: 2 % / 0.1 %)
    m = s["modal"]
    assert m["status"] == "finished"
    assert rel(m["growth_rate"], lam.real) < 0.02
    assert rel(2 * math.pi * m["frequency_hz"], lam.imag) < 1e-3
    st = s["stable"]
    assert st["growth_rate"] < 0 and rel(st["growth_rate"], lam_stable.real) < 0.02
    # a generic start excites the damped mode too; the summary's modal projection removes it (issue 10)
    assert rel(s["generic"]["growth_rate"], lam.real) < 1e-4
    # large start: the upper pad lifts off after ~0.1 s (docs/simulation.md: t = 0.1003179 s at rtol 1e-10)
    assert s["large"]["status"] == "contact-loss"
    assert s["large"]["t_event"] == pytest.approx(0.1003179, abs=2e-4)
    # the WAV: 0.5 s at 44.1 kHz, mono 16 bit, whose spectrum peaks at the squeal frequency
    w = s["wav"]
    assert (w["frames"], w["rate"], w["channels"], w["sample_width"]) == (22051, 44100, 1, 2)
    assert abs(w["peak_hz"] - lam.imag / (2 * math.pi)) < 3.0
    assert len(outputs_with(nb, "image/png")) >= 2
    audio = outputs_with(nb, "text/html")
    assert any("<audio" in t for t in audio)


# ------------------------------------------------------------------ 04
@pytest.mark.slow
def test_04_custom_model(kernel_dir):
    from brakesqueal.model import spec_from_dict

    def linearize_model(spec, overrides):
        return bs.linearize(spec.get_preset().resolve(overrides))

    nb = run("04", kernel_dir)
    s = summary(nb)
    # rebuild the custom model from the TOML the notebook printed and linearize it here
    spec = spec_from_dict(tomllib.loads(s["toml"]))
    assert len(spec.pads) == 2 and all(p.friction.law == "stribeck" for p in spec.pads)
    for point in s["points"]:
        lm = linearize_model(spec, point["overrides"])
        got = np.array([complex(*z) for z in point["eigenvalues"]])
        assert np.max(np.abs(got - lm.eigenvalues)) <= 1e-9 * np.max(np.abs(lm.eigenvalues)), point["overrides"]
    # with mu_s = mu the Stribeck law is Coulomb's: the builder reproduces the paper's model
    paper = bs.linearize(bs.get_preset("paper-fig2").resolve()).eigenvalues
    lm = linearize_model(spec, {"mu_s": spec.parameters["mu"]})
    assert np.max(np.abs(lm.eigenvalues - paper)) <= 1e-9 * np.max(np.abs(paper))
    # every crossing the notebook reports changes the sign of the largest real part, checked here
    for mu_s, found in s["critical_speeds"].items():
        for omega, direction in found:
            lo = linearize_model(spec, {"mu_s": float(mu_s), "Omega": omega * (1 - 1e-4)}).max_real
            hi = linearize_model(spec, {"mu_s": float(mu_s), "Omega": omega * (1 + 1e-4)}).max_real
            assert (lo < 0 < hi) if direction == "destabilizing" else (hi < 0 < lo), (mu_s, omega)
    # two mechanisms: mode coupling above ~35 rad/s, and with mu_s > mu the massless pads' own mode
    # lambda = k_ip / (N0 |mu'(v*)|) > 0 (falling friction) at every speed: unstable from the start, no crossing
    assert [d for _, d in s["critical_speeds"]["0.5"]] == ["destabilizing"] and s["stable_at_start"]["0.5"]
    assert s["critical_speeds"]["1.0"] == [] and not s["stable_at_start"]["1.0"]
    for omega in (1.0, 3.0, 100.0):
        lm = linearize_model(spec, {"mu_s": 1.0, "Omega": omega})
        assert lm.pad_states and lm.max_real > 0
    # only the Coulomb row mu_s = mu (1 of 36) has a stable region: below the onset, 1 rad/s to ~37 rad/s
    assert s["map_shape"] == [36, 61] and 0.005 < s["map_stable_fraction"] < 1 / 36
    # the three-pad model: equal pads at 120 degrees keep the silent motion trivial
    three = s["three_pad"]
    assert three["n_pads"] == 3 and max(abs(q) for q in three["Q0"]) < 1e-12
    assert three["normal_forces"] == pytest.approx([3600.0] * 3, rel=1e-9)
    assert len(outputs_with(nb, "image/png")) >= 2


# ------------------------------------------------------------------ 05
@pytest.mark.slow
def test_05_fe_matrices(kernel_dir):
    """Against a dense QZ of the companion pencil (disk_brake100, from scipy.io.loadmat here) and the stored dense
    reference of the 4669-DOF brake (tests/data/fe/disk_brake4669_omega2pi_box.md)."""
    import scipy.io
    import scipy.linalg

    nb = run("05", kernel_dir)
    s = summary(nb)
    d = scipy.io.loadmat(EXAMPLES.parent / "src" / "brakesqueal" / "data" / "fe" / "nlevp-disk-brake-100"
                         / "disk_brake100.mat")
    r = {k: np.asarray(d[k], dtype=float) for k in ("M", "D1", "DR", "DG", "K1", "KR")}
    n = 100
    for w, status, max_real in s["verdicts"]:
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-(r["K1"] + r["KR"]), -(r["D1"] + r["DR"] / w + w * r["DG"])]])
        B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), r["M"]]])
        ref = scipy.linalg.eig(A, B, right=False).real.max()
        assert status == "unstable" and max_real == pytest.approx(ref, rel=1e-6)
    dense = json.load(open(Path(__file__).parent / "data" / "fe" / "disk_brake4669_omega2pi_box.json"))
    key = next(k for k in ("eigenvalues", "box_eigenvalues") if k in dense)
    ref = np.array([complex(*z) for z in dense[key]])
    inbox = ref[(np.abs(ref.real) <= 50) & (ref.imag / (2 * math.pi) <= 20000) & (ref.imag >= 0)]
    got = np.array([complex(*z) for z in s["box_eigenvalues"]])
    assert s["box_unstable"] == int(np.sum(inbox.real > 0)) == 3 and got.size == inbox.size
    for z in inbox:
        assert np.min(np.abs(got - z)) <= 1e-8 * abs(z)
    assert s["reduced_dim"] < 100 and s["reduced_max_rel_error"] < 1e-4
