"""The ``[design]`` table of a study file and :func:`run_design` (``brakesqueal design``).

A design study is a study file with ``[distributions]`` and ``[samples] n, seed`` (the uncertain parameters and
their common draws, as ``brakesqueal uq``) and a ``[design]`` table::

    [design]
    variables = { k_ip = [1e5, 1e8] }   # design variables (settable names) and their bounds
    objective = "p_squeal"             # or "margin"
    uncertain = { mu = [0.35, 0.55] }  # optional: the uncertainty box (default: the distributions' supports)
    tolerance = 0.05                   # optional: relative tolerance of the design in the certified box
    maxiter = 30                       # optional: generations of the search
    popsize = 10                       # optional: population per variable
    confidence = 0.95                  # optional: of the Wilson intervals
    max_scale = 1.0                    # optional: largest scale of the uncertainty box ("margin")
    windows = true                     # optional: also the certified stable windows of each variable
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

from ..errors import ParameterError
from ..sweep import Study, load_study
from ..validation import validated
from ._api import OBJECTIVES, DesignResult, robust_design

__all__ = ["DESIGN_KEYS", "DesignStudy", "load_design", "run_design"]

#: Keys of the ``[design]`` table.
DESIGN_KEYS = ("variables", "objective", "uncertain", "tolerance", "maxiter", "popsize", "confidence", "max_scale",
               "windows")


@dataclass(frozen=True)
class DesignStudy:
    """A validated design study.

    Attributes
    ----------
    study : Study
        The study (space, ``[distributions]``, ``[samples]``).
    variables : dict
        Design variable -> bounds.
    objective : str
        One of :data:`~brakesqueal.design.OBJECTIVES`.
    uncertain : dict or None
        The uncertainty box, if given.
    tolerance, confidence, max_scale : float
    maxiter, popsize : int
    windows : bool
    """

    study: Study
    variables: dict[str, tuple[float, float]]
    objective: str
    uncertain: dict[str, tuple[float, float]] | None
    tolerance: float
    maxiter: int
    popsize: int
    confidence: float
    max_scale: float
    windows: bool = True


def _err(source: str, key: str, msg: str) -> ParameterError:
    return ParameterError(f"study file '{source}': key '{key}': {msg}")


def _number(source: str, key: str, v: object) -> float:
    from ..model.expressions import evaluate

    if isinstance(v, str):
        try:
            x = float(evaluate(v, {}, what=f"value of '{key}'"))
        except ParameterError as exc:
            raise _err(source, key, str(exc)) from None
    elif isinstance(v, (int, float)) and not isinstance(v, bool):
        x = float(v)
    else:
        raise _err(source, key, f"must be a number; got {v!r}")
    if not math.isfinite(x):
        raise _err(source, key, f"must be finite; got {v!r}")
    return x


def _bounds(source: str, key: str, tab: object, space: Any, what: str) -> dict[str, tuple[float, float]]:
    if not isinstance(tab, dict) or not tab:
        raise _err(source, key, f"must be a non-empty table of {what}, e.g. {{ k_ip = [1e5, 1e8] }}; got {tab!r}")
    out = {}
    for k, v in tab.items():
        kk = f"{key}.{k}"
        try:
            space.check_axis(k)
        except ParameterError as exc:
            raise _err(source, kk, str(exc)) from None
        if not isinstance(v, list) or len(v) != 2:
            raise _err(source, kk, f"must be [lo, hi]; got {v!r}")
        a, b = _number(source, f"{kk}[0]", v[0]), _number(source, f"{kk}[1]", v[1])
        if not a < b:
            raise _err(source, kk, f"empty or degenerate bounds [{a:g}, {b:g}]: give lo < hi")
        out[k] = (a, b)
    return out


def _integer(source: str, key: str, v: object, lo: int, hi: int) -> int:
    if not isinstance(v, int) or isinstance(v, bool) or not lo <= v <= hi:
        raise _err(source, key, f"must be an integer in [{lo}, {hi}]; got {v!r}")
    return v


@validated
def load_design(study: Union[str, Path, Mapping[str, Any]]) -> DesignStudy:
    """Read and validate a design study (a study file with ``[distributions]``, ``[samples]`` and ``[design]``).

    Parameters
    ----------
    study : str, Path or dict
        The TOML study file (or its content as a dict).

    Returns
    -------
    DesignStudy

    Raises
    ------
    ParameterError
        One line naming the file and the key: no ``[design]`` table, an unknown key, a design variable that is not
        settable or is also uncertain, empty or degenerate bounds, an unknown objective, ``[samples.ranges]``
        (design studies draw from ``[distributions]``), ...
    """
    if isinstance(study, (str, Path)):
        from ..model.io import read_toml_text

        source = str(study)
        _, data = read_toml_text(source, "study file")
    else:
        source, data = "<dict>", dict(study)
    st = load_study(study)
    source = st.source
    if "design" not in data:
        raise _err(source, "design", "missing: a design study needs a [design] table, e.g. [design] variables = "
                                     "{ k_ip = [1e5, 1e8] }")
    tab = data["design"]
    if not isinstance(tab, dict):
        raise _err(source, "design", f"must be a table; got {tab!r}")
    for k in tab:
        if k not in DESIGN_KEYS:
            raise _err(source, f"design.{k}", "unknown key; allowed keys: " + ", ".join(DESIGN_KEYS))
    if st.kind != "samples" or not st.ranges:
        raise _err(source, "distributions", "a design study needs [distributions] and [samples] (n, seed): the "
                                            "uncertain parameters and their common draws")
    for r in st.ranges:
        if r.distribution is None:
            raise _err(source, f"samples.ranges.{r.name}", "a design study draws its uncertain parameters from "
                                                           f"[distributions]; give e.g. {r.name} = {{ uniform = "
                                                           f"[{r.start:g}, {r.stop:g}] }} there")
    space = st.space()
    if "variables" not in tab:
        raise _err(source, "design.variables", "missing: the design variables and their bounds, e.g. variables = "
                                               "{ k_ip = [1e5, 1e8] }")
    variables = _bounds(source, "design.variables", tab["variables"], space, "design variables")
    for k in variables:
        if k in st.sample_names:
            raise _err(source, f"design.variables.{k}", f"'{k}' is also in [distributions]: a parameter is either "
                                                        "a design variable or uncertain")
    objective = tab.get("objective", "p_squeal")
    if objective not in OBJECTIVES:
        raise _err(source, "design.objective", f"must be one of {', '.join(OBJECTIVES)}; got {objective!r}")
    uncertain = None
    if "uncertain" in tab:
        uncertain = _bounds(source, "design.uncertain", tab["uncertain"], space, "uncertain parameters")
        for k in uncertain:
            if k in variables:
                raise _err(source, f"design.uncertain.{k}", f"'{k}' is also a design variable")
    tolerance = _number(source, "design.tolerance", tab.get("tolerance", 0.0))
    if not 0 <= tolerance <= 0.5:
        raise _err(source, "design.tolerance", f"must be in [0, 0.5] (relative); got {tolerance!r}")
    confidence = _number(source, "design.confidence", tab.get("confidence", 0.95))
    if not 0 < confidence < 1:
        raise _err(source, "design.confidence", f"must be in (0, 1); got {confidence!r}")
    max_scale = _number(source, "design.max_scale", tab.get("max_scale", 1.0))
    if not 0 < max_scale <= 100:
        raise _err(source, "design.max_scale", f"must be in (0, 100]; got {max_scale!r}")
    maxiter = _integer(source, "design.maxiter", tab.get("maxiter", 30), 1, 10_000)
    popsize = _integer(source, "design.popsize", tab.get("popsize", 10), 2, 1000)
    windows = tab.get("windows", True)
    if not isinstance(windows, bool):
        raise _err(source, "design.windows", f"must be true or false; got {windows!r}")
    return DesignStudy(st, variables, str(objective), uncertain, tolerance, maxiter, popsize, confidence, max_scale,
                       windows)


@validated
def run_design(study: Union[DesignStudy, str, Path, Mapping[str, Any]], *,
               progress: Callable[[float], None] | None = None) -> DesignResult:
    """Run a design study (``brakesqueal design STUDY.toml``): :func:`robust_design` with the study's space, its
    ``[samples]`` draws of ``[distributions]`` as the common random numbers and its ``[design]`` settings.

    Parameters
    ----------
    study : DesignStudy, str, Path or dict
        A design study (:func:`load_design`).
    progress : callable, optional
        Called with the fraction done.

    Returns
    -------
    DesignResult

    Raises
    ------
    ParameterError
        A bad design study (one line naming the file and the key), bounds reaching invalid parameters, a model
        without a closed form (the certified statement then reads "not available"; the ``margin`` objective is
        refused).
    """
    ds = study if isinstance(study, DesignStudy) else load_design(study)
    st = ds.study
    space = st.space()
    dists = {r.name: r.distribution for r in st.ranges if r.distribution is not None}
    try:
        return robust_design(st.engine(), space, ds.variables, objective=ds.objective,  # type: ignore[arg-type]
                             distributions=dists, draws=st.samples(), n=st.n_samples, seed=st.seed,
                             uncertain=ds.uncertain, tolerance=ds.tolerance, max_scale=ds.max_scale,
                             maxiter=ds.maxiter, popsize=ds.popsize, confidence=ds.confidence, windows=ds.windows,
                             progress=progress)
    except ParameterError as exc:
        if str(exc).startswith("study file"):
            raise
        p = exc.parameter
        key = (f"design.variables.{p}" if p in ds.variables else f"design.uncertain.{p}" if p in (ds.uncertain or {})
               else f"distributions.{p}" if p in dists else "design")
        raise ParameterError(f"study file '{st.source}': key '{key}': {exc}", parameter=p) from None
