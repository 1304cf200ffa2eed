"""``brakesqueal export`` for every model: the exported code is run (Python, C, Octave) and matches the library.

Models: every built-in model (paper, minimal, in-plane-pad, six-dof, eight-dof,
four-pad, belt) and a TOML model with angled pads on a floating caliper, one
of them with falling (rate-dependent) friction, a pad with a normal DOF and a
rigid one (:data:`ANGLED_TOML`).

Reference values come from the library, computed here with NumPy and never
from the exported code:

* residuals: the compiled model (``compile_model(spec).residuals``);
* pad unknowns: Newton's method on the library's ``G`` with its exact Jacobian
  columns (``dG/dl`` of quasi-static pads, ``dG/dldot`` of pads with
  rate-dependent friction, which keep their dynamics; which pads those are is
  taken from the library's own ``rate_free_at_zero``);
* right-hand side: ``M = dR/dQddot`` from the compiled Jacobian and
  ``f = R(Qddot = 0)``, ``Qddot = -numpy.linalg.solve(M, f)``;
* linear matrices: :func:`brakesqueal.analysis.linear.linearize` at
  parameter points whose silent motion is trivial (checked), and the
  library's batched zero-state elimination ``CompiledModel.zero_linear`` at
  arbitrary parameters.

"1e-12 relative" is normwise over each group of entries with the same unit
(so that an entry that is 0 in one and 1e-20 in the other does not count as a
relative error of 1).  Julia is not installable here (no Debian package): its
generated functions are translated line by line to Python and evaluated, its
hand-written helpers are checked as text.  Octave runs if it is installed
(``apt-get install octave``); LaTeX compiles if ``pdflatex`` exists.
"""

from __future__ import annotations

import ctypes
import importlib.util
import math
import re
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from brakesqueal import silent_motion
from brakesqueal import linearize
from brakesqueal.cli import main
from brakesqueal.codegen import compile_model
from brakesqueal.errors import ParameterError
from brakesqueal.export import TARGETS, export_code, export_model
from brakesqueal.model.library import get_model, resolve_model
from brakesqueal.model.options import resolve_space
from brakesqueal.model.parameters import Parameters

pytestmark = pytest.mark.slow  # module fixtures dominate: the whole module runs in `make test-slow`

RTOL = 1e-12
BUILT_IN = ("paper", "minimal", "in-plane-pad", "six-dof", "eight-dof", "four-pad", "belt")
ANGLED = "angled"
MODELS = (*BUILT_IN, ANGLED)

ANGLED_TOML = """
name = "angled-caliper"
description = "Pads at 30 degrees on a floating caliper (one with falling friction), a pad with a normal DOF and a rigid pad at 210 degrees."

[parameters]
Theta = 0.16
Phi = 0.32
k_t = 1.88e7
d_t = 0.1
h10 = 0.01
h20 = 0.01
Omega = 50.0
r = 0.1
k = 6e6
d = 5.0
N0 = 3000.0
mu = 0.5
k_ipa = 1e8
k_ipb = 5e7
mu0 = 0.6
slope = 0.02
m_p = 0.4
k_c = 1e9
d_c = 20.0
m_c = 3.0
k_cn = 5e7
k_ct = 5e7
d_cn = 100.0
d_ct = 100.0

[disk]

[[pads]]
name = "a"
face = "upper"
angle_deg = 30.0
k = "k"
d = "d"
k_ip = "k_ipa"
friction = { law = "coulomb", mu = "mu" }
mount = "cal"

[[pads]]
name = "b"
face = "lower"
angle_deg = 30.0
k = "k"
d = "d"
k_ip = "k_ipb"
friction = { law = "linear", mu = "mu0", slope = "slope" }
mount = "cal"

[[pads]]
name = "c"
face = "upper"
angle_deg = 210.0
k = "k"
d = "d"
mass = "m_p"
dofs = ["normal"]
k_c = "k_c"
d_c = "d_c"
friction = { law = "coulomb", mu = "mu" }

[[pads]]
name = "d"
face = "lower"
angle_deg = 210.0
k = "k"
d = "d"
friction = { law = "coulomb", mu = "mu" }

[[calipers]]
name = "cal"
mass = "m_c"
k_n = "k_cn"
d_n = "d_cn"
k_t = "k_ct"
d_t = "d_ct"
"""

NONTRIVIAL_TOML = """
[parameters]
Theta = 0.16
Phi = 0.32
k_t = 1.88e7
d_t = 0.1
k1 = 6e6
k2 = 6e6
d1 = 5.0
d2 = 5.0
k_ip1 = 1e8
k_ip2 = "inf"
mu1 = 0.6
mu2 = 0.4
h10 = 0.012
h20 = 0.01
r = 0.13
N0 = 3000.0
Omega = 50.0
"""


# ---------------------------------------------------------------- comparisons
def close(a, b, rtol=RTOL) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and float(np.max(np.abs(a - b), initial=0.0)) <= rtol * float(np.max(np.abs(b), initial=0.0))


def close_grouped(a, b, kinds, rtol=RTOL) -> bool:
    """Normwise per group of entries of the same kind (unit)."""
    a, b, kinds = np.asarray(a, dtype=float), np.asarray(b, dtype=float), np.asarray(kinds)
    return a.shape == b.shape and all(close(a[kinds == k], b[kinds == k], rtol) for k in set(kinds.tolist()))


def close_matrix(a, b, rows, cols, rtol=RTOL) -> bool:
    """Normwise per block of rows and columns of the same kinds."""
    a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
    if a.shape != b.shape:
        return False
    rk, ck = np.asarray(rows), np.asarray(cols)
    return all(close(a[np.ix_(rk == r, ck == c)], b[np.ix_(rk == r, ck == c)], rtol)
               for r in set(rk.tolist()) for c in set(ck.tolist()))  # fmt: skip


def kind(name: str) -> str:
    return "rad" if name.startswith("q") else "m"


