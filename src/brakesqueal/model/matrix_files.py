r"""Readers and writers of finite-element coefficient matrices (the ``matrices`` model kind).

An imported brake-squeal model is the quadratic eigenvalue problem
:math:`(\lambda^2 M + \lambda D + K)\,x = 0`; its matrices come out of a
finite-element program in one of these formats (:data:`FORMATS`):

* ``mat`` — MATLAB ``.mat`` (v4 to v7.2; :func:`scipy.io.loadmat`): every 2-D numeric variable by its name;
  no DOFs.
* ``mm`` — Matrix Market ``.mtx``/``.mm`` (:func:`scipy.io.mmread`): one, named after the file stem; no DOFs.
* ``hb`` — Harwell–Boeing ``.hb``/``.rua``/``.rsa``/``.rb``: one, named after the file stem; no DOFs.
* ``abaqus`` — ABAQUS ``*MATRIX GENERATE`` text ``.mtx``: one (``job_STIF1``, ``job_MASS1`` …); ``node:dof``.
* ``calculix`` — CalculiX ``*FREQUENCY, SOLVER=MATRIXSTORAGE``: ``K`` (``.sti``) and ``M`` (``.mas``);
  ``node:dof``.
* ``dmig`` — Nastran DMIG bulk data (``.bdf``/``.pch``/``.nas`` …): every DMIG by its name; ``grid:component``.
* ``op4`` — Nastran OUTPUT4 ``.op4`` (binary or text): every matrix by its (upper-case) name; no DOFs.

Format references and the rules this module follows:

- Matrix Market: R. F. Boisvert, R. Pozo, K. Remington, "The Matrix Market
  Exchange Formats: Initial Design", NIST IR 5935 (1996).  The header is read
  first (:func:`scipy.io.mminfo`): complex, Hermitian and pattern matrices are
  refused, and so is a header announcing more than :data:`MAX_DOFS` rows or
  :data:`MAX_NONZEROS` entries, before anything is allocated.
- Harwell–Boeing: I. S. Duff, R. G. Grimes, J. G. Lewis, "Users' Guide for the
  Harwell-Boeing Sparse Matrix Collection", RAL-92-086 (1992).  The third
  header line (type, rows, columns, non-zeros) is checked before reading; real
  assembled types ``RUA`` (general), ``RSA`` (symmetric: the stored triangle is
  mirrored) and ``RZA`` (skew-symmetric) are read, others refused.
- ABAQUS: Abaqus Keywords Reference, ``*MATRIX GENERATE``, ``*MATRIX OUTPUT``
  (``FORMAT=MATRIX INPUT``, the default, and ``FORMAT=COORDINATE``) and
  ``*MATRIX INPUT``.  Data lines are ``row node, row dof, column node, column
  dof, value`` (DOF labels ``node:dof``, sorted by node, then dof; ABAQUS's
  internal nodes have negative labels and sort first) or, in the coordinate
  form, ``row, column, value`` with 1-based equation numbers (no DOF labels).
  Lines starting with ``*`` (``**`` comments, keyword lines) and blank lines
  are skipped; commas or blanks separate the fields.
- CalculiX: ccx User's Manual, ``*FREQUENCY`` (``SOLVER=MATRIXSTORAGE``), and
  ccx's ``matrixstorage.c``: ``job.sti`` (stiffness) and ``job.mas`` (mass)
  hold lines ``i j value`` (1-based, ``i <= j``: one triangle of the symmetric
  matrix, every diagonal entry included, column by column), ``job.dof`` one
  line ``node.direction`` per row.  Only the active DOFs are there: ccx removes
  the DOFs fixed by ``*BOUNDARY`` (single-point constraints) and the dependent
  DOFs of MPCs before storing.  For a cyclic-symmetry model ccx stores the
  real form ``[[R, -I], [I, R]]`` of double size with one DOF list: the
  second half is labelled ``node:dir:im``.
- Nastran DMIG: MSC/NX Nastran Quick Reference Guide, ``DMIG`` bulk entry.
  Small-field, large-field and free-field cards are read (pyyeti's card
  reader); real matrices of form ``IFO`` 1 (square), 6 (symmetric: one
  triangle given, mirrored; giving both ``(i, j)`` and ``(j, i)`` with
  different values is an error, as in Nastran) and 2 (rectangular, accepted
  when its row and column DOF sets are equal) are read; form 9 and other
  non-square ones are refused.  The matrices of one file are put on the union
  of their DOFs (as Nastran adds ``K2GG``-type DMIGs on the g-set), sorted by
  grid, then component.
- OP4: the Nastran ``OUTPUT4`` module description (QRG); read and written with
  pyyeti's :mod:`pyyeti.nastran.op4` (binary, double precision, on writing).

DMIG and OP4 need the optional dependency ``pyyeti`` (``pip install
'brakesqueal[fe]'``), imported only when such a file is read or written.

One triangle or both (ABAQUS, CalculiX): a coordinate list whose off-diagonal
entries all lie in one triangle (with respect to the DOF order) is taken as
the stored half of a symmetric matrix and mirrored; one with entries in both
triangles is taken as the full matrix.  (A genuinely triangular matrix can
therefore not be told apart: :func:`write_matrix_file` writes an explicit
zero in the other triangle of such a matrix so that it reads back as it was.)
A position given twice is an error.

Every reading problem is a :class:`~brakesqueal.errors.ParameterError` whose
one-line message names the file, what is wrong and what is allowed.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
import scipy.sparse as sp

from ..errors import OutputError, ParameterError

__all__ = [
    "FORMATS",
    "MAX_DOFS",
    "MAX_NONZEROS",
    "MatrixFile",
    "detect_format",
    "read_matrix_file",
    "write_matrix_file",
]

#: The matrix file formats, in the order the docs list them.
FORMATS: tuple[str, ...] = ("mat", "mm", "hb", "abaqus", "calculix", "dmig", "op4")

#: The largest matrix dimension accepted (checked against a file's header before allocating).
MAX_DOFS: int = 2_000_000

#: The most stored entries accepted in one matrix (a dense matrix counts all of its entries).
MAX_NONZEROS: int = 500_000_000

_EXTENSIONS: dict[str, str] = {
    ".mat": "mat",
    ".mm": "mm",
    ".hb": "hb", ".rua": "hb", ".rsa": "hb", ".rza": "hb", ".rb": "hb",
    ".sti": "calculix", ".mas": "calculix", ".dof": "calculix",
    ".bdf": "dmig", ".pch": "dmig", ".punch": "dmig", ".nas": "dmig", ".dmig": "dmig", ".blk": "dmig",
    ".op4": "op4",
}

_FORMAT_NAMES = {"mat": "MATLAB", "mm": "Matrix Market", "hb": "Harwell-Boeing", "abaqus": "ABAQUS",
                 "calculix": "CalculiX", "dmig": "Nastran DMIG", "op4": "Nastran OP4"}

Matrix: TypeAlias = np.ndarray | sp.csr_array


@dataclass(frozen=True)
class MatrixFile:
    """The matrices read from one matrix file (or CalculiX file set).

    Attributes
    ----------
    path : str
        The file read (for CalculiX, the ``.sti`` file, or the ``.mas`` one when there is no ``.sti``).
    format : str
        One of :data:`FORMATS`.
    matrices : dict of str to ndarray or scipy.sparse.csr_array
        Name -> square real matrix (dense float64 ``ndarray`` or CSR sparse float64), all of one size.
    dofs : tuple of str or None
        The DOF label of each row (``"12:3"``: node 12, DOF 3) where the format has a DOF map, else None.
    """

    path: str
    format: str
    matrices: dict[str, Matrix]
    dofs: tuple[str, ...] | None


class _Fail(Exception):
    """An internal reading problem; :func:`read_matrix_file` adds the file name."""


def _err(path: str, msg: str) -> ParameterError:
    return ParameterError(f"matrix file '{path}': {msg}", parameter="file")


def _one_line(e: BaseException) -> str:
    text = " ".join(str(e).split())
    return f"{type(e).__name__}: {text[:200]}" if text else type(e).__name__


def _calculix_stem(path: str) -> str:
    root, ext = os.path.splitext(path)
    return root if ext.lower() in (".sti", ".mas", ".dof") else path


def detect_format(path: str) -> str:
    """The format of a matrix file, from its extension (and, for ``.mtx``, its first line).

    Parameters
    ----------
    path : str
        The file.  ``.mtx`` is Matrix Market when the file starts with ``%%MatrixMarket``,
        else ABAQUS; a path without extension whose ``.sti`` or ``.mas`` exists is a CalculiX job stem.

    Returns
    -------
    str
        One of :data:`FORMATS`.

    Raises
    ------
    ParameterError
        Unknown extension, or a ``.mtx`` file that cannot be opened.
    """
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".mtx":
        if os.path.exists(path):  # a FIFO or device is refused before it is opened (it could block forever)
            from ..inputs import check_input_file

            check_input_file(path, "matrix file")
        try:
            with open(path, "rb") as f:
                head = f.read(14)
        except OSError as e:
            raise _err(path, f"cannot be opened ({_one_line(e)})") from None
        return "mm" if head.startswith(b"%%MatrixMarket") else "abaqus"
    if ext in _EXTENSIONS:
        return _EXTENSIONS[ext]
    if os.path.isfile(path + ".sti") or os.path.isfile(path + ".mas"):
        return "calculix"
    known = ", ".join(sorted({".mtx", *_EXTENSIONS}))
    raise _err(path, f"cannot tell the format from the extension '{ext or '(none)'}'; known extensions: {known}; "
                     f"or give the format, one of {', '.join(FORMATS)}")


def _check_format(path: str, format: str | None) -> str:
    if format is None:
        return detect_format(path)
    if not isinstance(format, str) or format.lower() not in FORMATS:
        raise _err(path, f"unknown format {format!r}; formats: {', '.join(FORMATS)}")
    return format.lower()


def _check_dims(what: str, rows: int, cols: int, entries: int | None = None) -> None:
    if rows > MAX_DOFS or cols > MAX_DOFS:
        raise _Fail(f"{what} announces {rows}x{cols}, more than the {MAX_DOFS} DOFs allowed (MAX_DOFS)")
    if entries is not None and entries > MAX_NONZEROS:
        raise _Fail(f"{what} announces {entries} entries, more than the {MAX_NONZEROS} allowed (MAX_NONZEROS)")


def _stem(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]


# ----------------------------------------------------------------------------------------------------------- readers


def _read_mat(path: str, names: Sequence[str] | None) -> tuple[dict[str, Any], None]:
    import scipy.io as sio

    try:
        info = sio.whosmat(path)
    except NotImplementedError:
        raise _Fail("is a MATLAB v7.3 (HDF5) file, which is not supported; save it with -v7 "
                    "(MATLAB: save(file, ..., '-v7'))") from None
    numeric = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
               "sparse", "logical"}
    usable = [n for n, shape, cls in info if cls in numeric and len(shape) == 2]
    if names is None:
        chosen = usable
        if not chosen:
            raise _Fail(f"holds no 2-D numeric variable (it holds: {', '.join(n for n, _, _ in info) or 'nothing'})")
    else:
        shapes = {n: (tuple(shape), cls) for n, shape, cls in info}
        for n in names:
            if n in shapes and n not in usable:
                shape, cls = shapes[n]
                raise _Fail(f"variable '{n}' is a {'x'.join(map(str, shape))} {cls} array; a 2-D square numeric "
                            "matrix is needed")
        missing = [n for n in names if n not in usable]
        if missing:
            raise _Fail(f"has no matrix variable '{missing[0]}'; it holds {', '.join(sorted(usable)) or 'none'}")
        chosen = list(names)
    for n, shape, cls in info:
        if n in chosen:
            _check_dims(f"variable '{n}'", int(shape[0]), int(shape[1]),
                        None if cls == "sparse" else int(shape[0]) * int(shape[1]))
    data = sio.loadmat(path, variable_names=chosen)
    return {n: data[n] for n in chosen}, None


def _read_mm(path: str) -> dict[str, Any]:
    import scipy.io as sio

    rows, cols, entries, fmt, field, symmetry = sio.mminfo(path)
    if field in ("complex",) or symmetry == "hermitian":
        raise _Fail(f"holds a {field} {symmetry} matrix; only real matrices are allowed (complex entries refused)")
    if field == "pattern":
        raise _Fail("holds a pattern matrix (no values); a real or integer matrix is needed")
    _check_dims("the header", int(rows), int(cols), int(entries) * (2 if symmetry != "general" else 1))
    return {_stem(path): sio.mmread(path)}


def _hb_header(path: str) -> tuple[str, int, int, int]:
    with open(path, "rb") as f:
        lines = [f.readline().decode("ascii", "replace") for _ in range(3)]
    line = lines[2]
    mxtype = line[:3].upper()
    try:
        nrow, ncol, nnz = (int(x) for x in line[3:].split()[:3])
    except ValueError:
        raise _Fail("has no Harwell-Boeing header (line 3 must hold the type, rows, columns, non-zeros)") from None
    return mxtype, nrow, ncol, nnz


def _read_hb(path: str) -> dict[str, Any]:
    import io

    import scipy.io as sio

    mxtype, nrow, ncol, nnz = _hb_header(path)
    if len(mxtype) != 3 or mxtype[0] not in "RCPI" or mxtype[1] not in "SUHZR" or mxtype[2] not in "AE":
        raise _Fail(f"has an unknown Harwell-Boeing matrix type '{mxtype}'; RUA, RSA and RZA are read")
    if mxtype[0] == "C":
        raise _Fail(f"holds a complex matrix (type {mxtype}); only real matrices are allowed (complex entries refused)")
    if mxtype[0] == "P":
        raise _Fail(f"holds a pattern matrix (type {mxtype}, no values); RUA, RSA and RZA are read")
    if mxtype[2] == "E":
        raise _Fail(f"holds an unassembled (elemental) matrix (type {mxtype}); RUA, RSA and RZA are read")
    _check_dims("the header", nrow, ncol, nnz * (1 if mxtype[1] == "U" else 2))
    with open(path, "rb") as f:
        raw = f.read().decode("ascii", "replace")
    lines = raw.splitlines(keepends=True)
    lines[2] = "RUA" + lines[2][3:]  # scipy reads only the general layout; symmetric ones are mirrored below
    A = sp.csc_array(sio.hb_read(io.StringIO("".join(lines))))
    if mxtype[1] == "S":
        A = A + sp.triu(A, 1).T + sp.tril(A, -1).T
    elif mxtype[1] == "Z":
        A = A - sp.triu(A, 1).T - sp.tril(A, -1).T
    return {_stem(path): A}


def _read_text_numbers(path: str, ncols: tuple[int, ...]) -> np.ndarray:
    """The data lines of a text file as a float array of ``ncols`` columns (lines starting with * skipped)."""
    rows: list[str] = []
    with open(path, encoding="ascii", errors="replace") as f:
        for ln, line in enumerate(f, 1):
            s = line.strip()
            if not s or s.startswith("*") or s.startswith("$"):
                continue
            rows.append(s.replace(",", " ").rstrip())
    if not rows:
        raise _Fail("holds no data lines")
    first = len(rows[0].split())
    if first not in ncols:
        raise _Fail(f"has data lines of {first} fields; expected {' or '.join(map(str, ncols))} "
                    f"(e.g. {rows[0][:60]!r})")
    try:
        data = np.loadtxt(rows, dtype=np.float64, ndmin=2)
    except ValueError as e:
        raise _Fail(f"has an unreadable data line ({_one_line(e)}); expected {first} numbers per line") from None
    if data.shape[1] != first:
        raise _Fail(f"has data lines of different lengths; expected {first} numbers per line")
    return data


def _ints(col: np.ndarray, what: str) -> np.ndarray:
    if not np.all(np.isfinite(col)) or np.any(col != np.round(col)):
        bad = int(np.flatnonzero(~np.isfinite(col) | (col != np.round(col)))[0])
        raise _Fail(f"has a non-integer {what} {col[bad]!r} on data line {bad + 1}")
    if np.any(np.abs(col) > 2**62):
        raise _Fail(f"has an absurd {what}")
    return col.astype(np.int64)


def _assemble(r: np.ndarray, c: np.ndarray, v: np.ndarray, n: int, name: str) -> sp.csr_array:
    """A square CSR matrix from 0-based triplets; one triangle given -> mirrored (module docstring)."""
    if len(v) > MAX_NONZEROS:
        raise _Fail(f"matrix '{name}' has {len(v)} entries, more than the {MAX_NONZEROS} allowed (MAX_NONZEROS)")
    key = r * n + c
    uniq, counts = np.unique(key, return_counts=True)
    if len(uniq) != len(key):
        k = int(uniq[np.flatnonzero(counts > 1)[0]])
        raise _Fail(f"matrix '{name}' gives the entry ({k // n + 1}, {k % n + 1}) twice; each position once")
    bad = np.flatnonzero(~np.isfinite(v))
    if len(bad):
        i = int(bad[0])
        raise _Fail(f"matrix '{name}' has a non-finite entry {v[i]!r} at ({r[i] + 1}, {c[i] + 1}) (1-based row, "
                    f"column); entries must be finite")
    lower, upper = bool(np.any(r > c)), bool(np.any(r < c))
    if lower != upper:  # one triangle: the stored half of a symmetric matrix
        off = r != c
        r, c, v = np.concatenate([r, c[off]]), np.concatenate([c, r[off]]), np.concatenate([v, v[off]])
    return sp.csr_array((v, (r, c)), shape=(n, n))


def _dof_index(nodes: np.ndarray, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted unique (node, dof) pairs and the index of each input pair among them."""
    pairs = np.stack([nodes, dofs], axis=1)
    uniq, inv = np.unique(pairs, axis=0, return_inverse=True)
    return uniq, inv.ravel()


