"""``brakesqueal design``: robust design (issue 27, item 5): choose design variables of a study that minimise
P(squeal) or maximise the certified margin (:mod:`brakesqueal.design`)."""

from __future__ import annotations

import json
import sys
from typing import Annotated, Optional

import typer

from ._options import FormatOpt, OutFormat, ProgressOpt

__all__ = ["register"]


def design(
    study: Annotated[str, typer.Argument(help="Study file (TOML) with [distributions], [samples] n, seed and "
                                              "[design] variables, objective.")],
    out: Annotated[Optional[str], typer.Option("--out", help="Write the result (.json) or the result and every "
                                                             "candidate of the search (.nc).")] = None,
    progress: ProgressOpt = None,
    fmt: FormatOpt = OutFormat.text,
) -> None:
    """Robust design: the design variables' values that minimise P(squeal) or maximise the certified margin."""
    from ..design import load_design, run_design
    from ..outputs import atomic_write, check_output

    if out:
        check_output(out, what="--out", suffixes=(".nc", ".json"))
    ds = load_design(study)
    from ._progress import progress as _progress

    with _progress("design", progress) as cb:
        res = run_design(ds, progress=cb)
    summary = {"study": ds.study.source, **res.to_dict()}
    if out:
        with atomic_write(out, what="--out") as tmp:
            if out.lower().endswith(".json"):
                tmp.write_text(json.dumps(summary, indent=2) + "\n")
            else:
                import numpy as np
                import xarray as xr

                names = list(res.variables)
                xds = xr.Dataset({"candidate_x": (("candidate", "variable"), res.history),
                                  "candidate_objective": ("candidate", res.objective_values,
                                                          {"long_name": f"objective {res.objective} (with the "
                                                                        "tie-break; minimised)"}),
                                  "optimum": ("variable", np.array([res.optimum[k] for k in names])),
                                  "baseline": ("variable", np.array([res.baseline[k] for k in names]))},
                                 coords={"variable": np.array(names, dtype="S")},
                                 attrs={"title": f"brakesqueal design '{ds.study.name}'",
                                        "study_file": ds.study.source, "study_text": ds.study.text,
                                        "result_json": json.dumps(summary)})
                xds.to_netcdf(str(tmp), engine="scipy")
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(summary, indent=2) + "\n")
        return
    sys.stdout.write(f"{ds.study.source}: " + res.text())


def register(app: typer.Typer) -> None:
    """Add ``design`` to ``app``.

    Parameters
    ----------
    app : typer.Typer
        The main application.
    """
    app.command("design")(design)