# ---------------------------------------------------------------- the cases
@dataclass
class Case:
    name: str
    spec: Any
    cm: Any
    params: Parameters
    kept: tuple[str, ...]
    points: list[tuple[np.ndarray, np.ndarray]]
    trivial: list[Parameters]

    @property
    def n(self) -> int:
        return self.cm.n

    @property
    def m(self) -> int:
        return self.cm.m

    @property
    def kept_mask(self) -> np.ndarray:
        return np.array([a in self.kept for a in self.cm.algebraic], dtype=bool)

    def split(self, y, z):
        """Full state x from the ODE state y and the pad unknowns z."""
        n, m, kmask = self.n, self.m, self.kept_mask
        L, dL = np.zeros(m), np.zeros(m)
        L[~kmask] = np.asarray(z)[~kmask]
        L[kmask] = np.asarray(y)[2 * n:]
        dL[kmask] = np.asarray(z)[kmask]
        return [*y[: 2 * n], *np.zeros(n), *L, *dL]

    def y_of(self, x):
        n, m = self.n, self.m
        return np.concatenate([x[: 2 * n], np.asarray(x[3 * n: 3 * n + m])[self.kept_mask]])

    @property
    def coord_kinds(self) -> list[str]:
        return [kind(c) for c in self.cm.coords]

    @property
    def z_kinds(self) -> list[str]:
        return ["m/s" if k else "m" for k in self.kept_mask]

    @property
    def dydt_kinds(self) -> list[str]:
        c = self.coord_kinds
        return [f"{k}/s" for k in c] + [f"{k}/s2" for k in c] + ["m/s"] * int(self.kept_mask.sum())

    @property
    def res_kinds(self) -> list[str]:
        return [f"R{kind(c)}" for c in self.cm.coords] + ["G"] * self.m


def ref_pads(case: Case, y, p) -> np.ndarray:
    """Pad unknowns by Newton on the library's G with its exact Jacobian columns (30 steps from 0)."""
    n, m = case.n, case.m
    cols = [3 * n + m + j if k else 3 * n + j for j, k in enumerate(case.kept_mask)]
    z = np.zeros(m)
    for _ in range(30):
        x = case.split(y, z)
        g = np.asarray(case.cm.residuals(x, list(p)))[n:]
        J = case.cm.jacobian_matrix(x, list(p))[n:, cols]
        z = z - np.linalg.solve(J, g)
    return z


def ref_state_derivative(case: Case, y, z, p) -> np.ndarray:
    n = case.n
    x = case.split(y, z)
    f = np.asarray(case.cm.residuals(x, list(p)))[:n]
    M = case.cm.jacobian_matrix(x, list(p))[:n, 2 * n:3 * n]
    return np.concatenate([y[n:2 * n], -np.linalg.solve(M, f), np.asarray(z)[case.kept_mask]])


def _tie(name: str, v: dict[str, float]) -> dict[str, float]:
    """Parameter relations under which the zero state is the silent motion (e.g. eq. 49)."""
    if name in ("paper", "six-dof", "eight-dof"):
        v["h20"] = v["mu1"] * v["h10"] / v["mu2"]
    elif name in ("minimal", "in-plane-pad", "four-pad", ANGLED):
        v["h20"] = v["h10"]
    if name == ANGLED:
        v["mu0"] = v["mu"] + v["slope"] * v["Omega"] * v["r"]  # mu_b(Omega r) = mu_a
    return v


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("export")


@pytest.fixture(scope="module")
def angled_path(workdir) -> Path:
    path = workdir / "angled.toml"
    path.write_text(ANGLED_TOML)
    return path


@pytest.fixture(scope="module")
def cases(angled_path) -> dict[str, Case]:
    rng = np.random.default_rng(20261123)
    out = {}
    for name in MODELS:
        spec = resolve_model(str(angled_path)) if name == ANGLED else get_model(name)
        cm = compile_model(spec)
        params = resolve_space(spec).resolve({})
        kept = tuple(a for a, free in zip(cm.algebraic, cm.rate_free_at_zero) if not free)
        base = params.vector()
        n, m = cm.n, cm.m
        tilt = np.array([c.startswith("q") for c in cm.coords])
        # compliances that may be 0: massless pads that are quasi-static (a kept pad needs c > 0, see the header)
        names = list(spec.parameters)
        lname = {(f"l{q.name}" if q.name.isdigit() else f"l_{q.name}"): q for q in spec.pads}
        rigid = [names.index(lname[a].k_ip) for a in cm.algebraic if a not in kept and isinstance(lname[a].k_ip, str)]
        points = []
        for k in range(4):
            p = base * rng.uniform(0.7, 1.4, base.size)
            if k == 1:
                p[rigid] = 0.0  # rigid tangential supports of the quasi-static massless pads
            Q = np.where(tilt, rng.uniform(-0.05, 0.05, n), rng.uniform(-2e-6, 2e-6, n))
            dQ = np.where(tilt, rng.uniform(-5, 5, n), rng.uniform(-1e-2, 1e-2, n))
            ddQ = np.where(tilt, rng.uniform(-1e3, 1e3, n), rng.uniform(-10, 10, n))
            x = np.concatenate([Q, dQ, ddQ, rng.uniform(-1e-6, 1e-6, m), rng.uniform(-1e-3, 1e-3, m)])
            points.append((x, p))
        trivial = []
        for _ in range(3):
            v = {k: (val if math.isinf(val) else val * rng.uniform(0.8, 1.25)) for k, val in params.items()}
            pt = Parameters(spec, _tie(name, v))
            assert silent_motion(pt).trivial, (name, pt)
            trivial.append(pt)
        out[name] = Case(name, spec, cm, params, kept, points, trivial)
    return out


def model_option(name: str, angled_path: Path) -> str:
    return str(angled_path) if name == ANGLED else name