def _read_abaqus(path: str) -> tuple[dict[str, Any], tuple[str, ...] | None]:
    data = _read_text_numbers(path, (5, 3))
    name = _stem(path)
    if data.shape[1] == 3:
        r, c = _ints(data[:, 0], "row number"), _ints(data[:, 1], "column number")
        if r.min() < 1 or c.min() < 1:
            raise _Fail("has a row or column number below 1 in the coordinate form (row, column, value)")
        n = int(max(r.max(), c.max()))
        _check_dims("the largest row/column number", n, n)
        return {name: _assemble(r - 1, c - 1, data[:, 2], n, name)}, None
    rn, rd = _ints(data[:, 0], "row node"), _ints(data[:, 1], "row dof")
    cn, cd = _ints(data[:, 2], "column node"), _ints(data[:, 3], "column dof")
    m = len(rn)
    uniq, inv = _dof_index(np.concatenate([rn, cn]), np.concatenate([rd, cd]))
    n = len(uniq)
    _check_dims("the DOF list", n, n)
    labels = tuple(f"{a}:{b}" for a, b in uniq.tolist())
    return {name: _assemble(inv[:m], inv[m:], data[:, 4], n, name)}, labels


def _read_calculix(path: str) -> tuple[dict[str, Any], tuple[str, ...] | None, str]:
    stem = _calculix_stem(path)
    files = {"K": stem + ".sti", "M": stem + ".mas"}
    present = {k: f for k, f in files.items() if os.path.isfile(f)}
    if not present:
        raise _Fail(f"no CalculiX matrix file: neither {os.path.basename(files['K'])} nor "
                    f"{os.path.basename(files['M'])} exists (ccx writes them with *FREQUENCY, SOLVER=MATRIXSTORAGE)")
    labels: tuple[str, ...] | None = None
    dof_file = stem + ".dof"
    if os.path.isfile(dof_file):
        with open(dof_file, encoding="ascii", errors="replace") as fh:
            raw = [s.strip() for s in fh if s.strip()]
        if len(raw) > MAX_DOFS:
            raise _Fail(f"{os.path.basename(dof_file)} lists {len(raw)} DOFs, more than the {MAX_DOFS} allowed")
        out = []
        for i, s in enumerate(raw, 1):
            m = re.fullmatch(r"(-?\d+)\.(\d+)", s)
            if not m:
                raise _Fail(f"{os.path.basename(dof_file)} line {i} is {s[:40]!r}; each line must be node.direction")
            out.append(f"{int(m.group(1))}:{int(m.group(2))}")
        labels = tuple(out)
    mats: dict[str, Any] = {}
    sizes: dict[str, int] = {}
    parts: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    for k, f in present.items():
        try:
            data = _read_text_numbers(f, (3,))
        except _Fail as e:
            raise _Fail(f"{os.path.basename(f)} {e}") from None
        r, c = _ints(data[:, 0], "row number"), _ints(data[:, 1], "column number")
        if r.min() < 1 or c.min() < 1:
            raise _Fail(f"{os.path.basename(f)} has a row or column number below 1")
        sizes[k] = int(max(r.max(), c.max()))
        parts[k] = (r - 1, c - 1, data[:, 2])
    if len(set(sizes.values())) > 1:
        (k1, n1), (k2, n2) = sizes.items()
        raise _Fail(f"the matrices differ in size: {k1} ({os.path.basename(present[k1])}) is {n1}x{n1} but {k2} "
                    f"({os.path.basename(present[k2])}) is {n2}x{n2}; all must have one size")
    n = max(sizes.values())
    if labels is not None:
        if n != len(labels) and n != 2 * len(labels):
            raise _Fail(f"{os.path.basename(dof_file)} lists {len(labels)} DOFs but the matrices reach row {n}; "
                        "sizes must match")
        if n == 2 * len(labels):  # cyclic symmetry: [[R, -I], [I, R]]
            labels = labels + tuple(s + ":im" for s in labels)
        n = len(labels)
    _check_dims("the largest row/column number", n, n)
    for k, (r, c, v) in parts.items():
        try:
            mats[k] = _assemble(r, c, v, n, k)
        except _Fail as e:
            raise _Fail(f"{os.path.basename(present[k])}: {e}") from None
    return mats, labels, present.get("K", present.get("M", path))


