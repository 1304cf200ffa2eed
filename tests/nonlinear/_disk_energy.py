"""The work of the external moments on the tilting disk over a stretch of a trajectory (energy balance checks).

Independent of the equations' assembly: the Cardan kinematics (q1 about x0, q2 about y1, the spin rate from the
constraint, eq. 40), the contact points and the contact forces f_p = F_n (s z3 + mu v_r/|v_r|) are written here from
the trajectory's outputs (acting F_n, v_r, h, l).  d/dt (T - Omega L_z0) = w . m with w = omega - Omega z0, so over
a period the works sum to zero.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def disk_work(params: Any, tr: Any) -> dict[str, float]:
    """Work [J] of the supports, the support dampers and the pads' contact forces on the disk along ``tr``."""
    from scipy.integrate import trapezoid

    spec = params.model
    t, (q1, q2, dq1, dq2) = tr.t, tr.y[:, :4].T
    Om, kt, dt = float(params["Omega"]), float(params[spec.disk.k_t]), float(params[spec.disk.d_t])
    e_z = np.array([0.0, 0.0, 1.0])
    x0 = np.array([1.0, 0.0, 0.0])
    y1 = np.column_stack([np.zeros_like(q1), np.cos(q1), np.sin(q1)])
    z3 = np.column_stack([np.sin(q2), -np.sin(q1) * np.cos(q2), np.cos(q1) * np.cos(q2)])
    dq3 = (Om - dq2 * np.sin(q1)) / (np.cos(q1) * np.cos(q2))  # the spin constraint z0 . omega = Omega (eq. 40)
    w = dq1[:, None] * x0 + dq2[:, None] * y1 + dq3[:, None] * z3 - Om * e_z
    m_support = -kt * (q1[:, None] * x0 + q2[:, None] * y1)
    m_damper = -dt * (dq1[:, None] * x0 + dq2[:, None] * y1)
    m_contact = np.zeros_like(w)
    for j, pad in enumerate(spec.pads):
        s = 1 if pad.face == "upper" else -1
        r = float(params[pad.radius])
        h0 = float(params[spec.disk.h_upper if s == 1 else spec.disk.h_lower])
        a = math.radians(pad.angle_deg)
        base = np.array([r * math.sin(a), -r * math.cos(a), 0.0])
        e_t = np.array([math.cos(a), math.sin(a), 0.0])
        p = base + tr.contact[:, j, 6][:, None] * e_t + (-s * h0 + tr.contact[:, j, 4])[:, None] * e_z
        vr = tr.sliding_velocities[:, j]
        f = tr.normal_forces[:, j][:, None] * (s * z3 + float(params[f"mu{j + 1}"]) * vr
                                                / np.linalg.norm(vr, axis=1)[:, None])
        m_contact += np.cross(p, f)
    work = {k: trapezoid(np.einsum("ij,ij->i", w, m), t)
            for k, m in (("support", m_support), ("damper", m_damper), ("contact", m_contact))}
    return work