@pytest.fixture(scope="module")
def exported(cases, workdir, angled_path) -> dict[tuple[str, str, str], Path]:
    """Every model exported to every target, through the command line (one file each)."""
    out = {}
    for name in MODELS:
        for what in ("nonlinear", "linear"):
            for target, suffix in TARGETS.items():
                stem = f"bs_{name.replace('-', '_')}_{what[:3]}"
                path = workdir / target / f"{stem}{suffix}"
                path.parent.mkdir(exist_ok=True)
                assert main(["export", "--to", target, "--what", what, "--model", model_option(name, angled_path),
                             "--out", str(path)]) == 0  # fmt: skip
                out[(name, what, target)] = path
    return out


# ----------------------------------------------------------------------- Python
def _import(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def python_modules(exported) -> dict[tuple[str, str], Any]:
    return {(name, what): _import(exported[(name, what, "python")]) for name in MODELS
            for what in ("nonlinear", "linear")}  # fmt: skip


class Api:
    """The exported functions of one language behind one interface (values as NumPy arrays)."""

    def residuals(self, x, p): ...
    def pad_residuals(self, y, z, p): ...
    def solve_pads(self, y, p): ...
    def state_derivative(self, y, z, p): ...
    def rhs(self, y, p): ...
    def linear(self, p): ...
    def parameters(self): ...


class PythonApi(Api):
    def __init__(self, mods, name):
        self.mod, self.lin = mods[(name, "nonlinear")], mods[(name, "linear")]

    def residuals(self, x, p):
        return np.array(self.mod.residuals(list(x), list(p)))

    def pad_residuals(self, y, z, p):
        return np.array(self.mod.pad_residuals(list(y), list(z), list(p)))

    def solve_pads(self, y, p):
        return np.array(self.mod.solve_pads(list(y), list(p)), dtype=float)

    def state_derivative(self, y, z, p):
        return np.array(self.mod.state_derivative(list(y), list(z), list(p)))

    def rhs(self, y, p):
        return np.array(self.mod.rhs(0.0, list(y), list(p)))

    def linear(self, p):
        return [np.array(m, dtype=float) for m in self.lin.linear_matrices(list(p))]

    def parameters(self):
        return list(self.mod.parameters())


def check_nonlinear(api: Api, case: Case) -> None:
    n, m = case.n, case.m
    for x, p in case.points:
        r = api.residuals(x, p)
        ref = np.asarray(case.cm.residuals(list(x), list(p)))
        assert close_grouped(r, ref, case.res_kinds), (case.name, r, ref)
        y = case.y_of(x)
        z_ref = ref_pads(case, y, p)
        if m:  # away from the solution, where G is not at rounding level
            zt = perturbed_pads(case, z_ref)
            g = api.pad_residuals(y, zt, p)
            xr = case.split(y, zt)
            J = case.cm.jacobian_matrix(xr, list(p))
            cols = [3 * n + m + j if k else 3 * n + j for j, k in enumerate(case.kept_mask)]
            gr = np.asarray(case.cm.residuals(xr, list(p)))[n:]
            assert close(g[:m], gr), (case.name, g[:m] - gr, gr)
            assert close_grouped(g[m:], J[n:, cols].diagonal(), case.z_kinds), case.name
        z = api.solve_pads(y, p)
        assert z.shape == (m,) and close_grouped(z, z_ref, case.z_kinds), (case.name, z, z_ref)
        dydt_ref = ref_state_derivative(case, y, z_ref, p)
        assert close_grouped(api.state_derivative(y, z_ref, p), dydt_ref, case.dydt_kinds), case.name
        f = api.rhs(y, p)
        assert close_grouped(f, dydt_ref, case.dydt_kinds), case.name
        assert list(f[:n]) == list(y[n:2 * n])  # Qdot is copied exactly
    assert api.parameters() == [float(v) for v in case.params.vector()]


def ref_linear(case: Case, params: Parameters) -> list[np.ndarray]:
    lm = linearize(params, pad_rates="kept")
    if not case.kept:
        qs = linearize(params, pad_rates="quasi-static")
        assert np.array_equal(qs.M, lm.M) and np.array_equal(qs.D, lm.D) and np.array_equal(qs.K, lm.K)
        return [lm.M, lm.D, lm.K]
    assert lm.pad_states == case.kept and not np.any(lm.G_ddQ)  # G does not depend on Qddot
    return [lm.M, lm.D, lm.K, lm.R_L, lm.R_dL, lm.G_Q, lm.G_dQ, lm.G_L, lm.G_dL]


def check_linear(api: Api, case: Case) -> None:
    rows, k = case.coord_kinds, len(case.kept)
    kinds = [(rows, rows)] * 3 + [(rows, ["m"] * k)] * 2 + [(["m"] * k, rows)] * 2 + [(["m"] * k, ["m"] * k)] * 2
    for params in case.trivial:
        p = params.vector()
        got, want = api.linear(p), ref_linear(case, params)
        assert len(got) == len(want)
        for g, w, (rk, ck) in zip(got, want, kinds):
            assert close_matrix(g, w, rk, ck), (case.name, g, w)
    if not case.kept:  # the closed form is an identity in p: compare anywhere with the batched elimination
        for _, p in case.points:
            got = api.linear(p)
            for g, w in zip(got, case.cm.zero_linear(list(p))):
                assert close_matrix(g, np.asarray(w), rows, rows), case.name


@pytest.mark.parametrize("name", MODELS)
def test_python_nonlinear_matches_library(python_modules, cases, name):
    check_nonlinear(PythonApi(python_modules, name), cases[name])


@pytest.mark.parametrize("name", MODELS)
def test_python_linear_matches_library(python_modules, cases, name):
    check_linear(PythonApi(python_modules, name), cases[name])


def test_pads_that_keep_their_dynamics(cases, exported, python_modules):
    """The falling-friction pad keeps its first-order dynamics; the Coulomb pads are quasi-static."""
    case = cases[ANGLED]
    assert case.kept == ("l_b",)
    desc = export_model("nonlinear", case.params)
    assert desc.kept == ("l_b",) and desc.y_names[-1] == "l_b" and desc.z_names == ("l_a", "dl_b")
    text = exported[(ANGLED, "nonlinear", "python")].read_text()
    assert "y = (q1, q2, w_c, wc_cal, uc_cal, dq1, dq2, dw_c, dwc_cal, duc_cal, l_b)" in text
    assert "z = (l_a, dl_b) [m, m/s]" in text
    lin = exported[(ANGLED, "linear", "python")].read_text()
    assert "descriptor system" in lin and "R_dL = (R_dL11, R_dL21, R_dL31, R_dL41, R_dL51)" in lin
    # at the silent motion the pad unknowns are zero and so is dy/dt (the Newton solve stops at rounding level)
    mod = python_modules[(ANGLED, "nonlinear")]
    p = list(case.trivial[0].vector())
    y0 = [0.0] * (2 * case.n + 1)
    assert np.max(np.abs(mod.solve_pads(y0, p))) < 1e-12
    assert np.max(np.abs(mod.rhs(0.0, y0, p))) < 1e-6


def test_header_lists_argument_order_and_units(exported):
    text = exported[("paper", "nonlinear", "python")].read_text()
    assert "x = (q1, q2, dq1, dq2, ddq1, ddq2, l1, l2, dl1, dl2)" in text
    assert "y = (q1, q2, dq1, dq2) [rad, rad, rad/s, rad/s];  l = (l1, l2) [m, m]" in text
    assert "p = (Theta, Phi, k_t, d_t, k1, k2, d1, d2, c_ip1, c_ip2, mu1, mu2, h10, h20, r, N0, Omega)" in text
    assert "[kg m^2, kg m^2, N m/rad, N m s/rad, N/m, N/m, N s/m, N s/m, m/N, m/N, 1, 1, m, m, m, N, rad/s]" in text
    assert "c_ip1 = 1/k_ip1" in text
    assert re.search(r"^\s+w50 = ", text, re.M)  # common subexpressions were eliminated
    six = exported[("six-dof", "nonlinear", "python")].read_text()
    assert "x = (q1, q2, w1, u1, w2, u2, dq1, dq2, dw1, du1, dw2, du2, ddq1, ddq2, ddw1, ddu1, ddw2, ddu2)" in six
    assert "[rad, rad, m, m, m, m, rad/s, rad/s, m/s, m/s, m/s, m/s, rad/s^2, rad/s^2, m/s^2," in six
    assert "res = (psi1, psi2, R_w1, R_u1, R_w2, R_u2) [N m, N m, N, N, N, N]" in six
    assert "c_ip1 = 1/k_ip1" in six and "m_p" in six
    # the pads' coordinates w1, w2 would clash with CSE symbols w1, w2: another prefix is used
    assert not re.search(r"^\s+w\d+ = (?![xyp]\[)", six, re.M) and re.search(r"^\s+t40 = ", six, re.M)
    belt = exported[("belt", "linear", "python")].read_text()
    assert "M = (M11) [kg]; D = (D11) [N s/m]; K = (K11) [N/m]" in belt


def test_parameters_are_the_chosen_set(tmp_path, angled_path):
    path = tmp_path / "bs_fig3.py"
    assert main(["export", "--to", "python", "--preset", "paper-fig3", "--set", "mu1=0.7", "--out", str(path)]) == 0
    want = [float(v) for v in resolve_space(None, "paper-fig3", None, ["mu1=0.7"]).resolve({}).vector()]
    assert list(_import(path).parameters()) == want
    assert "preset paper-fig3, --set mu1=0.7" in path.read_text()
    # a rigid support (k_ip = inf) of a massless pad is the compliance 0 (pads with a tangential DOF refuse inf)
    path = tmp_path / "bs_paper.py"
    assert main(["export", "--to", "python", "--model", "paper", "--set", "k_ip1=inf", "--set", "N0=5",
                 "--out", str(path)]) == 0  # fmt: skip
    want = resolve_space("paper", None, None, ["k_ip1=inf", "N0=5"]).resolve({}).vector()
    got = _import(path).parameters()
    assert list(got) == [float(v) for v in want] and got[list(get_model("paper").parameters).index("k_ip1")] == 0
    assert "model paper, preset paper, --set k_ip1=inf N0=5" in path.read_text()


def test_paper_closed_form_is_the_general_case():
    """model_closed_form of the paper's model equals closed_form('general') symbolically (the linear export's basis)."""
    import sympy as sp

    from brakesqueal.symbolic.linearize import closed_form, model_closed_form

    a, b = model_closed_form(get_model("paper")), closed_form("general")
    subs = {a.symbols[n]: b.symbols[n] for n in a.symbols if n in b.symbols}
    for ma, mb in ((a.M, b.M), (a.D, b.D), (a.K, b.K)):
        assert sp.simplify(ma.xreplace(subs) - mb) == sp.zeros(2, 2)


# ---------------------------------------------------------------------------- C
@pytest.fixture(scope="module")
def c_libs(exported) -> dict[tuple[str, str], ctypes.CDLL]:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not on PATH")

    def build(key):
        src = exported[(*key, "c")]
        so = src.with_suffix(".so")
        res = subprocess.run([gcc, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                              "-o", str(so), str(src), "-lm"], capture_output=True, text=True)  # fmt: skip
        assert res.returncode == 0, res.stderr[-3000:]
        return key, so

    keys = [(name, what) for name in MODELS for what in ("nonlinear", "linear")]
    with ThreadPoolExecutor(max_workers=2) as pool:
        built = list(pool.map(build, keys))
    return {key: ctypes.CDLL(str(so)) for key, so in built}


def _arr(values=None, n=None):
    v = [0.0] * n if values is None else [float(a) for a in values]
    return (ctypes.c_double * max(len(v), 1))(*v)


class CApi(Api):
    def __init__(self, libs, case):
        self.lib, self.lin, self.case = libs[(case.name, "nonlinear")], libs[(case.name, "linear")], case
        self.lib.brakesqueal_rhs.argtypes = [ctypes.c_double] + [ctypes.c_void_p] * 3

    def residuals(self, x, p):
        out = _arr(n=self.case.n + self.case.m)
        self.lib.brakesqueal_residuals(_arr(x), _arr(p), out)
        return np.array(out[:])

    def pad_residuals(self, y, z, p):
        out = _arr(n=2 * self.case.m)
        self.lib.brakesqueal_pad_residuals(_arr(y), _arr(z), _arr(p), out)
        return np.array(out[:])

    def solve_pads(self, y, p):
        z = _arr(n=self.case.m)
        assert self.lib.brakesqueal_solve_pads(_arr(y), _arr(p), z) == 0
        return np.array(z[: self.case.m])

    def state_derivative(self, y, z, p):
        out = _arr(n=len(y))
        assert self.lib.brakesqueal_state_derivative(_arr(y), _arr(z), _arr(p), out) == 0
        return np.array(out[:])

    def rhs(self, y, p):
        out = _arr(n=len(y))
        assert self.lib.brakesqueal_rhs(0.0, _arr(y), _arr(p), out) == 0
        return np.array(out[:])

    def linear(self, p):
        n, k = self.case.n, len(self.case.kept)
        shapes = [(n, n)] * 3 + ([(n, k)] * 2 + [(k, n)] * 2 + [(k, k)] * 2 if k else [])
        outs = [_arr(n=r * c) for r, c in shapes]
        self.lin.brakesqueal_linear_matrices(_arr(p), *outs)
        return [np.array(o[: r * c]).reshape(r, c) for o, (r, c) in zip(outs, shapes)]

    def parameters(self):
        out = _arr(n=len(self.case.params))
        self.lib.brakesqueal_parameters(out)
        return list(out)


@pytest.mark.parametrize("name", MODELS)
def test_c_matches_library(c_libs, cases, name):
    api = CApi(c_libs, cases[name])
    check_nonlinear(api, cases[name])
    check_linear(api, cases[name])


def test_c_reports_failures(c_libs, cases):
    """A kept pad on a rigid support (c = 1/k_ip = 0: G does not depend on its rate) gives status 1, not NaN."""
    case = cases[ANGLED]
    lib = c_libs[(ANGLED, "nonlinear")]
    p = case.params.vector().copy()
    p[list(case.spec.parameters).index("k_ipb")] = 0.0
    y = case.y_of(case.points[0][0])
    z = _arr(n=case.m)
    assert lib.brakesqueal_solve_pads(_arr(y), _arr(p), z) == 1
    out = _arr(n=2 * case.n + 1)
    lib.brakesqueal_rhs.argtypes = [ctypes.c_double] + [ctypes.c_void_p] * 3
    assert lib.brakesqueal_rhs(0.0, _arr(y), _arr(p), out) == 1
    # where G = 0 already holds (the zero state) the solve stops at once with z = 0
    assert lib.brakesqueal_solve_pads(_arr(np.zeros(2 * case.n + 1)), _arr(p), z) == 0 and list(z) == [0.0, 0.0]


# ----------------------------------------------------------------------- Octave
def _octave_matrix(values) -> str:
    return "[" + "; ".join(" ".join(repr(float(v)) for v in row) for row in np.atleast_2d(values)) + "]"


def perturbed_pads(case: Case, z_ref: np.ndarray) -> np.ndarray:
    """Pad unknowns away from the solution, where G is not at rounding level."""
    return z_ref + np.where(case.kept_mask, 1e-2, 1e-5) * np.linspace(1.0, 2.0, case.m)


@pytest.fixture(scope="module")
def octave_rows(cases, exported, workdir) -> dict[str, dict[str, list[list[float]]]]:
    """One Octave run over every model, in the order check_nonlinear and check_linear ask for the values."""
    octave = shutil.which("octave-cli") or shutil.which("octave")
    if octave is None:
        pytest.skip("GNU Octave is not on PATH (apt-get install -y octave); the other targets are tested")
    lines = ["1;", "function out(key, v)", "  printf('%s', key); printf(' %.17g', v); printf('\\n');", "end"]
    for name in MODELS:
        case = cases[name]
        nl, li = exported[(name, "nonlinear", "octave")].stem, exported[(name, "linear", "octave")].stem
        X = np.array([x for x, _ in case.points])
        P = np.array([p for _, p in case.points])
        Y = np.array([case.y_of(x) for x in X])
        Z = np.array([ref_pads(case, y, p) for y, p in zip(Y, P)]).reshape(len(X), case.m)
        ZT = np.array([perturbed_pads(case, z) for z in Z]).reshape(len(X), case.m)
        PT = np.array([t.vector() for t in case.trivial] + ([] if case.kept else list(P)))
        key = name.replace("-", "_")
        mat = (lambda A: _octave_matrix(A) if A.size else f"zeros({A.shape[0]}, 0)")  # noqa: E731
        lines += [f"m = {nl}(); ml = {li}();", f"X = {mat(X)}; P = {mat(P)}; Y = {mat(Y)};",
                  f"Z = {mat(Z)}; ZT = {mat(ZT)}; PT = {mat(PT)};",
                  "for i = 1:rows(X)", "  p = P(i, :)'; y = Y(i, :)';",
                  f"  out('{key}:res', m.residuals(X(i, :)', p));",
                  f"  out('{key}:pr', m.pad_residuals(y, ZT(i, :)', p));" if case.m else "",
                  f"  out('{key}:pads', m.solve_pads(y, p));",
                  f"  out('{key}:sd', m.state_derivative(y, Z(i, :)', p));",
                  f"  out('{key}:rhs', m.rhs(0, y, p));", "end",
                  "for i = 1:rows(PT)", "  c = cell(1, nargout(ml.linear_matrices));",
                  "  [c{:}] = ml.linear_matrices(PT(i, :)');",
                  f"  for j = 1:numel(c) out(sprintf('{key}:lin%d', j), reshape(c{{j}}.', 1, [])); end", "end",
                  f"out('{key}:par', m.parameters());"]  # fmt: skip
    (workdir / "octave" / "driver.m").write_text("\n".join(lines) + "\n")
    res = subprocess.run([octave, "--no-gui", "--quiet", "--no-window-system", "driver.m"], cwd=workdir / "octave",
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert res.returncode == 0, res.stderr[-3000:]
    rows: dict[str, dict[str, list[list[float]]]] = {}
    for line in res.stdout.splitlines():
        if line.strip():
            head, *vals = line.split()
            model, key = head.split(":")
            rows.setdefault(model, {}).setdefault(key, []).append([float(v) for v in vals])
    return rows


class OctaveApi(Api):
    """Replays the Octave run's values in the order check_nonlinear and check_linear ask for them."""

    def __init__(self, rows, case):
        self.rows, self.case = rows[case.name.replace("-", "_")], case
        self.i: dict[str, int] = {}

    def _next(self, key):
        j = self.i.get(key, 0)
        self.i[key] = j + 1
        return np.array(self.rows[key][j])

    def residuals(self, x, p):
        return self._next("res")

    def pad_residuals(self, y, z, p):
        return self._next("pr")

    def solve_pads(self, y, p):
        return self._next("pads")

    def state_derivative(self, y, z, p):
        return self._next("sd")

    def rhs(self, y, p):
        return self._next("rhs")

    def linear(self, p):
        n, k = self.case.n, len(self.case.kept)
        shapes = [(n, n)] * 3 + ([(n, k)] * 2 + [(k, n)] * 2 + [(k, k)] * 2 if k else [])
        return [self._next(f"lin{t + 1}").reshape(s) for t, s in enumerate(shapes)]

    def parameters(self):
        return list(self.rows["par"][0])


@pytest.mark.parametrize("name", MODELS)
def test_octave_matches_library(octave_rows, cases, name):
    api = OctaveApi(octave_rows, cases[name])
    check_nonlinear(api, cases[name])
    check_linear(api, cases[name])


def test_octave_text(exported):
    text = exported[("paper", "nonlinear", "octave")].read_text()
    assert text.startswith("function m = bs_paper_non()\n")
    for fn in ("residuals", "pad_residuals", "pad_residual_scale", "mass_force", "solve_pads", "state_derivative",
               "rhs", "parameters"):
        assert f"  m.{fn} = @{fn};" in text
    assert "function res = residuals(x, p)" in text and "  Omega = p(17);" in text
    assert "function [M, f] = mass_force(y, l, p)" in text and "-(M \\ f)" in text
    assert 1 + text.count("\nfunction ") == text.count("\nend\n")  # every function closed at column 0
    lin = exported[("eight-dof", "linear", "octave")].read_text()
    assert "function [M, D, K] = linear_matrices(p)" in lin
    line = next(ln for ln in lin.splitlines() if ln.startswith("  M = ["))
    assert line.count("; ") == 7 and line.count(", ") == 8 * 7 and line.endswith("];")  # 8 x 8


# ------------------------------------------------------------------------ Julia
def _julia_body(text: str, fn: str) -> list[str]:
    return text.split(f"\nfunction {fn}(", 1)[1].split("\nend\n", 1)[0].split("\n")[1:]


def _run_julia_as_python(text: str, fn: str, args: dict[str, list[float]]) -> Any:
    """Evaluate one generated Julia function by translating its assignments to Python."""
    env: dict = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "exp": math.exp,
                 "abs": abs, "pi": math.pi, "reshape": lambda v, r, c: np.array(v, dtype=float).reshape(c, r).T,
                 **args}  # fmt: skip
    for line in _julia_body(text, fn):
        line = line.strip()
        if line.startswith("return "):
            return eval("(" + line[len("return "):] + ",)", env)  # noqa: S307 - our own generated, translated text
        name, expr = line.split(" = ", 1)
        expr = re.sub(r"\b([xyzlp])\[(\d+)\]", lambda m: f"{m.group(1)}[{int(m.group(2)) - 1}]", expr)  # 1-based
        expr = expr.replace(".^", "**").replace(".*", "*").replace("./", "/").replace("//", "/")
        if expr.startswith("[") and "; " in expr:  # a matrix literal [a b; c d]
            expr = "[" + ", ".join("[" + ", ".join(r.split()) + "]" for r in expr[1:-1].split("; ")) + "]"
        env[name] = eval(expr, env)  # noqa: S307
    raise AssertionError(f"no return in {fn}")


def _julia_blocks_balanced(text: str) -> bool:
    body = text.split("module BrakesquealModel", 1)[1]
    opens = len(re.findall(r"^\s*(function|for|if|module)\b", body, re.M)) + 1  # + the module itself
    return opens == len(re.findall(r"^\s*end\b", body, re.M))


@pytest.mark.parametrize("name", MODELS)
def test_julia_text_and_translated_values(exported, cases, name):
    case = cases[name]
    text = exported[(name, "nonlinear", "julia")].read_text()
    assert "module BrakesquealModel" in text and text.rstrip().endswith("end # module")
    assert _julia_blocks_balanced(text)
    assert "export residuals, " in text and "solve_pads, state_derivative, rhs, parameters" in text
    assert "rhs(t, y, p) = state_derivative(y, solve_pads(y, p), p)" in text
    for x, p in case.points[:2]:
        (r,) = _run_julia_as_python(text, "residuals", {"x": list(x), "p": list(p)})
        assert close_grouped(r, case.cm.residuals(list(x), list(p)), case.res_kinds)
        y = case.y_of(x)
        z = ref_pads(case, y, p)
        M, f = _run_julia_as_python(text, "mass_force", {"y": list(y), ("z" if case.kept else "l"): list(z),
                                                          "p": list(p)})  # fmt: skip
        acc = -np.linalg.solve(np.atleast_2d(np.array(M, dtype=float)), np.array(f, dtype=float))
        assert close_grouped(acc, ref_state_derivative(case, y, z, p)[case.n:2 * case.n], case.coord_kinds)
    lin = exported[(name, "linear", "julia")].read_text()
    assert _julia_blocks_balanced(lin)
    for params in case.trivial[:1]:
        got = _run_julia_as_python(lin, "linear_matrices", {"p": list(params.vector())})
        for g, w in zip(got, ref_linear(case, params)):
            assert np.shape(g) == w.shape and close(g, w, rtol=1e-11)


def test_julia_runs_if_available(tmp_path, exported, cases):
    julia = shutil.which("julia")
    if julia is None:
        pytest.skip("julia is not on PATH (no Debian package); the exported text is tested above")
    case = cases["eight-dof"]
    src = exported[("eight-dof", "nonlinear", "julia")]
    y = case.y_of(case.points[0][0])
    p = case.points[0][1]
    script = f"""include("{src}"); using .BrakesquealModel
for v in rhs(0.0, {list(map(float, y))}, {list(map(float, p))}); println(repr(v)); end
"""
    (tmp_path / "driver.jl").write_text(script)
    res = subprocess.run([julia, "driver.jl"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    got = [float(v) for v in res.stdout.split()]
    assert close_grouped(got, ref_state_derivative(case, y, ref_pads(case, y, p), p), case.dydt_kinds)


# ------------------------------------------------------------------------ LaTeX
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("what", ["nonlinear", "linear"])
def test_latex_standalone_document(exported, cases, name, what):
    path = exported[(name, what, "latex")]
    text = path.read_text()
    assert text.index(r"\documentclass") < text.index(r"\usepackage{amsmath}") < text.index(r"\begin{document}")
    assert text.rstrip().endswith(r"\end{document}")
    body = text.split(r"\documentclass", 1)[1]
    assert body.count("{") == body.count("}") and body.count(r"\left") == body.count(r"\right")
    assert body.count(r"\begin{align*}") == body.count(r"\end{align*}") > 0
    n = cases[name].n
    if what == "nonlinear":
        assert (r"\psi_{1} &=" in text) == (name != "belt")
        assert r"M_{11} &=" in text
    else:
        assert rf"\bar{{K}}_{{{n}{n}}} &=" in text or rf"\bar{{K}}_{{{n},{n}}} &=" in text
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        return  # the document's text was checked
    res = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error", path.name], cwd=path.parent,
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stdout[-2000:]


# -------------------------------------------------------------------- CLI errors
def _one_line_error(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("brakesqueal: error: ")
    return err


def test_linear_with_nontrivial_silent_motion_is_a_clear_error(tmp_path, capsys):
    toml = tmp_path / "nontrivial.toml"
    toml.write_text(NONTRIVIAL_TOML)
    out = tmp_path / "lin.c"
    err = _one_line_error(capsys, ["export", "--to", "c", "--what", "linear", "--params", str(toml), "--out", str(out)])
    assert "mu1*h10 = mu2*h20 (eq. 49)" in err and "linearize --format json" in err
    assert not out.exists()
    err = _one_line_error(capsys, ["export", "--to", "c", "--what", "linear", "--model", "minimal", "--set",
                                   "h10=0.012", "--out", str(out)])  # fmt: skip
    assert "zero state" in err and "q1 = " in err and "--model minimal" in err
    assert not out.exists()
    # the nonlinear equations are valid everywhere
    assert main(["export", "--to", "c", "--params", str(toml), "--out", str(out)]) == 0


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--to", "c", "--out", "x.py"], "must end in .c"),
        (["--to", "octave", "--out", "1model.m"], "identifier"),
        (["--to", "fortran", "--out", "x.f"], "--to"),
        (["--to", "c", "--what", "quadratic", "--out", "x.c"], "--what"),
        (["--to", "c", "--set", "mu=-1", "--out", "x.c"], "mu"),
        (["--to", "c", "--model", "six-dof", "--set", "m_p=-1", "--out", "x.c"], "m_p"),
        (["--to", "c", "--model", "nine-dof", "--out", "x.c"], "nine-dof"),
        (["--to", "c", "--out", "/nonexistent-dir/x.c"], "does not exist"),
    ],
)
def test_cli_errors(capsys, argv, needle):
    assert needle in _one_line_error(capsys, ["export", *argv])


def test_output_checked_before_work_and_written_atomically(tmp_path, capsys, monkeypatch):
    import brakesqueal.export as ex

    calls = []
    monkeypatch.setattr(ex, "export_model", lambda *a, **k: calls.append(1))
    _one_line_error(capsys, ["export", "--to", "c", "--out", str(tmp_path / "missing" / "x.c")])
    (tmp_path / "d.c").mkdir()
    _one_line_error(capsys, ["export", "--to", "c", "--out", str(tmp_path / "d.c")])
    assert calls == []  # nothing computed
    monkeypatch.undo()
    # a failing export leaves an existing file untouched and no temporary behind
    out = tmp_path / "keep.c"
    out.write_text("old")
    _one_line_error(capsys, ["export", "--to", "c", "--what", "linear", "--model", "minimal", "--set",
                             "h10=0.012", "--out", str(out)])  # fmt: skip
    assert out.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["d.c", "keep.c"]


def test_api_errors():
    with pytest.raises(ParameterError, match="--to"):
        export_code("fortran")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="--what"):
        export_model("quadratic")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="model 'paper', not to model 'belt'"):
        export_model("nonlinear", resolve_space("paper").resolve({}), model="belt")
    assert set(TARGETS) == {"latex", "octave", "c", "julia", "python"}