def _pyyeti(what: str) -> Any:
    import numpy as np

    # pyyeti's modules call np.set_printoptions(legacy="1.13") when imported, which makes str() of every numpy
    # float 12 significant digits for the whole process (pandas' CSV writer, for one, then rounds what it writes):
    # keep the process's print options as they were
    options = np.get_printoptions()
    try:
        import pyyeti.nastran.bulk as bulk
        import pyyeti.nastran.op4 as op4
    except ImportError:
        raise _Fail(f"{what} needs the optional package pyyeti; install it with "
                    "pip install 'brakesqueal[fe]'") from None
    finally:
        np.set_printoptions(**options)
    return bulk, op4


def _read_op4(path: str, names: Sequence[str] | None) -> dict[str, Any]:
    _, op4 = _pyyeti("reading OP4")
    import io
    from contextlib import redirect_stdout

    with redirect_stdout(io.StringIO()):
        found, sizes, forms, mtypes = op4.OP4().dir(path, verbose=False)
    if not found:
        raise _Fail("holds no OP4 matrix")
    upper = [n.upper() for n in found]
    if names is not None:
        missing = [n for n in names if n.upper() not in upper]
        if missing:
            raise _Fail(f"has no matrix '{missing[0]}'; it holds {', '.join(upper)}")
        wanted = {n.upper() for n in names}
    else:
        wanted = set(upper)
    for n, (rows, cols), mtype in zip(upper, sizes, mtypes):
        if n not in wanted:
            continue
        if mtype in (3, 4):
            raise _Fail(f"matrix '{n}' is complex (OP4 type {mtype}); only real matrices are allowed "
                        "(complex entries refused)")
        _check_dims(f"matrix '{n}'", int(rows), int(cols))
    with redirect_stdout(io.StringIO()):
        data = op4.read(path, [n.lower() for n in found if n.upper() in wanted], into="dct", sparse=None)
    return {k.upper(): v for k, v in data.items()}


