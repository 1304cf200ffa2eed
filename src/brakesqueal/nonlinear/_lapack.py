"""The real generalized eigenproblem without holding the interpreter lock (Ctrl-C during harmonic balance).

:func:`scipy.linalg.eig` with two matrices calls LAPACK's ``dggev`` through an
f2py wrapper that keeps the interpreter lock for the whole call: with 200-400
harmonics Hill's pencil has a few thousand rows and one call takes minutes, in
which no other thread runs Python, so neither a ``KeyboardInterrupt`` nor the
command line's watchdog (:mod:`brakesqueal.interrupts`, which ends the program
0.5 s after Ctrl-C) could act: Ctrl-C on ``cycles --pads exact`` took 57-81 s.

:func:`eig_pencil` calls the same ``dggev`` of SciPy's LAPACK (its
``cython_lapack`` entry) through :mod:`ctypes`, which releases the lock
during the call: the results are SciPy's (same routine, same inputs, the same
post-processing), and the watchdog ends an interrupted command line within a
second.  A library caller's ``KeyboardInterrupt`` is raised when the call
returns.
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

__all__ = ["eig_pencil"]

_FN: dict[str, Any] = {}


def _dggev() -> Any:
    """``dggev`` of SciPy's LAPACK as a ctypes function (which releases the interpreter lock), or ``None``."""
    if "dggev" not in _FN:
        fn = None
        try:
            from scipy.linalg import cython_lapack

            cap = cython_lapack.__pyx_capi__["dggev"]  # type: ignore[attr-defined]
            get_name = ctypes.pythonapi.PyCapsule_GetName
            get_name.restype, get_name.argtypes = ctypes.c_char_p, [ctypes.py_object]
            get_ptr = ctypes.pythonapi.PyCapsule_GetPointer
            get_ptr.restype, get_ptr.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
            addr = get_ptr(cap, get_name(cap))
            if addr:
                i, p, c = ctypes.POINTER(ctypes.c_int), ctypes.c_void_p, ctypes.c_char_p
                # jobvl, jobvr, n, a, lda, b, ldb, alphar, alphai, beta, vl, ldvl, vr, ldvr, work, lwork, info
                proto = ctypes.CFUNCTYPE(None, c, c, i, p, i, p, i, p, p, p, p, i, p, i, p, i, i)
                fn = proto(addr)
        except Exception:  # noqa: BLE001 - another SciPy layout: scipy.linalg.eig (holding the lock) is used
            fn = None
        _FN["dggev"] = fn
    return _FN["dggev"]


#: From this many rows on, the QZ iteration runs in a thread of its own and the caller waits interruptibly.
_THREAD_ROWS = 256


def _interruptible(call: Any, work: np.ndarray, lwork: int, *, big: bool) -> None:
    """``call(work, lwork)`` (a ctypes call: the interpreter lock is released), Ctrl-C acting at once if ``big``.

    A large call runs in a daemon thread while this thread waits in steps of
    0.05 s, in which a ``KeyboardInterrupt`` is raised as usual; the abandoned
    call finishes in the background (LAPACK cannot be stopped), holding its own
    references to the arrays it writes, and a command line ends at once.
    """
    if not big:
        call(work, lwork)
        return
    import threading

    failed: list[BaseException] = []

    def run() -> None:
        try:
            call(work, lwork)
        except BaseException as exc:  # noqa: BLE001 - re-raised in the caller  # pragma: no cover
            failed.append(exc)

    t = threading.Thread(target=run, name="brakesqueal-ggev", daemon=True)
    t.start()
    while t.is_alive():
        t.join(0.05)
    if failed:  # pragma: no cover - ctypes calls raise nothing of their own
        raise failed[0]


def eig_pencil(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and right eigenvectors of the real pencil ``a x = lambda b x``, as ``scipy.linalg.eig(a, b)``.

    Parameters
    ----------
    a, b : ndarray
        Real square matrices of the same size (finite).

    Returns
    -------
    w : ndarray of complex
        Eigenvalues (``inf`` where ``b`` is singular, ``nan`` for a singular pencil).
    v : ndarray of complex
        The eigenvectors in columns, each of unit 2-norm.

    Raises
    ------
    ValueError
        A matrix has a non-finite entry.
    numpy.linalg.LinAlgError
        LAPACK's QZ iteration did not converge.
    """
    fn = _dggev()
    a = np.asarray_chkfinite(a, dtype=float)
    b = np.asarray_chkfinite(b, dtype=float)
    if fn is None or a.ndim != 2 or a.shape[0] != a.shape[1] or b.shape != a.shape or a.shape[0] == 0:
        import scipy.linalg as sl

        return sl.eig(a, b)  # type: ignore[no-any-return]
    n = a.shape[0]
    A, B = np.array(a, order="F"), np.array(b, order="F")
    ar, ai, be = np.empty(n), np.empty(n), np.empty(n)
    vl, vr = np.empty(1), np.empty((n, n), order="F")
    N, one, info = ctypes.c_int(n), ctypes.c_int(1), ctypes.c_int(0)

    def call(work: np.ndarray, lwork: int) -> None:
        fn(b"N", b"V", ctypes.byref(N), A.ctypes.data, ctypes.byref(N), B.ctypes.data, ctypes.byref(N),
           ar.ctypes.data, ai.ctypes.data, be.ctypes.data, vl.ctypes.data, ctypes.byref(one), vr.ctypes.data,
           ctypes.byref(N), work.ctypes.data, ctypes.byref(ctypes.c_int(lwork)), ctypes.byref(info))

    query = np.empty(1)
    call(query, -1)
    lwork = max(int(query[0]), 8 * n, 1)
    _interruptible(call, np.empty(lwork), lwork, big=n >= _THREAD_ROWS)
    if info.value < 0:  # pragma: no cover - the arguments above are valid
        raise ValueError(f"illegal value in argument {-info.value} of internal ggev")
    if info.value > 0:
        raise np.linalg.LinAlgError(f"generalized eig algorithm (ggev) did not converge (LAPACK info={info.value})")
    # SciPy's post-processing (scipy.linalg._decomp._geneig): eigenvalues alpha / beta, complex pairs, unit norms
    alpha = ar + 1j * ai
    w = np.empty_like(alpha)
    nz = be != 0
    w[nz] = alpha[nz] / be[nz]
    w[(alpha != 0) & ~nz] = np.inf
    w[(alpha == 0) & ~nz] = complex(np.nan, np.nan) if np.any(ai != 0) else np.nan
    if np.all(w.imag == 0.0):
        v: np.ndarray = vr
    else:
        v = np.array(vr, dtype=complex)
        pair = w.imag > 0
        pair[:-1] |= w.imag[1:] < 0  # as SciPy (its workaround for a LAPACK bug, ticket #709)
        for jp in np.flatnonzero(pair):
            v.imag[:, jp] = vr[:, jp + 1]
            np.conj(v[:, jp], v[:, jp + 1])
    from scipy.linalg import norm  # BLAS nrm2, as SciPy (bit-identical vectors)

    for j in range(n):
        v[:, j] /= norm(v[:, j])
    return w, v
