"""The explorer's defaults on any model (issue 29): at most 8 sliders at first, map axes over the parameters that
matter (Omega × a friction coefficient, never the disk's inertias), the command line's map colours."""

from __future__ import annotations

import pytest

from brakesqueal import resolve_space
from brakesqueal.model.io import model_to_toml
from brakesqueal.model.library import MODELS, get_model
from brakesqueal.model.roles import parameter_roles
from brakesqueal.plotting import MAP_STABLE, MAP_UNSTABLE
from brakesqueal.explorer.state import (
    MAX_SLIDERS,
    Origin,
    default_axes,
    important_names,
    slider_names,
    stability_names,
)

INERTIAS = {"Theta", "Phi"}


def toml_space(name: str, tmp_path):
    """The default space of built-in model ``name`` read back from its TOML model file (every parameter free)."""
    path = tmp_path / f"{name}.toml"
    path.write_text(model_to_toml(get_model(name)))
    return resolve_space(str(path), None, None, [])


def friction_names(space) -> set[str]:
    uses = parameter_roles(space.model).uses
    return {n for n, roles in uses.items() if any(r.key == "friction.mu" for r, _ in roles)}


@pytest.mark.parametrize("name", list(MODELS))
def test_a_model_file_shows_at_most_8_sliders_and_a_map_over_what_matters(name, tmp_path):
    space = toml_space(name, tmp_path)
    shown, more = slider_names(space)
    assert len(shown) <= MAX_SLIDERS
    assert sorted(shown + more) == sorted(space.preset.free)  # every free name keeps a slider
    along, x, y = default_axes(space)
    assert {x, y} != INERTIAS and along == y
    if len(space.preset.free) > MAX_SLIDERS:
        assert "Omega" in shown and friction_names(space) & set(shown)
        assert shown == important_names(space, list(space.preset.free))[:MAX_SLIDERS]
        matter = stability_names(space, list(space.preset.free))  # the verdict depends on them here
        if "Omega" in matter and friction_names(space) & set(matter):
            assert x == "Omega" and y in friction_names(space), (x, y)
        assert {x, y} <= set(matter), (x, y, matter)


def test_importance_order_of_the_eight_dof_model(tmp_path):
    space = toml_space("eight-dof", tmp_path)
    assert len(space.preset.free) == 26  # the problem: every parameter of a model file is free
    ranked = important_names(space, list(space.preset.free))
    assert ranked[:5] == ["Omega", "mu1", "mu2", "k_ip1", "k_ip2"]
    assert ranked.index("k1") < ranked.index("Theta") and ranked.index("k_t") < ranked.index("m_p")
    assert not INERTIAS & set(slider_names(space)[0])


def test_a_preset_with_few_free_names_keeps_them_in_its_order():
    space = resolve_space(None, "paper-fig2", None, [])
    assert slider_names(space) == (["mu", "k_ip"], [])
    assert default_axes(space) == ("mu", "k_ip", "mu")


def test_the_page_of_a_model_file(tmp_path):
    from brakesqueal.explorer import app

    ex = app.Explorer(Origin(toml_space("eight-dof", tmp_path)), {"nx": "2", "ny": "2"})
    try:
        assert len(ex.params_box.objects) <= MAX_SLIDERS
        assert ex.more_box.visible and ex.more_box.collapsed and ex.more_box.objects == []
        assert ex.more_box.title == f"more parameters ({26 - len(ex.params_box.objects)})"
        ex.more_box.collapsed = False  # opening the card builds the other sliders
        assert len(ex.params_box.objects) + len(ex.more_box.objects) == 26
        assert (ex.state.x, ex.state.y) == ("Omega", "mu1")
        assert ex.fig_map.xaxis.axis_label.startswith("Omega [") and ex.fig_map.yaxis.axis_label.startswith("mu1")
        # the command line's map colours: code 0 unstable, 1 stable
        assert list(ex.map_mapper.palette[:2]) == [MAP_UNSTABLE, MAP_STABLE]
    finally:
        ex.stop()