_DMIG_FORMS = {1: "square", 2: "rectangular", 6: "symmetric", 9: "rectangular (numbered columns)"}


def _read_dmig(path: str, names: Sequence[str] | None) -> tuple[dict[str, Any], tuple[str, ...]]:
    bulk, _ = _pyyeti("reading DMIG")
    import io
    from contextlib import redirect_stdout

    with redirect_stdout(io.StringIO()):
        cards = bulk.rdcards(path, r"DMIG[ *,\t]", regex=True, return_var="list", blank=None, no_data_return=[])
    headers: dict[str, tuple[int, int]] = {}
    columns: dict[str, list[list[Any]]] = {}
    for card in cards:
        if len(card) < 3 or not isinstance(card[0], str):
            raise _Fail(f"has a malformed DMIG card: {card[:6]}")
        name = card[0].strip().upper()
        if name == "UACCEL":
            continue  # a load vector, not a matrix
        if card[1] == 0:
            form, tin = (card + [None, None, None])[2:4]
            if not isinstance(form, int) or not isinstance(tin, int):
                raise _Fail(f"DMIG '{name}' header has no integer form (IFO) and type (TIN)")
            headers[name] = (form, tin)
            columns.setdefault(name, [])
        else:
            columns.setdefault(name, []).append(card)
    if not headers:
        raise _Fail("holds no DMIG matrix (no DMIG header card)")
    headerless = [n for n in columns if n not in headers]
    if headerless:
        raise _Fail(f"DMIG '{headerless[0]}' has column cards but no header card")
    if names is not None:
        missing = [n for n in names if n.upper() not in headers]
        if missing:
            raise _Fail(f"has no DMIG matrix '{missing[0]}'; it holds {', '.join(headers)}")
        chosen = list(dict.fromkeys(n.upper() for n in names))
    else:
        chosen = list(headers)
    triplets = {}
    for name in chosen:
        form, tin = headers[name]
        if tin in (3, 4):
            raise _Fail(f"DMIG '{name}' is complex (TIN={tin}); only real matrices are allowed (complex entries "
                        "refused)")
        if tin not in (1, 2):
            raise _Fail(f"DMIG '{name}' has type TIN={tin}; 1 or 2 (real) are read")
        if form not in (1, 2, 6):
            what = _DMIG_FORMS.get(form, "unknown")
            raise _Fail(f"DMIG '{name}' has form IFO={form} ({what}); a square matrix is needed: IFO 1 (square), "
                        "6 (symmetric) or 2 with equal row and column DOFs")
        rg: list[int] = []
        rc: list[int] = []
        cg: list[int] = []
        cc: list[int] = []
        vals: list[float] = []
        for card in columns[name]:
            gj, cj = card[1], card[2] if card[2] != "" else 0
            terms = card[4:]
            for t in range(0, len(terms), 4):
                g, c, a = (terms[t:t + 3] + ["", "", ""])[:3]
                if g == "" and c == "" and a == "":
                    continue
                c = 0 if c == "" else c
                if not (isinstance(gj, int) and isinstance(cj, int) and isinstance(g, int) and isinstance(c, int)):
                    raise _Fail(f"DMIG '{name}' has a non-integer grid or component near column {gj}, row {g}")
                if a == "":
                    a = 0.0
                if not isinstance(a, (int, float)):
                    raise _Fail(f"DMIG '{name}' has a non-numeric value {a!r} at row {g}:{c}, column {gj}:{cj}")
                rg.append(g)
                rc.append(c)
                cg.append(gj)
                cc.append(cj)
                vals.append(float(a))
        triplets[name] = (form, np.array(rg, np.int64), np.array(rc, np.int64), np.array(cg, np.int64),
                          np.array(cc, np.int64), np.array(vals, np.float64))
    for name, (form, rg_, rc_, cg_, cc_, _v) in triplets.items():
        if form == 2 and set(zip(rg_.tolist(), rc_.tolist())) != set(zip(cg_.tolist(), cc_.tolist())):
            raise _Fail(f"DMIG '{name}' has form IFO=2 (rectangular) with different row and column DOFs; "
                        "a square matrix is needed")
    all_g = np.concatenate([np.concatenate([t[1], t[3]]) for t in triplets.values()])
    all_c = np.concatenate([np.concatenate([t[2], t[4]]) for t in triplets.values()])
    uniq = np.unique(np.stack([all_g, all_c], axis=1), axis=0) if len(all_g) else np.zeros((0, 2), np.int64)
    n = len(uniq)
    _check_dims("the DOF list", n, n)
    lookup = {(int(a), int(b)): i for i, (a, b) in enumerate(uniq.tolist())}
    mats: dict[str, Any] = {}
    for name, (form, rg_, rc_, cg_, cc_, v) in triplets.items():
        r = np.array([lookup[p] for p in zip(rg_.tolist(), rc_.tolist())], np.int64)
        c = np.array([lookup[p] for p in zip(cg_.tolist(), cc_.tolist())], np.int64)
        if form == 6:
            lo, hi = np.minimum(r, c), np.maximum(r, c)
            key = lo * n + hi
            order = np.argsort(key, kind="stable")
            ks, vs = key[order], v[order]
            dup = np.flatnonzero(ks[1:] == ks[:-1])
            for d in dup:
                if vs[d] != vs[d + 1]:
                    k = int(ks[d])
                    raise _Fail(f"DMIG '{name}' (symmetric) gives both ({uniq[k // n][0]}:{uniq[k // n][1]}, "
                                f"{uniq[k % n][0]}:{uniq[k % n][1]}) and its mirror with different values")
            keep = np.ones(len(ks), bool)
            keep[dup + 1] = False
            r, c, v = lo[order][keep], hi[order][keep], vs[keep]
            off = r != c
            r, c, v = np.concatenate([r, c[off]]), np.concatenate([c, r[off]]), np.concatenate([v, v[off]])
        mats[name] = _assemble_general(r, c, v, n, name)
    return mats, tuple(f"{a}:{b}" for a, b in uniq.tolist())


