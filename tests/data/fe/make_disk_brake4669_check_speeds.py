"""Make ``disk_brake4669_check_speeds_box.json``: box eigenvalues of the full 4669-DOF brake at Omega = 3, 5, 7 pi.

The reference of ``tests/analysis/test_reduction.py::test_brake4669_reduced_model_keeps_box_eigenvalues``: the
reduced model (a POD basis of the box eigenvectors at Omega = 2, 4, 6, 8 pi) must keep every eigenvalue of the
FULL model in the box Re in [-50, 50], f in [0, 20] kHz at the unsampled speeds 3, 5, 7 pi.  The full-model
eigenvalues do not depend on the reduction, so they are computed once here instead of in every run (3 full sparse
box solves per run, about 20 % of that test's CPU time).

Route: :func:`brakesqueal.analysis.sparse_box.box_eigenvalues` on the full sparse QEP (NLEVP definition
D = D1 + DR/Omega + Omega DG + D4/1600, K = K1 + KR + Omega^2 KGeo), i.e. exactly the computation the test made
before; that route is checked against an independent dense LAPACK solve of the whole 9338-wide linearization at
Omega = 2 pi to 6.5e-11 relative (``disk_brake4669_omega2pi_box.md``, ``test_sparse_box.py``).  Stored: every
eigenvalue (Im >= 0) in a box a little wider than the checked one (Re in [-60, 60], f in [0, 20.5] kHz), with
its first-order error bound, and each run's ``complete`` flag and verdict.  The test selects the checked box from
it.  Run: ``OPENBLAS_NUM_THREADS=1 python tests/data/fe/make_disk_brake4669_check_speeds.py`` (a few minutes).
"""

import datetime
import json
import math
import os
import platform
import time
from importlib import resources

import numpy as np
import scipy
import scipy.io as sio
import scipy.sparse as sp

from brakesqueal.analysis.sparse_box import box_eigenvalues

HERE = os.path.dirname(os.path.abspath(__file__))
FE = resources.files("brakesqueal").joinpath("data", "fe", "tu-berlin-disk-brake-4669")
NAMES = (("M", "BMLL"), ("D1", "BDLL"), ("DG", "BYLL"), ("DR", "BDIWLL"), ("D4", "BHLL"),
         ("K1", "BKLL"), ("KR", "BKQLL"), ("KGeo", "BWLL"))
BOX = {"re": (-60.0, 60.0), "freq": (0.0, 20500.0)}

m = {}
for name, key in NAMES:
    with FE.joinpath(f"{key}00.mat").open("rb") as f:
        m[name] = sp.csc_matrix(sio.loadmat(f)[key])
out = {"problem": "TU Berlin disk brake disk_brake4669 (src/brakesqueal/data/fe/tu-berlin-disk-brake-4669), "
                  "NLEVP definition",
       "definition": "lambda^2 M + lambda (D1 + DR/Omega + Omega DG + D4/1600) + (K1 + KR + Omega^2 KGeo)",
       "box": {"re": list(BOX["re"]), "freq": list(BOX["freq"])},
       "method": "brakesqueal.analysis.sparse_box.box_eigenvalues (defaults k=60, tol=1e-12) of the full sparse QEP",
       "note": __doc__.strip(),
       "made": {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                "python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__},
       "cases": []}
for label, mult in (("3pi", 3), ("5pi", 5), ("7pi", 7)):
    w = mult * math.pi
    D = (m["D1"] + m["DR"] / w + w * m["DG"] + m["D4"] / 1600.0).tocsc()
    K = (m["K1"] + m["KR"] + w**2 * m["KGeo"]).tocsc()
    t0 = time.perf_counter()
    res = box_eigenvalues(m["M"], D, K, vectors=False, **BOX)
    sec = time.perf_counter() - t0
    order = np.argsort(res.eigenvalues.imag)
    lam, bnd = res.eigenvalues[order], np.asarray(res.bounds)[order]
    out["cases"].append({"label": label, "omega": w, "complete": bool(res.complete), "verdict": str(res.verdict),
                         "seconds": sec, "count": int(lam.size),
                         "eigenvalues": [[float(v.real), float(v.imag)] for v in lam],
                         "bounds": [float(b) for b in bnd]})
    print(label, res.complete, res.verdict, lam.size, f"{sec:.1f} s", flush=True)
with open(os.path.join(HERE, "disk_brake4669_check_speeds_box.json"), "w") as f:
    json.dump(out, f, indent=1)
