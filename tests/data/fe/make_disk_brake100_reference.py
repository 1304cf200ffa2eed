"""Make ``disk_brake100_reference.json``: eigenvalues of NLEVP disk_brake100 to 40 digits (independent of brakesqueal).

For Omega = 2 pi, 4 pi, 8 pi (D = D1 + DR/Omega + Omega DG, K = K1 + KR, the matrices' double entries taken as
exact), the eigenvalues of smallest magnitude (relative accuracy is hardest there: a backward-stable double
precision method guarantees only about kappa u ||(A, B)|| / |lambda|, ~3e-8 for |lambda| ~ 1e-3) are started from
a dense QZ of the companion pencil and refined by Newton's method on the Rayleigh functional
``x^H Q(lambda) x / x^H Q'(lambda) x`` with inverse iteration, in mpmath at 40 digits, until two successive
iterates agree to 1e-30.  Run: ``python tests/data/fe/make_disk_brake100_reference.py`` (about 10 min).
"""

import json
import os
import sys

import mpmath as mp
import numpy as np
import scipy
import scipy.io
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
MAT = os.path.join(HERE, "..", "..", "..", "src", "brakesqueal", "data", "fe", "nlevp-disk-brake-100",
                   "disk_brake100.mat")
COUNT = 6

mp.mp.dps = 40
d = scipy.io.loadmat(MAT)
r = {k: np.asarray(d[k], dtype=float) for k in ("M", "D1", "DR", "DG", "K1", "KR")}
n = r["M"].shape[0]
out = {"note": __doc__.strip(), "mpmath": mp.__version__, "numpy": np.__version__, "scipy": scipy.__version__,
       "cases": []}
for label, w in (("2pi", 2 * mp.pi), ("4pi", 4 * mp.pi), ("8pi", 8 * mp.pi)):
    wf = float(w)
    Mm = mp.matrix(r["M"].tolist())
    Dm = mp.matrix(r["D1"].tolist()) + mp.matrix(r["DR"].tolist()) / w + w * mp.matrix(r["DG"].tolist())
    Km = mp.matrix(r["K1"].tolist()) + mp.matrix(r["KR"].tolist())
    D = r["D1"] + r["DR"] / wf + wf * r["DG"]
    K = r["K1"] + r["KR"]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -D]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), r["M"]]])
    qz = scipy.linalg.eig(A, B, right=False)
    start = qz[np.argsort(np.abs(qz))]
    start = [z for z in start if z.imag >= 0][:COUNT]
    vals = []
    for z in start:
        lam, v = mp.mpc(z), mp.matrix([1] * n)
        for _ in range(12):
            Q = lam ** 2 * Mm + lam * Dm + Km
            x = mp.lu_solve(Q, v)
            x = x / mp.norm(x)
            new = lam - (x.H * Q * x)[0] / (x.H * (2 * lam * Mm + Dm) * x)[0]
            done = abs(new - lam) <= mp.mpf("1e-30") * abs(new)
            lam, v = new, x
            if done:
                break
        vals.append([mp.nstr(lam.real, 35), mp.nstr(lam.imag, 35)])
        print(label, vals[-1], file=sys.stderr)
    out["cases"].append({"Omega": label, "eigenvalues": vals})
with open(os.path.join(HERE, "disk_brake100_reference.json"), "w") as f:
    json.dump(out, f, indent=1)