def _assemble_general(r: np.ndarray, c: np.ndarray, v: np.ndarray, n: int, name: str) -> sp.csr_array:
    key = r * n + c
    uniq, counts = np.unique(key, return_counts=True)
    if len(uniq) != len(key):
        raise _Fail(f"matrix '{name}' gives one entry twice; each position once")
    return sp.csr_array((v, (r, c)), shape=(n, n))


def _finish(path: str, fmt: str, raw: Mapping[str, Any], dofs: tuple[str, ...] | None) -> MatrixFile:
    """Check and normalise: square, real, finite, one size; dense float64 or CSR float64."""
    out: dict[str, Matrix] = {}
    size: tuple[str, int] | None = None
    for name, X in raw.items():
        if sp.issparse(X):
            if np.iscomplexobj(X.data):
                raise _Fail(f"matrix '{name}' is complex; only real matrices are allowed (complex entries refused)")
            S = sp.csr_array(X, dtype=np.float64)
            S.sum_duplicates()
            S.sort_indices()
            A: Matrix = S
            shape = A.shape
        else:
            arr = np.asarray(X)
            if np.iscomplexobj(arr):
                raise _Fail(f"matrix '{name}' is complex; only real matrices are allowed (complex entries refused)")
            if arr.dtype.kind not in "fiub":
                raise _Fail(f"matrix '{name}' is not numeric ({arr.dtype}); a real matrix is needed")
            if arr.ndim != 2:
                raise _Fail(f"matrix '{name}' has {arr.ndim} dimensions {arr.shape}; a 2-D square matrix is needed")
            A = np.ascontiguousarray(arr, dtype=np.float64)
            shape = A.shape
        if len(shape) != 2:
            raise _Fail(f"matrix '{name}' has shape {shape}; a 2-D square matrix is needed")
        if shape[0] != shape[1]:
            raise _Fail(f"matrix '{name}' is {shape[0]}x{shape[1]}, not square; a square matrix is needed")
        vals = A.data if sp.issparse(A) else A
        bad = ~np.isfinite(vals)
        if bad.any():
            if isinstance(A, sp.csr_array):
                coo = A.tocoo()
                i = int(np.flatnonzero(~np.isfinite(coo.data))[0])
                where, value = (int(coo.row[i]) + 1, int(coo.col[i]) + 1), coo.data[i]
            else:
                ij = np.argwhere(bad)[0]
                where, value = (int(ij[0]) + 1, int(ij[1]) + 1), A[ij[0], ij[1]]
            raise _Fail(f"matrix '{name}' has a non-finite entry {float(value)!r} at {where} (1-based row, column); "
                        "entries must be finite")
        if size is None:
            size = (name, shape[0])
        elif shape[0] != size[1]:
            raise _Fail(f"the matrices differ in size: '{size[0]}' is {size[1]}x{size[1]} but '{name}' is "
                        f"{shape[0]}x{shape[0]}; all must have one size")
        out[name] = A
    if size is not None and dofs is not None and len(dofs) != size[1]:
        raise _Fail(f"lists {len(dofs)} DOFs but the matrices are {size[1]}x{size[1]}; sizes must match")
    return MatrixFile(path=path, format=fmt, matrices=out, dofs=dofs)