def test_reserved_names_get_local_aliases(tmp_path):
    """Parameter names that are keywords or library names in a target language still compile and run."""
    text = ANGLED_TOML.replace('"slope"', '"int"').replace("slope = 0.02", "int = 0.02").replace(
        '"k"', '"end"').replace("k = 6e6", "end = 6e6")  # fmt: skip
    path = tmp_path / "reserved.toml"
    path.write_text(text)
    spec = resolve_model(str(path))
    src = tmp_path / "bs_reserved.c"
    assert main(["export", "--to", "c", "--model", str(path), "--out", str(src)]) == 0
    c = src.read_text()
    assert "const double int_ = p[" in c and "const double end_ = p[" in c and ", end, " in c and ", int, " in c
    cm = compile_model(spec)
    rng = np.random.default_rng(1)
    x = rng.uniform(-1e-3, 1e-3, cm.nx)
    p = resolve_space(spec).resolve({}).vector()
    kinds = [f"R{kind(c)}" for c in cm.coords] + ["G"] * cm.m
    py = tmp_path / "bs_reserved.py"
    assert main(["export", "--to", "python", "--model", str(path), "--out", str(py)]) == 0
    assert close_grouped(_import(py).residuals(list(x), list(p)), cm.residuals(list(x), list(p)), kinds)
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not on PATH")
    so = tmp_path / "bs_reserved.so"
    res = subprocess.run([gcc, "-std=c99", "-O0", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC", "-o", str(so),
                          str(src), "-lm"], capture_output=True, text=True)  # fmt: skip
    assert res.returncode == 0, res.stderr[-2000:]
    out = _arr(n=cm.n + cm.m)
    ctypes.CDLL(str(so)).brakesqueal_residuals(_arr(x), _arr(p), out)
    assert close_grouped(out[:], cm.residuals(list(x), list(p)), kinds)


