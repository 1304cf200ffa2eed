"""Finite-element matrix files (brakesqueal.model.matrix_files): round trips through every writer, bad input, ccx."""

from __future__ import annotations

import importlib.util
import math
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
import scipy.io as sio
import scipy.linalg as la
import scipy.sparse as sp

from brakesqueal.errors import ParameterError
from brakesqueal.model.matrix_files import FORMATS, MAX_DOFS, detect_format, read_matrix_file, write_matrix_file

HAVE_PYYETI = importlib.util.find_spec("pyyeti") is not None
N = 40
# 40 DOFs as 14 nodes x 3 DOFs (the last node has 1), sorted by node then dof
DOFS = tuple(f"{i // 3 + 1}:{i % 3 + 1}" for i in range(N))


def _qep(symmetric: bool, seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((N, N))
    M = B @ B.T + N * np.eye(N)  # symmetric positive definite
    D = rng.standard_normal((N, N))
    K = rng.standard_normal((N, N)) + 4 * N * np.eye(N)
    if symmetric:
        D, K = D + D.T, K + K.T
    return {"M": M, "D": D, "K": K}


def _qep_eigenvalues(M, D, K) -> np.ndarray:
    """The 2N eigenvalues of λ²M + λD + K from the companion pencil A - λB."""
    M, D, K = (X.toarray() if sp.issparse(X) else np.asarray(X) for X in (M, D, K))
    n = M.shape[0]
    Z, eye = np.zeros((n, n)), np.eye(n)
    A = np.block([[Z, eye], [-K, -D]])
    Bm = np.block([[eye, Z], [Z, M]])
    return la.eig(A, Bm, right=False)


def _assert_same_spectrum(got: np.ndarray, ref: np.ndarray, rtol: float = 1e-12) -> None:
    assert len(got) == len(ref)
    left = list(got)
    for lam in ref:  # match each reference eigenvalue with its nearest remaining one
        k = int(np.argmin([abs(x - lam) for x in left]))
        assert abs(left[k] - lam) <= rtol * abs(lam), (lam, left[k])
        left.pop(k)


def _dense(X) -> np.ndarray:
    return X.toarray() if sp.issparse(X) else np.asarray(X)


def _inputs(mats: dict[str, np.ndarray], sparse: bool) -> dict:
    return {k: (sp.csr_array(v) if sparse else v) for k, v in mats.items()}


def _write_and_read(fmt: str, tmp_path, mats: dict, dofs) -> tuple[dict, tuple | None]:
    """Write ``mats`` in ``fmt`` (one file per matrix where the format holds one) and read all back."""
    got: dict = {}
    read_dofs = None
    if fmt in ("mm", "hb", "abaqus"):
        ext = {"mm": ".mtx", "hb": ".rua", "abaqus": ".mtx"}[fmt]
        for name, X in mats.items():
            path = str(tmp_path / f"{name}{ext}")
            write_matrix_file(path, {name: X}, fmt, dofs=dofs if fmt == "abaqus" else None)
            assert detect_format(path) == fmt
            mf = read_matrix_file(path)
            assert mf.format == fmt and list(mf.matrices) == [name]
            got.update(mf.matrices)
            read_dofs = mf.dofs
    else:
        ext = {"mat": ".mat", "dmig": ".bdf", "op4": ".op4", "calculix": ""}[fmt]
        path = str(tmp_path / f"job{ext}")
        write_matrix_file(path, mats, fmt, dofs=dofs if fmt in ("dmig", "calculix") else None)
        mf = read_matrix_file(path + (".sti" if fmt == "calculix" else ""))
        assert mf.format == fmt
        got, read_dofs = mf.matrices, mf.dofs
    return got, read_dofs


# formats that take general (non-symmetric) matrices; CalculiX stores one triangle of symmetric K and M only
GENERAL = ("mat", "mm", "hb", "abaqus", "dmig", "op4")


@pytest.mark.parametrize("sparse", [False, True], ids=["dense", "sparse"])
@pytest.mark.parametrize(("fmt", "symmetric"), [(f, False) for f in GENERAL] + [(f, True) for f in FORMATS],
                         ids=[f"{f}-general" for f in GENERAL] + [f"{f}-symmetric" for f in FORMATS])
def test_round_trip_preserves_matrices_and_qep_eigenvalues(fmt, symmetric, sparse, tmp_path):
    if fmt in ("dmig", "op4"):
        pytest.importorskip("pyyeti")
    mats = _qep(symmetric, seed=7 if symmetric else 11)
    if fmt == "calculix":  # K (.sti) and M (.mas) only: the QEP with D = 0
        mats = {"K": mats["K"], "M": mats["M"]}
    ref = _qep_eigenvalues(mats["M"], mats.get("D", np.zeros((N, N))), mats["K"])
    got, dofs = _write_and_read(fmt, tmp_path, _inputs(mats, sparse), DOFS)
    assert set(got) == set(mats)
    for name, X in mats.items():
        Y = got[name]
        assert isinstance(Y, (np.ndarray, sp.csr_array)) and Y.dtype == np.float64 and Y.shape == (N, N)
        if fmt == "dmig":  # pyyeti's card reader may round the 17th digit: 1 ulp
            assert np.max(np.abs(_dense(Y) - X)) <= 1e-15 * np.max(np.abs(X))
        else:
            assert np.array_equal(_dense(Y), X), (fmt, name)
    assert dofs == (DOFS if fmt in ("abaqus", "calculix", "dmig") else None)
    lam = _qep_eigenvalues(got["M"], got.get("D", np.zeros((N, N))), got["K"])
    _assert_same_spectrum(lam, ref)
    if fmt == "calculix":  # the files are in ccx's layout: i <= j, column by column, every diagonal entry
        rows = np.loadtxt(tmp_path / "job.sti")
        assert np.all(rows[:, 0] <= rows[:, 1]) and np.sum(rows[:, 0] == rows[:, 1]) == N
        assert np.all(np.diff(rows[:, 1]) >= 0)
        assert (tmp_path / "job.dof").read_text().split()[:2] == ["1.1", "1.2"]


def test_triangular_general_matrix_survives_the_one_triangle_rule(tmp_path):
    """A non-symmetric matrix with one triangle empty is not mirrored: the writer marks full storage."""
    A = np.triu(np.arange(1.0, 17.0).reshape(4, 4))
    for dofs in (None, ("1:1", "1:2", "2:1", "2:2")):
        path = str(tmp_path / "U.mtx")
        write_matrix_file(path, {"U": A}, "abaqus", dofs=dofs)
        mf = read_matrix_file(path)
        assert np.array_equal(_dense(mf.matrices["U"]), A)
        assert mf.dofs == dofs


def test_abaqus_reader_mirrors_one_triangle_and_keeps_a_full_matrix(tmp_path):
    lower = tmp_path / "job_STIF1.mtx"
    lower.write_text("** ABAQUS-like output\n*MATRIX\n1,1, 1,1, 4.0\n1,2, 1,1, -1.0\n1,2, 1,2, 5.0\n"
                     "2,1, 1,1, -2.0\n2,1, 2,1, 6.0\n")
    mf = read_matrix_file(str(lower))
    assert list(mf.matrices) == ["job_STIF1"] and mf.dofs == ("1:1", "1:2", "2:1")
    assert np.array_equal(_dense(mf.matrices["job_STIF1"]),
                          [[4.0, -1.0, -2.0], [-1.0, 5.0, 0.0], [-2.0, 0.0, 6.0]])
    full = tmp_path / "full.mtx"
    full.write_text("1, 1, 1.0\n1, 2, 2.0\n2, 1, 3.0\n2, 2, 4.0\n")
    assert np.array_equal(_dense(read_matrix_file(str(full)).matrices["full"]), [[1.0, 2.0], [3.0, 4.0]])


def test_dmig_symmetric_small_field_and_form_rules(tmp_path):
    pytest.importorskip("pyyeti")
    bdf = tmp_path / "k.bdf"
    # small-field, form 6 (symmetric, lower triangle given), grid 10 components 1 and 2, scalar point 20
    bdf.write_text("BEGIN BULK\n"
                   "DMIG    KAA     0       6       2       0\n"
                   "DMIG    KAA     10      1               10      1       4.0\n"
                   "+       10      2       -1.0            20      0       0.5\n"
                   "DMIG    KAA     10      2               10      2       3.0\n"
                   "DMIG    KAA     20      0               20      0       2.0\n"
                   "ENDDATA\n")
    mf = read_matrix_file(str(bdf))
    assert mf.format == "dmig" and mf.dofs == ("10:1", "10:2", "20:0")
    assert np.array_equal(_dense(mf.matrices["KAA"]), [[4.0, -1.0, 0.5], [-1.0, 3.0, 0.0], [0.5, 0.0, 2.0]])
    assert list(read_matrix_file(str(bdf), names=["kaa"]).matrices) == ["KAA"]


# ------------------------------------------------------------------------------------------------------ bad input


def _raises(path, *words, **kw) -> str:
    with pytest.raises(ParameterError) as info:
        read_matrix_file(str(path), **kw)
    msg = str(info.value)
    assert "\n" not in msg
    assert os.path.basename(str(path)) in msg, msg
    for w in words:
        assert w.lower() in msg.lower(), (w, msg)
    return msg


def test_missing_file_and_unknown_format(tmp_path):
    for name in ("nope.mat", "nope.mtx", "nope.rua", "nope.bdf", "nope.op4"):
        _raises(tmp_path / name, "no such file")
    _raises(tmp_path / "job.sti", "no such file", "job.mas")
    bad = tmp_path / "a.txt"
    bad.write_text("1 1 1.0\n")
    _raises(bad, "extension", ".txt", "mat, mm, hb, abaqus, calculix, dmig, op4")
    _raises(bad, "unknown format", "'xyz'", ", ".join(FORMATS), format="xyz")


def test_unreadable_content(tmp_path):
    junk = b"this is not a matrix file at all\n\x00\x01\x02"
    cases = [("junk.mat", "cannot be read"), ("junk.mtx", "fields"), ("junk.rua", "header")]
    for name, word in cases + ([("junk.op4", "op4")] if HAVE_PYYETI else []):
        p = tmp_path / name
        p.write_bytes(junk)
        _raises(p, word)
    p = tmp_path / "bad.mtx"
    p.write_text("%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n2 two 2.0\n")
    _raises(p, "Matrix Market", "cannot be read")
    p = tmp_path / "nodmig.bdf"
    p.write_text("BEGIN BULK\nGRID    1               0.      0.      0.\nENDDATA\n")
    if HAVE_PYYETI:
        _raises(p, "no DMIG")
    cx = tmp_path / "cx.sti"
    cx.write_text("1 1 2.0\n1 x 1.0\n")
    _raises(cx, "CalculiX", "unreadable")


def test_not_two_d_not_square_and_size_mismatch(tmp_path):
    p = tmp_path / "m.mat"
    sio.savemat(str(p), {"A": np.eye(3), "B": np.eye(4), "R": np.ones((3, 4)), "T": np.ones((2, 2, 2))})
    _raises(p, "'T'", "2x2x2", "2-D", names=["T"])
    _raises(p, "'R'", "3x4", "not square", names=["A", "R"])
    _raises(p, "differ in size", "'A'", "'B'", names=["A", "B"])
    mm = tmp_path / "r.mtx"
    sio.mmwrite(str(mm), np.ones((2, 3)))
    _raises(mm, "2x3", "not square")
    (tmp_path / "job.sti").write_text("1 1 1.0\n2 2 1.0\n3 3 1.0\n")
    (tmp_path / "job.mas").write_text("1 1 1.0\n2 2 1.0\n")
    _raises(tmp_path / "job.sti", "differ in size", "job.mas")
    (tmp_path / "job.mas").write_text("1 1 1.0\n2 2 1.0\n3 3 1.0\n")
    (tmp_path / "job.dof").write_text("2.1\n2.2\n")
    _raises(tmp_path / "job.sti", "job.dof", "2 DOFs", "sizes must match")


def test_non_finite_entries_name_the_matrix_and_an_entry(tmp_path):
    A = np.eye(3)
    A[1, 2] = np.nan
    p = tmp_path / "n.mat"
    sio.savemat(str(p), {"K": A, "M": np.eye(3)})
    _raises(p, "'K'", "non-finite", "nan", "(2, 3)")
    mm = tmp_path / "S.mtx"
    mm.write_text("%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1.0\n3 2 inf\n")
    _raises(mm, "'S'", "non-finite", "inf", "(3, 2)")
    (tmp_path / "c.sti").write_text("1 1 1.0\n1 2 nan\n2 2 1.0\n")
    _raises(tmp_path / "c.sti", "'K'", "non-finite", "(1, 2)")


def test_missing_variable_lists_the_available_ones(tmp_path):
    p = tmp_path / "v.mat"
    sio.savemat(str(p), {"M": np.eye(2), "K": np.eye(2)})
    _raises(p, "'Q'", "K, M", names=["Q"])
    mm = tmp_path / "one.mtx"
    sio.mmwrite(str(mm), np.eye(2))
    _raises(mm, "'K'", "one", names=["K"])


def test_complex_entries_are_refused(tmp_path):
    p = tmp_path / "c.mat"
    sio.savemat(str(p), {"K": np.eye(2) * (1 + 1j)})
    _raises(p, "complex", "'K'")
    mm = tmp_path / "c.mtx"
    sio.mmwrite(str(mm), sp.coo_array(np.eye(2) * (1 + 1j)))
    _raises(mm, "complex")
    hb = tmp_path / "c.rua"
    sio.hb_write(str(hb), sp.csc_array(np.eye(2)))
    hb.write_text(hb.read_text().replace("RUA", "CUA", 1))
    _raises(hb, "complex", "CUA")
    if HAVE_PYYETI:
        d = tmp_path / "c.bdf"
        d.write_text("DMIG,KC,0,1,3,0\nDMIG,KC,1,1,,1,1,1.0,2.0\n")
        _raises(d, "complex", "'KC'", "TIN=3")


def test_absurd_header_sizes_are_refused_before_allocating(tmp_path):
    coord = tmp_path / "huge.mtx"
    coord.write_text("%%MatrixMarket matrix coordinate real general\n1000000000 1000000000 1\n1 1 1.0\n")
    _raises(coord, "1000000000x1000000000", str(MAX_DOFS), "MAX_DOFS")
    dense = tmp_path / "dense.mtx"  # within the DOF cap, but 1e12 dense entries
    dense.write_text("%%MatrixMarket matrix array real general\n1000000 1000000\n1.0\n")
    _raises(dense, "1000000000000 entries", "MAX_NONZEROS")
    hb = tmp_path / "huge.rua"
    sio.hb_write(str(hb), sp.csc_array(np.eye(2)))
    lines = hb.read_text().splitlines(keepends=True)
    lines[2] = "RUA" + f"{1_000_000_000:>25d}{1_000_000_000:>14d}{2:>14d}{0:>14d}\n"
    hb.write_text("".join(lines))
    _raises(hb, "1000000000x1000000000", "MAX_DOFS")
    ab = tmp_path / "far.mtx"
    ab.write_text("1, 1, 1.0\n999999999, 999999999, 1.0\n")
    _raises(ab, "999999999", "MAX_DOFS")


def test_dmig_non_square_forms_are_refused(tmp_path):
    pytest.importorskip("pyyeti")
    f9 = tmp_path / "f9.bdf"
    f9.write_text("DMIG,PHI,0,9,2,0,,,2\nDMIG,PHI,1,,,10,1,1.0\nDMIG,PHI,2,,,10,2,1.0\n")
    _raises(f9, "'PHI'", "IFO=9", "square")
    f2 = tmp_path / "f2.bdf"
    f2.write_text("DMIG,R,0,2,2,0\nDMIG,R,10,1,,20,1,1.0\n")
    _raises(f2, "'R'", "IFO=2", "different row and column DOFs")


# ------------------------------------------------------------------------------------------- CalculiX (ccx) itself


def _beam_input(step: str) -> str:
    """A clamped steel beam, 100 x 10 x 10 mm, of 10 x 2 x 2 C3D8 bricks (99 nodes; x = 0 face fixed: 270 DOFs)."""
    nx, ny, nz = 10, 2, 2

    def nid(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)

    lines = ["*HEADING", "brakesqueal test: clamped steel beam", "*NODE, NSET=NALL"]
    lines += [f"{nid(i, j, k)}, {100.0 * i / nx!r}, {10.0 * j / ny!r}, {10.0 * k / nz!r}"
              for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=EALL")
    e = 0
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                e += 1
                n = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                     nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1), nid(i, j + 1, k + 1)]
                lines.append(f"{e}, " + ", ".join(map(str, n)))
    lines += ["*NSET, NSET=FIXED"] + [str(nid(0, j, k)) for k in range(nz + 1) for j in range(ny + 1)]
    lines += ["*BOUNDARY", "FIXED, 1, 3", "*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., 0.3", "*DENSITY",
              "7.85e-9", "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL", "*STEP", step, "*END STEP"]
    return "\n".join(lines) + "\n"