def read_matrix_file(path: str, format: str | None = None, names: Sequence[str] | None = None) -> MatrixFile:
    """Read the coefficient matrices of a finite-element model (formats in the module docstring).

    Parameters
    ----------
    path : str
        The file; for CalculiX the ``.sti``, the ``.mas`` or the job stem (the three files are read).
    format : str, optional
        One of :data:`FORMATS` (default: :func:`detect_format`).
    names : sequence of str, optional
        The matrices to keep (default: all of the file).  For DMIG and OP4 the names are compared
        case-insensitively and returned upper-case, as Nastran writes them.

    Returns
    -------
    MatrixFile

    Raises
    ------
    ParameterError
        A one-line message naming the file and the problem: missing file, unknown format,
        unreadable content, a matrix that is not 2-D, not square, complex or has NaN/inf entries,
        matrices of different sizes, a missing name, or a header announcing more than
        :data:`MAX_DOFS` rows or :data:`MAX_NONZEROS` entries.
    """
    path = os.fspath(path)
    fmt = _check_format(path, format)
    if names is not None:
        if isinstance(names, str) or not all(isinstance(n, str) for n in names):
            raise _err(path, f"names must be a list of matrix names; got {names!r}")
        names = list(names)
    shown = path
    if fmt == "calculix":
        stem = _calculix_stem(path)
        if not (os.path.isfile(stem + ".sti") or os.path.isfile(stem + ".mas")):
            raise _err(path, f"no such file: neither {stem}.sti nor {stem}.mas exists")
    elif not os.path.exists(path):
        raise _err(path, "no such file")
    else:
        from ..inputs import check_input_file

        check_input_file(path, "matrix file")  # a FIFO, device or directory: refused, never opened (one rule)
    try:
        dofs: tuple[str, ...] | None = None
        if fmt == "mat":
            raw, dofs = _read_mat(path, names)
        elif fmt == "mm":
            raw = _read_mm(path)
        elif fmt == "hb":
            raw = _read_hb(path)
        elif fmt == "abaqus":
            raw, dofs = _read_abaqus(path)
        elif fmt == "calculix":
            raw, dofs, shown = _read_calculix(path)
        elif fmt == "dmig":
            raw, dofs = _read_dmig(path, names)
        else:
            raw = _read_op4(path, names)
        if names is not None and fmt in ("mm", "hb", "abaqus", "calculix"):
            missing = [n for n in names if n not in raw]
            if missing:
                raise _Fail(f"has no matrix '{missing[0]}'; it holds {', '.join(raw)}")
            raw = {n: raw[n] for n in names}
        return _finish(shown, fmt, raw, dofs)
    except _Fail as e:
        raise _err(path, f"({_FORMAT_NAMES[fmt]}) {e}") from None
    except ParameterError:
        raise
    except MemoryError:
        raise _err(path, f"({_FORMAT_NAMES[fmt]}) does not fit in memory") from None
    except Exception as e:  # noqa: BLE001 - any parser failure is unreadable content, reported in one line
        raise _err(path, f"({_FORMAT_NAMES[fmt]}) cannot be read as {fmt}: {_one_line(e)}") from None


