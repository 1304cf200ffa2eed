"""``brakesqueal export``: the exported code is run (Python, C, Octave) and matches the library to 1e-12.

The reference numbers are the library's compiled model (residuals, Jacobians,
closed-form trivial matrices); "1e-12 relative" is normwise over each group of
outputs with the same unit (``psi``; ``g``; each matrix), so that an entry that is
zero in one and 1e-20 in the other does not count as a relative error of 1.
Julia is not installable here (no Debian package); its text is translated
line by line to Python and evaluated, which checks what ``julia_code`` printed.
"""

from __future__ import annotations

import ctypes
import importlib.util
import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.export import TARGETS, export_code
from brakesqueal.numeric.compiled import compiled_model
from brakesqueal.parameters import get_preset

RTOL = 1e-12
PV_LEN, X_LEN = 17, 10

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


def close(a, b, rtol=RTOL) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and float(np.max(np.abs(a - b))) <= rtol * float(np.max(np.abs(b)))


# ----------------------------------------------------------------- test points
@pytest.fixture(scope="module")
def model():
    return compiled_model()


@pytest.fixture(scope="module")
def points(rng):
    """(x, p) pairs: general parameters (asymmetric, one rigid pad support) at random states."""
    base = np.array(parameter_vector(get_preset("paper-fig3").resolve({})))
    out = []
    for k in range(5):
        p = base * rng.uniform(0.7, 1.4, PV_LEN)
        p[9] = 0.0 if k % 2 else p[9]  # rigid lower tangential support
        x = np.concatenate([
            rng.uniform(-0.2, 0.2, 2), rng.uniform(-20, 20, 2), rng.uniform(-1e3, 1e3, 2),
            rng.uniform(-1e-5, 1e-5, 2), rng.uniform(-1e-2, 1e-2, 2),
        ])  # fmt: skip
        out.append((x, p))
    return out


def ref_residuals(model, x, p):
    return np.asarray(model.residuals(list(x), list(p)))


def ref_pads(model, y, p):
    """Pad deformations by Newton on the library's g (ldot = 0) with its exact Jacobian."""
    l = np.zeros(2)
    for _ in range(50):
        x = [*y, 0.0, 0.0, *l, 0.0, 0.0]
        g = ref_residuals(model, x, p)[2:]
        J = np.asarray(model.jacobians(x, list(p))).reshape(4, 10)[2:, 6:8]
        step = np.linalg.solve(J, g)
        l = l - step
        if np.all(np.abs(step) <= 1e-15 * np.abs(l) + 1e-300):
            break
    return l


def ref_state_derivative(model, y, l, p):
    """dy/dt from the library: psi = M ddq + f, M = dpsi/dddq (exact Jacobian)."""
    x = [*y, 0.0, 0.0, *l, 0.0, 0.0]
    f = ref_residuals(model, x, p)[:2]
    M = np.asarray(model.jacobians(x, list(p))).reshape(4, 10)[:2, 4:6]
    return np.concatenate([y[2:], -np.linalg.solve(M, f)])


def ref_matrices(model, p):
    m = np.asarray(model.trivial_matrices(np.asarray(p)), dtype=float)
    return m[0:4], m[4:8], m[8:12]


def trivial_parameter_vectors():
    """Parameter vectors whose silent motion is trivial (where the closed form is valid)."""
    sets = [get_preset("paper-fig2").resolve({}), get_preset("paper-fig3").resolve({"mu1": 0.7, "mu2": 0.3}),
            get_preset("minimal-model").resolve({})]  # fmt: skip
    return [np.array(parameter_vector(s)) for s in sets]