def _ccx(tmp_path, job: str) -> None:
    if shutil.which("ccx") is None:
        if os.environ.get("BRAKESQUEAL_REQUIRE_CCX") == "1":
            pytest.fail("BRAKESQUEAL_REQUIRE_CCX=1 but ccx (CalculiX, Debian package calculix-ccx) is not installed")
        pytest.skip("ccx (CalculiX, Debian package calculix-ccx) is not installed")
    out = subprocess.run(["ccx", job], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                         env={**os.environ, "OMP_NUM_THREADS": "1"})
    assert out.returncode == 0 and "Job finished" in out.stdout, out.stdout[-2000:] + out.stderr[-2000:]


def test_calculix_matrices_give_ccx_eigenfrequencies(tmp_path):
    """ccx's MATRIXSTORAGE matrices, read and solved here, give ccx's own *FREQUENCY eigenvalues.

    Reference: the same model (``_beam_input``) run by ccx with a plain ``*FREQUENCY`` step of 10
    eigenvalues; its ``.dat`` prints EIGENVALUE (ω²) and CYCLES/TIME (Hz) to 7 significant digits.
    MATRIXSTORAGE removes the DOFs fixed by *BOUNDARY, as does the frequency step: like for like.
    """
    (tmp_path / "mat.inp").write_text(_beam_input("*FREQUENCY, SOLVER=MATRIXSTORAGE\n10"))
    (tmp_path / "freq.inp").write_text(_beam_input("*FREQUENCY\n10"))
    _ccx(tmp_path, "mat")
    _ccx(tmp_path, "freq")
    mf = read_matrix_file(str(tmp_path / "mat"))
    assert mf.format == "calculix" and set(mf.matrices) == {"K", "M"}
    assert mf.dofs is not None and len(mf.dofs) == 270 and len(set(mf.dofs)) == 270
    fixed = {str(1 + 11 * m) for m in range(9)}  # the x = 0 face: nodes 1, 12, 23, ...
    assert not {d.split(":")[0] for d in mf.dofs} & fixed  # constrained DOFs are not in the matrices
    K, M = _dense(mf.matrices["K"]), _dense(mf.matrices["M"])
    assert np.array_equal(K, K.T) and np.array_equal(M, M.T)
    lam = la.eigh(K, M, eigvals_only=True, subset_by_index=[0, 9])

    dat = (tmp_path / "freq.dat").read_text()
    block = dat.split("E I G E N V A L U E   O U T P U T")[1].split("P A R T I C I P A T I O N")[0]
    printed = [line.split() for line in block.splitlines() if re.match(r"\s+\d+\s+[-\d.]+E[-+]\d+", line)]
    assert len(printed) == 10
    for (mode, ev, _rad, hz, *_), w2 in zip(printed, lam):
        for text, ours in ((ev, w2), (hz, math.sqrt(w2) / (2 * math.pi))):
            ref = float(text)
            mantissa = text.split("E")[0]
            digits = len(mantissa.split(".")[1])  # 0.1000459E+04: 7 printed digits
            half_unit = 0.5 * 10 ** (math.floor(math.log10(abs(ref))) + 1 - digits)
            assert abs(ours - ref) <= half_unit * 1.001 + 1e-9 * abs(ref), (mode, text, ours)


def test_reading_nastran_files_keeps_numpys_print_options(tmp_path):
    """pyyeti sets numpy's legacy (12-digit) float printing when imported; reading and writing OP4 and DMIG in a
    fresh process leaves the process's print options, and so every CSV or text written after it, as they were."""
    pytest.importorskip("pyyeti")
    import sys

    code = (
        "import numpy as np, pandas as pd\n"
        "from brakesqueal.model.matrix_files import read_matrix_file, write_matrix_file\n"
        "before = np.get_printoptions()\n"
        f"p = {str(tmp_path / 'm.op4')!r}\n"
        "write_matrix_file(p, {'K': np.eye(3)}, 'op4')\n"
        "read_matrix_file(p)\n"
        "assert np.get_printoptions() == before, np.get_printoptions()\n"
        "x = -0.34336942644540613\n"
        "assert str(np.float64(x)) == repr(x)\n"
        "assert float(pd.DataFrame({'a': [x]}).to_csv(index=False).split()[1]) == x\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
