"""Self-tests of the independent Newton-Euler reference model (tests/reference).

These tests check the reference against facts that follow from the physics
(independence of q3, the trivial-state residual, the structure of the
frictionless linearization, exactness of the symbolic Jacobians) and against
the paper's printed closed forms (eqs. 49, 51-53, 54, 59-61).  They do not use
the package ``brakesqueal``.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

try:
    from reference import newton_euler as ne
except ImportError:  # pragma: no cover - if tests/ becomes a package
    from tests.reference import newton_euler as ne

PAPER = dict(  # section 3.1 values, made asymmetric where possible
    Theta=0.16, Phi=0.32, k_t=1.88e7, d_t=0.1, k1=6e6, k2=5e6, d1=5.0, d2=4.0,
    c_ip1=1 / 2e7, c_ip2=1 / 3e7, mu1=0.4, mu2=0.3, h10=0.012, h20=0.008,
    r=0.13, N0=3000.0, Omega=8 * 2 * np.pi,
)


def random_state(rng, scale=0.05):
    s = {n: scale * rng.standard_normal() for n in ne.STATE}
    s["l1"] *= 0.1
    s["l2"] *= 0.1
    return s


def test_state_and_param_names():
    assert ne.STATE == ("q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "l1", "l2", "dl1", "dl2")
    assert len(ne.PARAMS) == 17 and set(ne.PARAMS) == set(PAPER)
    m = ne.reference_model()
    assert m.psi.shape == (2, 1) and m.g.shape == (2, 1)
    free = m.psi.free_symbols | m.g.free_symbols
    assert free <= set(m.state.values()) | set(m.params.values())


def test_cardan_dcm_is_RxRyRz():
    import sympy.physics.mechanics as me
    m = ne.reference_model()
    N, A1, B = m.extras["frames"]
    q1, q2, q3 = me.dynamicsymbols("q1 q2 q3")

    def R(axis, a):
        c, s = sp.cos(a), sp.sin(a)
        return {"x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
                "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
                "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]

    assert sp.simplify(N.dcm(B) - R("x", q1) * R("y", q2) * R("z", q3)) == sp.zeros(3, 3)
    assert sp.simplify(A1.y.to_matrix(N) - sp.Matrix([0, sp.cos(q1), sp.sin(q1)])) == sp.zeros(3, 1)
    # z0-component of the angular velocity: eq. (40)
    w = B.ang_vel_in(N).to_matrix(N)
    t = me.dynamicsymbols._t
    assert sp.simplify(w[2] - (q2.diff(t) * sp.sin(q1) + q3.diff(t) * sp.cos(q1) * sp.cos(q2))) == 0


def test_psi_and_g_do_not_depend_on_q3():
    rng = np.random.default_rng(1)
    for _ in range(3):
        s = random_state(rng, 0.2)
        psi0, g0 = ne.residuals(s, PAPER)
        for q3 in (0.0, 0.7, -2.9):
            psi, g = ne.residuals({**s, "q3": q3}, PAPER)
            np.testing.assert_allclose(psi, psi0, rtol=1e-13, atol=1e-9)
            np.testing.assert_allclose(g, g0, rtol=1e-13, atol=1e-18)


def test_zero_state_residual_matches_eq49():
    psi, g = ne.residuals(dict.fromkeys(ne.STATE, 0.0), PAPER)
    p = PAPER
    # derived: psi = [0, -N0 (mu1 h10 - mu2 h20)], same sign as eq. (49)
    np.testing.assert_allclose(psi, [0.0, -p["N0"] * (p["mu1"] * p["h10"] - p["mu2"] * p["h20"])],
                               rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(g, [0.0, 0.0])
    # symbolic version of the same statement
    m = ne.reference_model()
    zero = {m.state[n]: 0 for n in ne.STATE}
    P = m.params
    r, Om = sp.Symbol("r", positive=True), sp.Symbol("Omega", positive=True)
    val = m.psi.xreplace(zero).xreplace({P["r"]: r, P["Omega"]: Om}).applyfunc(sp.simplify)
    assert sp.simplify(val - sp.Matrix([0, -P["N0"] * (P["mu1"] * P["h10"] - P["mu2"] * P["h20"])])) \
        == sp.zeros(2, 1)


def test_steady_spin_about_tilted_axis_needs_no_torque():
    """With all external forces off, dq = ddq = 0 at any tilt is a motion
    (axisymmetric disk spinning about its own axis), i.e. the Omega**2 term
    that eq. (44) does not show really vanishes."""
    p = {**PAPER, "k_t": 0.0, "N0": 0.0, "k1": 0.0, "k2": 0.0}
    rng = np.random.default_rng(2)
    for _ in range(3):
        s = dict.fromkeys(ne.STATE, 0.0)
        s.update(q1=0.3 * rng.standard_normal(), q2=0.3 * rng.standard_normal(),
                 l1=0.01 * rng.standard_normal(), l2=0.01 * rng.standard_normal())
        psi, _ = ne.residuals(s, p)
        np.testing.assert_allclose(psi, 0.0, atol=1e-20)


def test_rotational_support_acts_about_x0_and_y1():
    """Only the supports loaded, disk at rest relative to the spin: psi equals
    K_m(q) q_m with K_m = diag(k_t, k_t cos q1) as in eq. (45)."""
    p = {**PAPER, "N0": 0.0, "k1": 0.0, "k2": 0.0, "d1": 0.0, "d2": 0.0}
    s = dict.fromkeys(ne.STATE, 0.0)
    s.update(q1=0.4, q2=-0.25, l1=0.003, l2=-0.002)
    psi, _ = ne.residuals(s, p)
    np.testing.assert_allclose(psi, [p["k_t"] * 0.4, p["k_t"] * np.cos(0.4) * -0.25], rtol=1e-14)


def test_gyroscopic_residual_at_zero_tilt():
    """psi at q = 0 for rates only and no forces: Euler's equations by hand.
    w = (dq1, dq2, Omega), alpha = (ddq1 + Omega dq2, ddq2 - Omega dq1, .)
    psi = Theta alpha + w x (I w) = [Theta ddq1 + Phi Omega dq2, Theta ddq2 - Phi Omega dq1]."""
    p = {**PAPER, "k_t": 0.0, "d_t": 0.0, "N0": 0.0, "k1": 0.0, "k2": 0.0, "d1": 0.0, "d2": 0.0}
    s = dict.fromkeys(ne.STATE, 0.0)
    s.update(dq1=0.7, dq2=-1.3, ddq1=2.1, ddq2=0.4)
    psi, _ = ne.residuals(s, p)
    T, F, W = p["Theta"], p["Phi"], p["Omega"]
    np.testing.assert_allclose(psi, [T * 2.1 + F * W * (-1.3), T * 0.4 - F * W * 0.7], rtol=1e-14)


def _brute_force_residuals(s, p, dps=40):
    """Third route, purely numeric: rotation matrices, contact points from the
    3x3 system of eq. (16), and every time derivative (H_O, p_i, h_i) by
    central differences in time along q(t) = q + dq t + ddq t^2/2,
    l(t) = l + dl t, dq3(t) from the constraint."""
    with mpmath.workdps(dps):
        P = {k: mpmath.mpf(v) for k, v in p.items()}
        S = {k: mpmath.mpf(v) for k, v in s.items()}
        ex, ey, ez = (mpmath.matrix([[1], [0], [0]]), mpmath.matrix([[0], [1], [0]]),
                      mpmath.matrix([[0], [0], [1]]))

        def Rx(a):
            c, si = mpmath.cos(a), mpmath.sin(a)
            return mpmath.matrix([[1, 0, 0], [0, c, -si], [0, si, c]])

        def Ry(a):
            c, si = mpmath.cos(a), mpmath.sin(a)
            return mpmath.matrix([[c, 0, si], [0, 1, 0], [-si, 0, c]])

        def cross(a, b):
            return mpmath.matrix([[a[1] * b[2] - a[2] * b[1]], [a[2] * b[0] - a[0] * b[2]],
                                  [a[0] * b[1] - a[1] * b[0]]])

        def dot(a, b):
            return sum(a[i] * b[i] for i in range(3))

        I3 = mpmath.diag([P["Theta"], P["Theta"], P["Phi"]])

        def kin(t):
            q1 = S["q1"] + S["dq1"] * t + S["ddq1"] * t**2 / 2
            q2 = S["q2"] + S["dq2"] * t + S["ddq2"] * t**2 / 2
            dq1 = S["dq1"] + S["ddq1"] * t
            dq2 = S["dq2"] + S["ddq2"] * t
            A = Rx(q1) * Ry(q2)  # q3 = 0: nothing below depends on q3
            y1, zB = Rx(q1) * ey, A * ez
            dq3 = (P["Omega"] - dq2 * mpmath.sin(q1)) / (mpmath.cos(q1) * mpmath.cos(q2))
            w = dq1 * ex + dq2 * y1 + dq3 * zB
            H = A * I3 * A.T * w
            pts = []
            for i, (K, zoff) in enumerate(((-P["h10"], -P["h10"]), (P["h20"], P["h20"]))):
                l = S[f"l{i + 1}"] + S[f"dl{i + 1}"] * t
                pl = mpmath.matrix([[l], [-P["r"]], [zoff]])
                Amat = mpmath.matrix(3, 3)
                for j, col in enumerate((A * ex, A * ey, -ez)):
                    for k in range(3):
                        Amat[k, j] = col[k]
                uvh = mpmath.lu_solve(Amat, pl - A * (K * ez))  # eq. (16)
                pts.append((pl + uvh[2] * ez, uvh[2]))
            return q1, q2, dq1, dq2, y1, zB, w, H, pts

        eps = mpmath.mpf(10) ** (-dps // 3)
        kp, km, k0 = kin(eps), kin(-eps), kin(mpmath.mpf(0))
        q1, q2, dq1, dq2, y1, zB, w, H, pts = k0
        Hdot = (kp[7] - km[7]) / (2 * eps)
        res = Hdot + (P["k_t"] * q1 + P["d_t"] * dq1) * ex + (P["k_t"] * q2 + P["d_t"] * dq2) * y1
        g = []
        for i in range(2):
            p_i, h_i = pts[i]
            pdot = (kp[8][i][0] - km[8][i][0]) / (2 * eps)
            hdot = (kp[8][i][1] - km[8][i][1]) / (2 * eps)
            vr = pdot - cross(w, p_i)
            tdir = vr / mpmath.sqrt(dot(vr, vr))
            mu = P[f"mu{i + 1}"]
            if i == 0:
                Fn = (P["N0"] - P["k1"] * h_i - P["d1"] * hdot) / (dot(ez, zB) + mu * dot(ez, tdir))
                f = Fn * zB + mu * Fn * tdir
            else:
                Fn = (P["N0"] + P["k2"] * h_i + P["d2"] * hdot) / (dot(ez, zB) - mu * dot(ez, tdir))
                f = -Fn * zB + mu * Fn * tdir
            res -= cross(p_i, f)
            g.append(S[f"l{i + 1}"] + P[f"c_ip{i + 1}"] * (f[0] + mu * P["N0"]))
        return np.array([float(res[0]), float(res[1])]), np.array([float(x) for x in g])


def test_residuals_match_brute_force_numeric_route():
    rng = np.random.default_rng(4)
    for scale in (0.02, 0.2):
        s = random_state(rng, scale)
        psi, g = ne.residuals(s, PAPER)
        psi_bf, g_bf = _brute_force_residuals(s, PAPER)
        np.testing.assert_allclose(psi, psi_bf, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(g, g_bf, rtol=1e-12, atol=1e-18)


@pytest.mark.slow
def test_jacobians_match_finite_differences():
    """Symbolic Jacobians vs. central differences of the 30-digit residual."""
    rng = np.random.default_rng(3)
    s = random_state(rng, 0.05)
    J = ne.jacobians(s, PAPER)
    f = ne._function("residual")
    eps = mpmath.mpf("1e-12")
    with mpmath.workdps(ne.DPS):
        base = ne._values(s, PAPER)
        for grp, names in ne.GROUPS.items():
            for j, name in enumerate(names):
                k = ne.STATE.index(name)
                up, dn = list(base), list(base)
                up[k] += eps
                dn[k] -= eps
                fu, fdn = f(*up), f(*dn)
                (pu, gu), (pd, gd) = (fu[:2], fu[2:]), (fdn[:2], fdn[2:])
                for lhs, a, b in (("psi", pu, pd), ("g", gu, gd)):
                    key = f"{lhs}_{grp}"
                    if key not in J:
                        continue
                    fd = np.array([float((x - y) / (2 * eps)) for x, y in zip(a, b)])
                    np.testing.assert_allclose(J[key][:, j], fd, rtol=1e-10,
                                               atol=1e-12 * (1 + np.abs(J[key]).max()))


def test_frictionless_linearization_structure():
    p = {**PAPER, "mu1": 0.0, "mu2": 0.0, "d_t": 0.0, "d1": 0.0, "d2": 0.0,
         "c_ip1": 0.0, "c_ip2": 0.0}
    s0 = ne.silent_motion(p)
    assert all(s0[n] == 0.0 for n in ne.STATE)
    M, D, K = ne.linearize(s0, p)
    np.testing.assert_allclose(M, np.diag([p["Theta"]] * 2), rtol=1e-15)
    PO = p["Phi"] * p["Omega"]
    np.testing.assert_allclose(D, [[0.0, PO], [-PO, 0.0]], atol=1e-12)
    np.testing.assert_allclose(K, K.T, rtol=1e-14, atol=0)
    h, r = p["h10"] + p["h20"], p["r"]
    np.testing.assert_allclose(np.diag(K), [p["k_t"] + p["N0"] * h + (p["k1"] + p["k2"]) * r**2,
                                            p["k_t"] + p["N0"] * h], rtol=1e-14)


def test_silent_motion_is_trivial_when_eq57_holds():
    mu1, mu2, h = 0.65, 0.35, 0.02
    p = {**PAPER, "mu1": mu1, "mu2": mu2,
         "h10": h * mu2 / (mu1 + mu2), "h20": h * mu1 / (mu1 + mu2)}
    s0 = ne.silent_motion(p)
    for n in ("q1", "q2", "l1", "l2"):
        assert abs(s0[n]) < 1e-15, (n, s0[n])
    J = ne.jacobians(s0, p)
    # at the trivial state the pad rates do not enter linearly: dl := 0 is exact there
    np.testing.assert_allclose(J["psi_dl"], 0.0, atol=1e-12)
    np.testing.assert_allclose(J["g_dl"], 0.0, atol=1e-20)


def test_silent_motion_asymmetric_converges():
    s0 = ne.silent_motion(PAPER)
    psi, g = ne.residuals(s0, PAPER)
    assert np.abs(psi).max() < 1e-13 * PAPER["k_t"] * max(abs(s0["q1"]), abs(s0["q2"]))
    assert np.abs(g).max() < 1e-22
    assert abs(s0["q2"]) > 1e-8  # the asymmetric case really tilts the disk


def _paper_symmetric(P):
    """Eqs. (51)-(53), with the Phi*Omega of the (1,1) entry of eq. (52)
    moved to the (1,2) entry (OCR glitch, cf. eq. 60); 1/k_ipi = c_ipi."""
    Th, Ph, kt, dt, k1, k2, d1, d2, c1, c2, _, _, _, _, r, N0, Om = (P[n] for n in ne.PARAMS)
    mu, h = sp.symbols("mu h", positive=True)
    M = sp.diag(Th, Th)
    D = sp.Matrix([
        [dt + (d1 + d2) * r**2 + mu**2 * N0 * h / 2 * (d1 * c1 + d2 * c2)
         + mu * N0 * h**2 / (2 * Om * r), Ph * Om],
        [mu * N0 * r * (d1 * c1 + d2 * c2) - (d1 + d2) * mu * h * r / 2 - Ph * Om, dt]])
    K = sp.Matrix([
        [kt + N0 * h + (k1 + k2) * r**2 + mu**2 * N0 * h / 2 * (k1 * c1 + k2 * c2),
         mu * N0 * h / (2 * r) * (h - (1 + mu**2) * (N0 * c1 + N0 * c2))],
        [-mu * r * (2 * N0 - N0 * k1 * c1 - N0 * k2 * c2 + k1 * h / 2 + k2 * h / 2),
         kt + (1 + mu**2) * N0 * (h - N0 * c1 - N0 * c2)]])
    return mu, h, (M, D, K)


def _paper_asymmetric(P):
    """Eqs. (59)-(61): k1=k2=k, d1=d2=d, c1=c2=c, mu1 h10 = mu2 h20 (eq. 57)."""
    Th, Ph, kt, dt = P["Theta"], P["Phi"], P["k_t"], P["d_t"]
    m1, m2, r, N0, Om = P["mu1"], P["mu2"], P["r"], P["N0"], P["Omega"]
    k, d, c, h = sp.symbols("k d c h", positive=True)
    s = m1 + m2
    M = sp.diag(Th, Th)
    D = sp.Matrix([
        [dt + 2 * d * r**2 + N0 * d * h * m1 * m2 * c + N0 / (Om * r) * h**2 * m1 * m2 / s, Ph * Om],
        [N0 * d * r * c * s - 2 * h * m1 * m2 * d * r / s - Ph * Om, dt]])
    K = sp.Matrix([
        [kt + N0 * h + 2 * k * r**2 + N0 * k * c * h * m1 * m2,
         N0 * h**2 * m1 * m2 / (r * s) - N0**2 * h * m1 * m2 * c / (r * s) * (2 + m1**2 + m2**2)],
        [-r * N0 * s * (1 - k * c) - 2 * r * k * h * m1 * m2 / s,
         kt + N0 * h * (1 + m1 * m2) - N0**2 * c * (2 + m1**2 + m2**2)]])
    sub = {P["k1"]: k, P["k2"]: k, P["d1"]: d, P["d2"]: d, P["c_ip1"]: c, P["c_ip2"]: c,
           P["h10"]: h * m2 / s, P["h20"]: h * m1 / s}
    return sub, (M, D, K)


def test_trivial_linearization_matches_paper_eqs_51_53():
    m = ne.reference_model()
    P = m.params
    mine = ne.trivial_linearization_symbolic()
    mu, h, paper = _paper_symmetric(P)
    sub = {P["mu1"]: mu, P["mu2"]: mu, P["h10"]: h / 2, P["h20"]: h / 2}
    for name, A, B in zip("MDK", mine, paper):
        diff = (A.xreplace(sub) - B).applyfunc(lambda e: sp.simplify(sp.expand(e)))
        assert diff == sp.zeros(2, 2), (name, diff)


def test_trivial_linearization_matches_paper_eqs_59_61():
    m = ne.reference_model()
    sub, paper = _paper_asymmetric(m.params)
    for name, A, B in zip("MDK", ne.trivial_linearization_symbolic(), paper):
        diff = (A.xreplace(sub) - B).applyfunc(lambda e: sp.simplify(sp.factor(e)))
        assert diff == sp.zeros(2, 2), (name, diff)


def test_symbolic_and_numeric_trivial_linearization_agree():
    mu1, mu2, h = 0.55, 0.45, 0.02
    p = {**PAPER, "mu1": mu1, "mu2": mu2,
         "h10": h * mu2 / (mu1 + mu2), "h20": h * mu1 / (mu1 + mu2)}
    m = ne.reference_model()
    num = ne.linearize(dict.fromkeys(ne.STATE, 0.0), p)
    vals = {m.params[n]: p[n] for n in ne.PARAMS}
    for A, B in zip(ne.trivial_linearization_symbolic(), num):
        Af = np.array(A.xreplace(vals).evalf(30).tolist(), dtype=float)
        np.testing.assert_allclose(B, Af, rtol=1e-13, atol=1e-13 * np.abs(Af).max())