# ----------------------------------------------------------------------- Python
def _import(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def py_nonlinear(tmp_path_factory):
    path = tmp_path_factory.mktemp("py") / "bs_nonlinear.py"
    assert main(["export", "--to", "python", "--out", str(path)]) == 0
    return _import(path)


def test_python_nonlinear_matches_library(py_nonlinear, model, points):
    mod = py_nonlinear
    for x, p in points:
        r = np.array(mod.residuals(list(x), list(p)))
        ref = ref_residuals(model, x, p)
        assert close(r[:2], ref[:2]) and close(r[2:], ref[2:])
        y = x[:4]
        l = ref_pads(model, y, p)
        g = np.array(mod.pad_residuals(list(y), list(l), list(p)))
        J = np.asarray(model.jacobians([*y, 0, 0, *l, 0, 0], list(p))).reshape(4, 10)
        assert close(g[2:], [J[2, 6], J[3, 7]])
        assert np.all(np.abs(g[:2]) <= 1e-12 * np.abs(l))  # l solves g = 0
        assert close(mod.solve_pads(list(y), list(p)), l)
        dydt = ref_state_derivative(model, y, l, p)
        assert close(mod.state_derivative(list(y), list(l), list(p))[2:], dydt[2:])
        assert close(mod.rhs(0.0, list(y), list(p))[2:], dydt[2:])
        assert close(mod.rhs(0.0, list(y), list(p))[:2], y[2:], rtol=0)


def test_python_parameters_are_the_chosen_set(tmp_path):
    path = tmp_path / "bs_fig3.py"
    assert main(["export", "--to", "python", "--preset", "paper-fig3", "--set", "mu1=0.7", "--out", str(path)]) == 0
    mod = _import(path)
    want = parameter_vector(get_preset("paper-fig3").resolve({"mu1": 0.7}))
    assert list(mod.parameters()) == want
    assert "preset paper-fig3, --set mu1=0.7" in path.read_text()


def test_python_linear_matches_closed_form(tmp_path, model):
    path = tmp_path / "bs_linear.py"
    assert main(["export", "--to", "python", "--what", "linear", "--out", str(path)]) == 0
    mod = _import(path)
    for p in trivial_parameter_vectors():
        M, D, K = (np.ravel(m) for m in mod.linear_matrices(list(p)))
        Mr, Dr, Kr = ref_matrices(model, p)
        assert close(M, Mr) and close(D, Dr) and close(K, Kr)


def test_header_lists_argument_order_and_units():
    text = export_code("python", "nonlinear")
    assert "x = (q1, q2, dq1, dq2, ddq1, ddq2, l1, l2, dl1, dl2)" in text
    assert "p = (Theta, Phi, k_t, d_t, k1, k2, d1, d2, c_ip1, c_ip2, mu1, mu2, h10, h20, r, N0, Omega)" in text
    assert "[kg m^2, kg m^2, N m/rad, N m s/rad, N/m, N/m, N s/m, N s/m, m/N, m/N, 1, 1, m, m, m, N, rad/s]" in text
    assert "c_ip1 = 1/k_ip1" in text
    # common subexpressions were eliminated
    assert re.search(r"^\s+w50 = ", text, re.M)


# ---------------------------------------------------------------------------- C
@pytest.fixture(scope="module")
def c_libs(tmp_path_factory):
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not on PATH")
    d = tmp_path_factory.mktemp("c")
    libs = {}
    for what in ("nonlinear", "linear"):
        src = d / f"bs_{what}.c"
        assert main(["export", "--to", "c", "--what", what, "--out", str(src)]) == 0
        so = d / f"bs_{what}.so"
        res = subprocess.run([gcc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                              "-o", str(so), str(src), "-lm"], capture_output=True, text=True)  # fmt: skip
        assert res.returncode == 0, res.stderr
        libs[what] = ctypes.CDLL(str(so))
    return libs


def _arr(values, n=None):
    v = list(values) if n is None else [0.0] * n
    return (ctypes.c_double * len(v))(*v)


def test_c_nonlinear_matches_library(c_libs, model, points):
    lib = c_libs["nonlinear"]
    lib.brakesqueal_rhs.argtypes = [ctypes.c_double] + [ctypes.c_void_p] * 3
    for x, p in points:
        out = _arr(None, 4)
        lib.brakesqueal_residuals(_arr(x), _arr(p), out)
        ref = ref_residuals(model, x, p)
        assert close(out[:2], ref[:2]) and close(out[2:], ref[2:])
        y = x[:4]
        l_ref = ref_pads(model, y, p)
        l = _arr(None, 2)
        assert lib.brakesqueal_solve_pads(_arr(y), _arr(p), l) == 0
        assert close(l[:], l_ref)
        dydt_ref = ref_state_derivative(model, y, l_ref, p)
        out = _arr(None, 4)
        lib.brakesqueal_state_derivative(_arr(y), _arr(l_ref), _arr(p), out)
        assert close(out[2:], dydt_ref[2:])
        out = _arr(None, 4)
        assert lib.brakesqueal_rhs(0.0, _arr(y), _arr(p), out) == 0
        assert close(out[2:], dydt_ref[2:]) and list(out[:2]) == list(y[2:])
    pv = _arr(None, PV_LEN)
    lib.brakesqueal_parameters(pv)
    assert list(pv) == parameter_vector(get_preset("paper-fig2").resolve({}))


def test_c_linear_matches_closed_form(c_libs, model):
    lib = c_libs["linear"]
    for p in trivial_parameter_vectors():
        M, D, K = _arr(None, 4), _arr(None, 4), _arr(None, 4)
        lib.brakesqueal_linear_matrices(_arr(p), M, D, K)
        for got, want in zip((M, D, K), ref_matrices(model, p)):
            assert close(got[:], want)


# ----------------------------------------------------------------------- Octave
def test_octave_text():
    text = export_code("octave", "nonlinear", name="bs_model")
    assert text.startswith("function m = bs_model()\n")
    for fn in ("residuals", "pad_residuals", "state_derivative", "solve_pads", "rhs", "parameters"):
        assert f"  m.{fn} = @{fn};" in text
    assert "function res = residuals(x, p)" in text and "  Omega = p(17);" in text
    assert 1 + text.count("\nfunction ") == text.count("\nend\n")  # every function closed at column 0
    lin = export_code("octave", "linear", name="bs_lin")
    assert "function [M, D, K] = linear_matrices(p)" in lin and "  M = [M_1, M_2; M_3, M_4];" in lin


def _octave_matrix(values) -> str:
    return "[" + "; ".join(" ".join(repr(float(v)) for v in row) for row in np.atleast_2d(values)) + "]"


def test_octave_runs_and_matches_library(tmp_path, model, points):
    octave = shutil.which("octave") or shutil.which("octave-cli")
    if octave is None:
        pytest.skip("GNU Octave is not on PATH (apt-get install -y octave); the exported text is tested above")
    for what in ("nonlinear", "linear"):
        assert main(["export", "--to", "octave", "--what", what, "--out", str(tmp_path / f"bs_{what}.m")]) == 0
    X = np.array([x for x, _ in points])
    P = np.array([p for _, p in points])
    PT = np.array(trivial_parameter_vectors())
    script = f"""
m = bs_nonlinear(); ml = bs_linear();
X = {_octave_matrix(X)}; P = {_octave_matrix(P)}; PT = {_octave_matrix(PT)};
for i = 1:rows(X)
  x = X(i, :)'; p = P(i, :)'; y = x(1:4);
  printf('res %.17g %.17g %.17g %.17g\\n', m.residuals(x, p));
  l = m.solve_pads(y, p);
  printf('pads %.17g %.17g\\n', l);
  printf('rhs %.17g %.17g %.17g %.17g\\n', m.rhs(0, y, p));
end
for i = 1:rows(PT)
  [M, D, K] = ml.linear_matrices(PT(i, :)');
  printf('lin %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\\n', M', D', K');
end
printf('par %.17g\\n', m.parameters());
"""
    (tmp_path / "driver.m").write_text(script)
    res = subprocess.run([octave, "--no-gui", "--quiet", "--no-window-system", "driver.m"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert res.returncode == 0, res.stderr
    rows: dict[str, list[list[float]]] = {}
    for line in res.stdout.split("\n"):
        if line.strip():
            key, *vals = line.split()
            rows.setdefault(key, []).append([float(v) for v in vals])
    for (x, p), r, l, f in zip(points, rows["res"], rows["pads"], rows["rhs"]):
        ref = ref_residuals(model, x, p)
        assert close(r[:2], ref[:2]) and close(r[2:], ref[2:])
        l_ref = ref_pads(model, x[:4], p)
        assert close(l, l_ref)
        assert close(f[2:], ref_state_derivative(model, x[:4], l_ref, p)[2:])
    for p, lin in zip(PT, rows["lin"]):
        for got, want in zip((lin[0:4], lin[4:8], lin[8:12]), ref_matrices(model, p)):
            assert close(got, want)
    assert [v[0] for v in rows["par"]] == parameter_vector(get_preset("paper-fig2").resolve({}))


# ------------------------------------------------------------------------ Julia
def _run_julia_as_python(text: str, fn: str, args: dict[str, list[float]]) -> list[float]:
    """Evaluate one exported Julia function by translating its assignments to Python."""
    body = text.split(f"\nfunction {fn}(", 1)[1].split("\nend\n", 1)[0].split("\n")[1:]
    env: dict = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "pi": math.pi, **args}
    result = None
    for line in body:
        line = line.strip()
        if line.startswith("return "):
            result = eval(line[len("return "):], env)  # noqa: S307 - our own generated, translated text
            break
        name, expr = line.split(" = ", 1)
        expr = re.sub(r"\[(\d+)\]", lambda m: f"[{int(m.group(1)) - 1}]", expr)  # 1-based indexing
        expr = expr.replace(".^", "**").replace(".*", "*").replace("./", "/").replace("//", "/")
        expr = re.sub(r"\[([^\[\];]+); ([^\[\];]+)\]", r"[[\1], [\2]]", expr)  # [a b; c d] -> rows
        expr = re.sub(r"\[\[(\w+) (\w+)\], \[(\w+) (\w+)\]\]", r"[[\1, \2], [\3, \4]]", expr)
        env[name] = eval(expr, env)  # noqa: S307
    assert result is not None
    return result


def test_julia_text_and_translated_values(model, points):
    text = export_code("julia", "nonlinear")
    assert "module BrakesquealModel" in text and text.rstrip().endswith("end # module")
    assert "export residuals, pad_residuals, state_derivative, solve_pads, rhs, parameters" in text
    assert "function residuals(x, p)" in text and "    Omega = p[17]" in text
    assert text.count("\nfunction ") == text.count("\nend\n") == 4  # every function closed at column 0
    for x, p in points[:2]:
        (r,) = (_run_julia_as_python(text, "residuals", {"x": list(x), "p": list(p)}),)
        ref = ref_residuals(model, x, p)
        assert close(r[:2], ref[:2]) and close(r[2:], ref[2:])
    lin = export_code("julia", "linear")
    for p in trivial_parameter_vectors():
        M, D, K = _run_julia_as_python(lin, "linear_matrices", {"p": list(p)})
        for got, want in zip((M, D, K), ref_matrices(model, p)):
            assert close(np.ravel(got), want)


def test_julia_runs_if_available(tmp_path, model, points):
    julia = shutil.which("julia")
    if julia is None:
        pytest.skip("julia is not on PATH (no Debian package); the exported text is tested above")
    (tmp_path / "bs.jl").write_text(export_code("julia", "nonlinear", name="bs"))
    x, p = points[0]
    script = f"""include("bs.jl"); using .BrakesquealModel
for v in residuals({list(map(float, x))}, {list(map(float, p))}); println(repr(v)); end
"""
    (tmp_path / "driver.jl").write_text(script)
    res = subprocess.run([julia, "driver.jl"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    r = [float(v) for v in res.stdout.split()]
    ref = ref_residuals(model, x, p)
    assert close(r[:2], ref[:2]) and close(r[2:], ref[2:])


# ------------------------------------------------------------------------ LaTeX
@pytest.mark.parametrize("what", ["nonlinear", "linear"])
def test_latex_standalone_document(tmp_path, what):
    path = tmp_path / f"bs_{what}.tex"
    assert main(["export", "--to", "latex", "--what", what, "--out", str(path)]) == 0
    text = path.read_text()
    assert text.index(r"\documentclass") < text.index(r"\usepackage{amsmath}") < text.index(r"\begin{document}")
    assert text.rstrip().endswith(r"\end{document}")
    assert text.count("{") == text.count("}")
    assert text.count(r"\begin{align*}") == text.count(r"\end{align*}") > 0
    assert (r"\psi_1 &=" in text) if what == "nonlinear" else (r"\bar{K}_{21} &=" in text)
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        pytest.skip("pdflatex is not on PATH; the document's text was checked")
    res = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error", path.name], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert res.returncode == 0, res.stdout[-2000:]
    assert (tmp_path / f"bs_{what}.pdf").stat().st_size > 0


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
        (["--to", "c", "--out", "/nonexistent-dir/x.c"], "cannot be written"),
    ],
)
def test_cli_errors(capsys, argv, needle):
    assert needle in _one_line_error(capsys, ["export", *argv])


def test_api_errors():
    with pytest.raises(ParameterError, match="--to"):
        export_code("fortran")  # type: ignore[arg-type]
    assert set(TARGETS) == {"latex", "octave", "c", "julia", "python"}


def test_stdout(capsys):
    assert main(["export", "--to", "julia", "--what", "linear", "--out", "-"]) == 0
    assert "function linear_matrices(p)" in capsys.readouterr().out
