"""``brakesqueal robust``: certified robust design windows (issue 27, item 4; :mod:`brakesqueal.robust`)."""

from __future__ import annotations

import json
import sys
from typing import Annotated

import typer

from ._options import FormatOpt, ModelOpt, OutFormat, ParamsOpt, PresetOpt, SetOpt, refuse_set_of_axes, space_from

__all__ = ["register"]


def robust(
    box: Annotated[list[str], typer.Option("--box", help="NAME=LO:HI side of the box, LO < HI (repeatable; "
                                                         "settable names; tied names follow).")],
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    margins: Annotated[bool, typer.Option("--margins", help="Also give certified-stable windows per name and "
                                                            "the largest stable box around the nominal design "
                                                            "(the preset's values or --set), within the box.")
                       ] = False,
    worst: Annotated[bool, typer.Option("--worst-case", help="Also bound the worst-case max Re lambda over the "
                                                             "box (certified upper bound, largest value found).")
                     ] = False,
    max_boxes: Annotated[int, typer.Option("--max-boxes", help="Budget of sub-boxes (the rest is reported "
                                                               "undecided).", min=1, max=10_000_000)] = 4000,
    fmt: FormatOpt = OutFormat.text,
) -> None:
    """Stable for every point of a box, unstable somewhere (a certified witness), or undecided sub-boxes."""
    from ..api import engine
    from ..errors import ParameterError
    from ..robust import parse_box, robust_box, stable_margins, worst_case

    sides: dict[str, tuple[float, float]] = {}
    for text in box:
        name, lo, hi = parse_box(text)
        if name in sides:
            raise ParameterError(f"--box {name} is given twice: one --box per name", parameter=name)
        sides[name] = (lo, hi)
    if not margins:
        refuse_set_of_axes(set_, {n: "--box" for n in sides})
    space = space_from(model, preset, params, set_)
    eng = engine(space)
    result = robust_box(eng, space, sides, max_boxes=max_boxes)
    out = result.to_dict()
    if worst:
        out["worst_max_real"] = worst_case(eng, space, sides).to_dict()
    if margins:
        out["margins"] = stable_margins(eng, space, list(sides), within=sides).to_dict()
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(out, indent=2) + "\n")
        return
    text = result.text()
    if worst:
        wc = out["worst_max_real"]
        text += (f"worst-case max Re lambda over the box: < {wc['upper']:.10g} 1/s (certified); "
                 f"{wc['lower']:.10g} 1/s at " + ", ".join(f"{n}={v:.6g}" for n, v in wc["at"].items()) + "\n")
    if margins:
        m = out["margins"]
        text += ("margins around " + ", ".join(f"{n}={v:.6g}" for n, v in m["nominal"].items())
                 + " (certified stable, one name at a time):\n")
        for n, (a, b) in m["windows"].items():
            text += f"  {n} in [{a:.6g}, {b:.6g}]\n"
        text += (f"largest stable box found (scale {m['scale']:.3f} of those windows): "
                 + ", ".join(f"{n} in [{a:.6g}, {b:.6g}]" for n, (a, b) in m["box"].items()) + "\n")
    sys.stdout.write(text)


def register(app: typer.Typer) -> None:
    """Add ``robust`` to ``app``."""
    app.command("robust")(robust)
