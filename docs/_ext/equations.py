"""Which function implements which equation of the theory page (``docs/theory.md``).

One row per function: the target on the theory page (a MyST label such as ``eq-44-45``, placed
just before the displayed equation), the paper's equation numbers as shown, the function's full
name and what it computes.  ``bsdocs`` renders the whole table on the API index page
(``.. brakesqueal-equations::``) and, on each module's API page, a "Theory" list of the rows of
that module, so the reference and the theory page link both ways.  A row whose function no longer
exists, or whose label is not on the theory page, fails ``make docs`` (``-W``).
"""

from __future__ import annotations

#: (theory label, equations as printed, function, what it computes)
EQUATIONS: list[tuple[str, str, str, str]] = [
    ("eq-2-4", "(2)-(4)", "brakesqueal.symbolic.kinematics.rot", "elementary rotations :math:`R(x,q)`, :math:`R(y,q)`, :math:`R(z,q)`"),
    ("eq-2-4", "(2)-(11)", "brakesqueal.symbolic.kinematics.cardan_kinematics",
     "Cardan kinematics: :math:`A`, rotational Jacobians :math:`J_R` and Hessians :math:`H_R`"),
    ("eq-10-11", "(10)-(11)", "brakesqueal.symbolic.kinematics.dmat_dvec",
     r"derivative of a matrix with respect to a vector, :math:`H_R = \partial J_R/\partial q`"),
    ("eq-37", "(37)", "brakesqueal.symbolic.kinematics.tilde_matrix", r"tilde :math:`\tilde J` of a :math:`3 \times n` matrix (row-block convention)"),
    ("eq-37", "(37)", "brakesqueal.symbolic.kinematics.kron", r"Kronecker product :math:`A \otimes B`"),
    ("eq-16", "(12)-(34), (16)", "brakesqueal.symbolic.contact.pad_contact",
     "contact point and height :math:`h_i`, sliding velocity, friction direction, pad forces of one pad"),
    ("eq-37", "(36)-(37)", "brakesqueal.symbolic.euler.euler_matrices",
     "mass matrix :math:`M_0` and Kronecker gyroscopic matrix of the Euler equations"),
    ("theory-steps", "(38)", "brakesqueal.symbolic.euler.support_moment", "moment of the rotational supports"),
    ("theory-steps", "(41)-(42)", "brakesqueal.symbolic.constraint.spin_constraint",
     r"non-holonomic spin constraint, :math:`\dot q = s + S\,\dot q_m`"),
    ("theory-steps", "(43)-(45)", "brakesqueal.symbolic.constraint.reduce_equations",
     "elimination of the driving moment :math:`M_A`"),
    ("eq-44-45", "(44)-(45), (33)-(34)", "brakesqueal.symbolic.model.derive_equations",
     r"nonlinear residuals :math:`\psi` and pad residuals :math:`g` of the paper's general model"),
    ("eq-44-45", "(2)-(45)", "brakesqueal.symbolic.assemble.build_equations",
     "the same procedure for any model built from components"),
    ("eq-46", "(46)", "brakesqueal.analysis.equilibrium.silent_motion", "silent motion (trivial or Newton), contact checks"),
    ("eq-49", "(49)", "brakesqueal.analysis.equilibrium.is_trivial", "whether the silent motion is the trivial one"),
    ("eq-47-48", "(47)-(48)", "brakesqueal.symbolic.linearize.linear_matrices",
     r":math:`\bar M, \bar D, \bar K` with the pad deformations eliminated through :math:`g = 0`"),
    ("eq-47-48", "(46)-(48)", "brakesqueal.analysis.linear.linearize", "numeric linearization about the silent motion"),
    ("eq-47-48", "(47)", "brakesqueal.analysis.linear.state_matrix", "first-order state matrix"),
    ("eq-47-48", "(33)-(34), rates kept", "brakesqueal.analysis.linear.pad_rate_eigenvalues",
     r"eigenvalues of the descriptor system with the pads' tangential rates :math:`\dot l` kept"),
    ("eq-general-closed-form", "(49)-(61)", "brakesqueal.symbolic.linearize.closed_form",
     r"closed-form :math:`\bar M, \bar D, \bar K` of the general, symmetric, asymmetric-friction and minimal cases"),
    ("eq-general-closed-form", "(47)-(48)", "brakesqueal.symbolic.linearize.model_closed_form",
     "symbolic :math:`M, D, K` of any model about the zero state"),
]