def test_stdout(capsys):
    assert main(["export", "--to", "julia", "--what", "linear", "--model", "belt", "--out", "-"]) == 0
    out = capsys.readouterr().out
    assert "function linear_matrices(p)" in out and "M = reshape([M_1], 1, 1)" in out


def test_dense_pad_jacobian_path(tmp_path, monkeypatch, cases):
    """The solver for coupled pads (dense dG/dz, a linear solve per Newton step) gives the same pads and dy/dt."""
    import brakesqueal.export.model as em

    monkeypatch.setattr(em, "_pads_coupled", lambda G, z: True)
    monkeypatch.setattr(em, "_FUNCTIONS", {})
    gcc = shutil.which("gcc")
    for name in ("paper", ANGLED):
        case = cases[name]
        m = case.m
        desc = export_model("nonlinear", case.params)
        assert desc.pad_jacobian == "dense"
        stem = f"bs_dense_{name}"
        (tmp_path / f"{stem}.py").write_text(export_code("python", "nonlinear", case.params, name=stem))
        mod = _import(tmp_path / f"{stem}.py")
        apis = [("python", mod)]
        if gcc is not None:
            (tmp_path / f"{stem}.c").write_text(export_code("c", "nonlinear", case.params, name=stem))
            so = tmp_path / f"{stem}.so"
            res = subprocess.run([gcc, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC", "-o",
                                  str(so), str(tmp_path / f"{stem}.c"), "-lm"], capture_output=True, text=True)  # fmt: skip
            assert res.returncode == 0, res.stderr[-2000:]
            apis.append(("c", ctypes.CDLL(str(so))))
        jl = export_code("julia", "nonlinear", case.params, name=stem)
        assert f"permutedims(reshape(g[{m + 1}:end], {m}, {m})) \\ r" in jl
        assert f"reshape(g({m + 1}:end), {m}, {m}).' \\ r" in export_code("octave", "nonlinear", case.params, name=stem)
        for x, p in case.points:
            y = case.y_of(x)
            z_ref = ref_pads(case, y, p)
            dydt = ref_state_derivative(case, y, z_ref, p)
            zt = perturbed_pads(case, z_ref)
            xr = case.split(y, zt)
            cols = [3 * case.n + m + j if k else 3 * case.n + j for j, k in enumerate(case.kept_mask)]
            J = case.cm.jacobian_matrix(xr, list(p))[case.n:, cols]
            for lang, api in apis:
                if lang == "python":
                    g = np.array(mod.pad_residuals(list(y), list(zt), list(p)))
                    z = np.array(mod.solve_pads(list(y), list(p)))
                    f = np.array(mod.rhs(0.0, list(y), list(p)))
                else:
                    out = _arr(n=m + m * m)
                    api.brakesqueal_pad_residuals(_arr(y), _arr(zt), _arr(p), out)
                    g = np.array(out[:])
                    zz = _arr(n=m)
                    assert api.brakesqueal_solve_pads(_arr(y), _arr(p), zz) == 0
                    z = np.array(zz[:])
                    ff = _arr(n=len(y))
                    api.brakesqueal_rhs.argtypes = [ctypes.c_double] + [ctypes.c_void_p] * 3
                    assert api.brakesqueal_rhs(0.0, _arr(y), _arr(p), ff) == 0
                    f = np.array(ff[:])
                assert g.shape == (m + m * m,)
                jk = [case.z_kinds[j] for i in range(m) for j in range(m)]
                assert close_grouped(g[m:], J.ravel(), jk), (lang, name)
                assert close_grouped(z, z_ref, case.z_kinds), (lang, name)
                assert close_grouped(f, dydt, case.dydt_kinds), (lang, name)


def test_api_defaults_are_those_of_the_options():
    """export_model without parameters uses the same defaults as the command line (resolve_space)."""
    for model in (None, "six-dof"):
        desc = export_model("nonlinear", model=model)
        assert list(desc.parameter_values) == [float(v) for v in resolve_space(model).resolve({}).vector()]
        assert desc.model_name == (model or "paper")


def test_paper_rhs_agrees_with_the_simulator(python_modules, cases):
    """The exported paper RHS equals the library's compiled simulator RHS (closed-form 2 x 2 solve, numba)."""
    from brakesqueal import simulation_model

    case = cases["paper"]
    f = simulation_model("paper").rhs(case.params)
    mod = python_modules[("paper", "nonlinear")]
    p = list(case.params.vector())
    rng = np.random.default_rng(7)
    for _ in range(20):
        y = np.concatenate([rng.uniform(-0.05, 0.05, 2), rng.uniform(-5, 5, 2)])
        assert close_grouped(mod.rhs(0.0, list(y), p), f(0.0, y), ["rad/s"] * 2 + ["rad/s2"] * 2)
