"""The explorer's simulation panel shows the coordinate that carries the motion, in that coordinate's unit."""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal import resolve_space, simulate
from brakesqueal.explorer.state import simulation_view
from brakesqueal.model.components import coordinate_unit


@pytest.mark.slow
@pytest.mark.parametrize("model,sets,t_end", [("belt", [], 0.05), ("paper", ["Theta=0.16", "mu1=0.7"], 0.02)])
def test_simulation_panel_names_the_carrying_coordinate_and_its_unit(model, sets, t_end):
    space = resolve_space(model, None, None, sets)
    v = simulation_view(space, t_end)
    tr = simulate(space.resolve({}), t_end, sample_rate=44100.0)
    name = tr.coords[tr.main_coordinate]
    unit = coordinate_unit(name)
    assert v.coordinate == f"{name} − {name}₀ [{unit}]"
    a = tr.final_amplitudes()[name]
    assert f"final amplitude of {name} = {a:.3g} {unit}" in v.summary and tr.stop_reason in v.summary
    # the plotted history is that coordinate's deviation (decimated), not the first coordinate's
    j = tr.main_coordinate
    assert np.max(np.abs(v.x)) == pytest.approx(np.max(np.abs(tr.dq[:, j])), rel=0.05)
