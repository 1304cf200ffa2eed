"""The piecewise (unilateral-contact) model refuses pads whose tangential deformation is a state.

Why (the pads' rate balance degenerates before lift-off) is shown in
``tests/simulation/test_unilateral_dynamic_pads.py``; here: the refusal names the pads, and the same space with
Coulomb pads is accepted (the refusal depends on the friction law, not on the parameters).
"""

from __future__ import annotations

import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.model.options import regularised_pads, resolve_space
from brakesqueal import model_piecewise_system

SETS = ["mu1=0.5", "mu2=0.5", "k_ip1=1e6", "k_ip2=1e6"]


def test_piecewise_system_refuses_dynamic_pads():
    space = resolve_space(preset="paper-fig3", sets=SETS)
    pw = model_piecewise_system(space, "Omega")  # coulomb pads: quasi-static, accepted
    assert len(pw.modes) == 4
    with pytest.raises(ParameterError, match=r"needs a tangential damper d_ip > 0 .*\(l1, l2, rate-dependent friction\)"):
        model_piecewise_system(regularised_pads(space, 1e-4), "Omega")