# ----------------------------------------------------------------------------------------------------------- writers


def _as_matrix(name: str, X: Any) -> Matrix:
    if sp.issparse(X):
        if np.iscomplexobj(X.data):
            raise ParameterError(f"matrix '{name}' is complex; only real matrices can be written", parameter=name)
        S = sp.csr_array(X, dtype=np.float64)
        S.sum_duplicates()
        S.sort_indices()
        A: Matrix = S
    else:
        arr = np.asarray(X)
        if np.iscomplexobj(arr) or arr.dtype.kind not in "fiub":
            raise ParameterError(f"matrix '{name}' must be a real matrix; got dtype {arr.dtype}", parameter=name)
        A = np.ascontiguousarray(arr, dtype=np.float64)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ParameterError(f"matrix '{name}' has shape {A.shape}; a square matrix is needed", parameter=name)
    if not np.all(np.isfinite(A.data if sp.issparse(A) else A)):
        raise ParameterError(f"matrix '{name}' has non-finite entries; they cannot be written", parameter=name)
    return A


def _triplets(A: Matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """0-based (row, column, value) of the stored entries (all non-zeros of a dense matrix)."""
    if isinstance(A, sp.csr_array):
        coo = A.tocoo()
        return coo.row.astype(np.int64), coo.col.astype(np.int64), coo.data
    r, c = np.nonzero(A)
    return r.astype(np.int64), c.astype(np.int64), A[r, c]


def _is_symmetric(A: Matrix) -> bool:
    if sp.issparse(A):
        return bool((A != A.T).nnz == 0)
    return bool(np.array_equal(A, A.T))


def _node_dofs(dofs: Sequence[str], what: str, *, sorted_required: bool) -> list[tuple[int, int]]:
    out = []
    for s in dofs:
        m = re.fullmatch(r"\s*(-?\d+)\s*:\s*(\d+)\s*", str(s))
        if not m:
            raise ParameterError(f"{what}: DOF label {s!r} must be node:dof (e.g. 12:3)", parameter="dofs")
        out.append((int(m.group(1)), int(m.group(2))))
    if len(set(out)) != len(out):
        raise ParameterError(f"{what}: DOF labels must be distinct", parameter="dofs")
    if sorted_required and out != sorted(out):
        raise ParameterError(f"{what}: DOF labels must be sorted by node, then dof (the order the format is "
                             "read back in)", parameter="dofs")
    return out


def _write_abaqus(path: str, A: Matrix, dofs: Sequence[str] | None) -> None:
    labels = _node_dofs(dofs, "abaqus", sorted_required=True) if dofs is not None else None
    r, c, v = _triplets(A)
    n = A.shape[0]
    if _is_symmetric(A):
        keep = r >= c  # the lower triangle, as ABAQUS writes symmetric matrices
        r, c, v = r[keep], c[keep], v[keep]
    elif np.any(r != c) and not (np.any(r > c) and np.any(r < c)):
        i = int(np.flatnonzero(r != c)[0])  # triangular: an explicit zero marks full storage
        r, c, v = np.append(r, c[i]), np.append(c, r[i]), np.append(v, 0.0)
    on_diagonal = set(r[r == c].tolist())
    missing = [i for i in range(n) if i not in on_diagonal]
    if missing:  # every DOF appears (its diagonal entry, zero or not), so the DOF list reads back whole
        r = np.concatenate([r, np.array(missing, np.int64)])
        c = np.concatenate([c, np.array(missing, np.int64)])
        v = np.concatenate([v, np.zeros(len(missing))])
    order = np.lexsort((r, c))
    lines = ["** written by brakesqueal: " + ("node, dof, node, dof, value" if labels else "row, column, value")]
    if labels is not None:
        lines += [f"{labels[i][0]},{labels[i][1]}, {labels[j][0]},{labels[j][1]}, {x!r}"
                  for i, j, x in zip(r[order].tolist(), c[order].tolist(), v[order].tolist())]
    else:
        lines += [f"{i + 1}, {j + 1}, {x!r}" for i, j, x in zip(r[order].tolist(), c[order].tolist(),
                                                             v[order].tolist())]
    _write_text(path, "\n".join(lines) + "\n")


def _write_calculix(path: str, mats: Mapping[str, Matrix], dofs: Sequence[str] | None) -> None:
    stem = _calculix_stem(path)
    unknown = [k for k in mats if k not in ("K", "M")]
    if unknown:
        raise ParameterError(f"calculix: matrix '{unknown[0]}' cannot be written; the files hold K (.sti) and "
                             "M (.mas)", parameter=unknown[0])
    if dofs is not None:
        _node_dofs(dofs, "calculix", sorted_required=False)
    for k, A in mats.items():
        if not _is_symmetric(A):
            raise ParameterError(f"calculix: matrix '{k}' is not symmetric; ccx's files store one triangle of a "
                                 "symmetric matrix", parameter=k)
        r, c, v = _triplets(A)
        keep = r < c
        n = A.shape[0]
        d = np.arange(n, dtype=np.int64)
        dv = A.diagonal()
        r = np.concatenate([d, r[keep]])
        c = np.concatenate([d, c[keep]])
        v = np.concatenate([dv, v[keep]])
        order = np.lexsort((r, c))  # column by column, rows ascending, as ccx's matrixstorage.c
        text = "".join(f"{i + 1} {j + 1} {x:.17e}\n" for i, j, x in zip(r[order].tolist(), c[order].tolist(),
                                                                          v[order].tolist()))
        _write_text(stem + (".sti" if k == "K" else ".mas"), text)
    if dofs is not None:
        _write_text(stem + ".dof", "".join(s.strip().replace(":", ".").replace(" ", "") + "\n" for s in dofs))


def _nastran_name(name: str, fmt: str) -> str:
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,7}", name):
        raise ParameterError(f"{fmt}: matrix name {name!r} must be 1 to 8 letters, digits or _ starting with a letter "
                             "(a Nastran name)", parameter=name)
    return name.upper()


def _write_dmig(path: str, mats: Mapping[str, Matrix], dofs: Sequence[str] | None) -> None:
    n = next(iter(mats.values())).shape[0]
    labels = (_node_dofs(dofs, "dmig", sorted_required=True) if dofs is not None
              else [(i + 1, 0) for i in range(n)])
    lines = ["$ DMIG matrices written by brakesqueal (free field, 17 significant digits)"]
    for name, A in mats.items():
        nm = _nastran_name(name, "dmig")
        sym = _is_symmetric(A)
        r, c, v = _triplets(A)
        if sym:
            keep = r >= c  # lower triangle, column by column, as Nastran punches symmetric DMIGs
            r, c, v = r[keep], c[keep], v[keep]
        present = set(c.tolist())
        extra = [j for j in range(n) if j not in present]
        if extra:  # a zero diagonal term per empty column, so that every DOF is read back
            r = np.concatenate([r, np.array(extra, np.int64)])
            c = np.concatenate([c, np.array(extra, np.int64)])
            v = np.concatenate([v, np.zeros(len(extra))])
        order = np.lexsort((r, c))
        r, c, v = r[order], c[order], v[order]
        lines.append(f"DMIG,{nm},0,{6 if sym else 1},2,0")
        starts = np.flatnonzero(np.r_[True, c[1:] != c[:-1]])
        ends = np.r_[starts[1:], len(c)]
        for s, e in zip(starts.tolist(), ends.tolist()):
            g, cc = labels[int(c[s])]
            terms = [f"{labels[int(i)][0]},{labels[int(i)][1]},{x!r},," for i, x in zip(r[s:e].tolist(),
                                                                                     v[s:e].tolist())]
            first, rest = terms[0], terms[1:]
            lines.append(f"DMIG,{nm},{g},{cc},,{first}")
            for t in range(0, len(rest), 2):
                lines.append("," + "".join(rest[t:t + 2]))
    _write_text(path, "\n".join(lines) + "\n")


def _write_text(path: str, text: str) -> None:
    try:
        with open(path, "w", encoding="ascii") as f:
            f.write(text)
    except OSError as e:
        raise OutputError(f"cannot write matrix file '{path}': {_one_line(e)}") from None


def write_matrix_file(path: str, matrices: Mapping[str, Any], format: str,
                      dofs: Sequence[str] | None = None) -> None:
    """Write coefficient matrices in one of :data:`FORMATS`, exactly (17 significant digits in text formats).

    Parameters
    ----------
    path : str
        The file; for CalculiX the job stem (or its ``.sti``/``.mas``): ``.sti``, ``.mas`` and, with
        ``dofs``, ``.dof`` are written.
    matrices : Mapping[str, array_like or scipy.sparse]
        Name -> square real finite matrix, all of one size.  ``mm``, ``hb`` and ``abaqus`` hold one
        matrix per file (read back under the file's stem); ``calculix`` holds ``K`` and/or ``M``
        (symmetric); ``dmig`` and ``op4`` names are Nastran names (1–8 characters).
    format : str
        One of :data:`FORMATS`.
    dofs : sequence of str, optional
        DOF labels ``node:dof`` (``abaqus``, ``calculix``, ``dmig``; for ``abaqus`` and ``dmig`` sorted
        by node, then dof, the order they are read back in).  Without them ABAQUS gets the coordinate
        form ``row, column, value``, CalculiX no ``.dof`` file and DMIG scalar points ``i:0``.

    Raises
    ------
    ParameterError
        Bad matrices, names, labels or format.
    OutputError
        The file cannot be written.
    """
    path = os.fspath(path)
    if not isinstance(format, str) or format.lower() not in FORMATS:
        raise ParameterError(f"unknown matrix file format {format!r}; formats: {', '.join(FORMATS)}",
                             parameter="format")
    fmt = format.lower()
    if not matrices:
        raise ParameterError("write_matrix_file: give at least one matrix", parameter="matrices")
    mats = {str(k): _as_matrix(str(k), X) for k, X in matrices.items()}
    sizes = {A.shape[0] for A in mats.values()}
    if len(sizes) > 1:
        raise ParameterError(f"the matrices differ in size ({sorted(sizes)}); all must have one size",
                             parameter="matrices")
    n = sizes.pop()
    if dofs is not None:
        dofs = [str(s) for s in dofs]
        if len(dofs) != n:
            raise ParameterError(f"{len(dofs)} DOF labels for {n}x{n} matrices", parameter="dofs")
    if fmt in ("mm", "hb", "abaqus") and len(mats) != 1:
        raise ParameterError(f"{fmt} holds one matrix per file; got {len(mats)} ({', '.join(mats)})",
                             parameter="matrices")
    try:
        if fmt == "mat":
            import scipy.io as sio

            for k in mats:
                if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,62}", k):
                    raise ParameterError(f"mat: variable name {k!r} is not a MATLAB name", parameter=k)
            sio.savemat(path, {k: (sp.csc_matrix(A) if sp.issparse(A) else A) for k, A in mats.items()},
                        do_compression=True, oned_as="column")
        elif fmt == "mm":
            import scipy.io as sio

            A = next(iter(mats.values()))
            sio.mmwrite(path, sp.coo_array(A) if sp.issparse(A) else A, symmetry="general")
        elif fmt == "hb":
            import scipy.io as sio

            A = next(iter(mats.values()))
            sio.hb_write(path, sp.csc_array(A))
        elif fmt == "abaqus":
            _write_abaqus(path, next(iter(mats.values())), dofs)
        elif fmt == "calculix":
            _write_calculix(path, mats, dofs)
        elif fmt == "dmig":
            _write_dmig(path, mats, dofs)
        else:
            try:
                _, op4 = _pyyeti("writing OP4")
            except _Fail as e:
                raise ParameterError(f"op4: {e}", parameter="format") from None
            names = [_nastran_name(k, "op4") for k in mats]
            values = [sp.coo_matrix(A) if sp.issparse(A) else A for A in mats.values()]
            op4.write(path, names, values, binary=True, sparse="auto")
    except (ParameterError, OutputError):
        raise
    except OSError as e:
        raise OutputError(f"cannot write matrix file '{path}': {_one_line(e)}") from None
