"""``robust_design``: choose design variables that minimise P(squeal) or maximise the certified margin."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np

from ..errors import ParameterError
from ..validation import Range, validated
from ._objectives import certified_scales, design_box, squeal_counts
from ._windows import stable_windows

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..uq import Distribution

__all__ = ["OBJECTIVES", "DesignResult", "robust_design", "draw_samples", "uncertainty_box"]

#: The objectives of :func:`robust_design`.
OBJECTIVES = ("p_squeal", "margin")
#: Probability mass left out of the default uncertainty box of an unbounded distribution (half in each tail).
TAIL = 1e-3
_SCALE_LEVELS, _SCALE_STEPS = 8, 8


def _fmt(x: float) -> str:
    return f"{x:.7g}"


@dataclass
class DesignResult:
    """What :func:`robust_design` found.

    Attributes
    ----------
    objective : str
        ``"p_squeal"`` or ``"margin"``.
    variables : dict
        Design variable -> its bounds ``(lo, hi)``.
    scales : dict
        Design variable -> ``"log"`` or ``"linear"`` (the search coordinate).
    baseline, optimum : dict
        Design variable -> value at the baseline (the space's values) and at the optimum.
    p_squeal : dict
        ``"baseline"`` and ``"optimum"`` -> ``{"value", "ci", "squealing", "with_verdict", "no_verdict"}``
        (Wilson interval at :attr:`confidence`; the same draws).
    margin : dict
        ``"baseline"`` and ``"optimum"`` -> the certified scale of the uncertainty box (see :func:`robust_design`).
    certified : dict
        ``"baseline"`` and ``"optimum"`` -> :meth:`brakesqueal.robust.RobustResult.to_dict` over the uncertainty
        box times the design tolerance box (or ``{"verdict": "not available", "reason": ...}``).
    uncertain : dict
        The uncertainty box ``name -> (lo, hi)``.
    windows : dict
        Design variable -> its certified-stable windows within its bounds, the uncertain parameters at the space's
        (nominal) values and the other design variables at the optimum (:func:`~brakesqueal.design.stable_windows`;
        None: not available, e.g. a model without a closed-form quartic).
    robust_windows : dict
        Design variable -> its windows certified stable for every point of the uncertainty box (the other design
        variables at the optimum; None: not available).
    tolerance, confidence : float
        Relative design tolerance of the certified box; confidence level.
    n, seed : int
        Draws and seed (common random numbers).
    evaluations, generations : int
        Candidate designs evaluated; generations of the search.
    message : str
        The optimiser's message.
    history : ndarray, shape (evaluations, d)
        Every candidate design.
    objective_values : ndarray, shape (evaluations,)
        The objective value of every candidate (with the tie-break).
    method : str
        How the optimum was searched.
    """

    objective: str
    variables: dict[str, tuple[float, float]]
    scales: dict[str, str]
    baseline: dict[str, float]
    optimum: dict[str, float]
    p_squeal: dict[str, dict[str, Any]]
    margin: dict[str, float | None]
    certified: dict[str, dict[str, Any]]
    uncertain: dict[str, tuple[float, float]]
    windows: dict[str, list[tuple[float, float]] | None]
    robust_windows: dict[str, list[tuple[float, float]] | None]
    tolerance: float
    confidence: float
    n: int
    seed: int
    evaluations: int
    generations: int
    message: str
    history: np.ndarray = field(repr=False)
    objective_values: np.ndarray = field(repr=False)
    method: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-able form (NaN as ``None``; no history)."""
        def num(x: Any) -> Any:
            if isinstance(x, float) and not math.isfinite(x):
                return None
            if isinstance(x, dict):
                return {k: num(v) for k, v in x.items()}
            if isinstance(x, (list, tuple)):
                return [num(v) for v in x]
            return x

        return num({"objective": self.objective, "variables": self.variables, "scales": self.scales,
                    "baseline": self.baseline, "optimum": self.optimum, "p_squeal": self.p_squeal,
                    "margin": self.margin, "certified": self.certified, "uncertain": self.uncertain,
                    "windows": self.windows, "robust_windows": self.robust_windows,
                    "tolerance": self.tolerance, "confidence": self.confidence,
                    "n": self.n, "seed": self.seed, "evaluations": self.evaluations,
                    "generations": self.generations, "message": self.message, "method": self.method})

    def text(self) -> str:
        """A few lines for people."""
        pct = f"{100 * self.confidence:g} %"
        lines = [f"objective: {self.objective}; variables: "
                 + ", ".join(f"{k} in [{_fmt(a)}, {_fmt(b)}] ({self.scales[k]})" for k, (a, b) in
                             self.variables.items()),
                 "uncertain: " + ", ".join(f"{k} in [{_fmt(a)}, {_fmt(b)}]" for k, (a, b) in self.uncertain.items())
                 + (f"; design tolerance ±{100 * self.tolerance:g} %" if self.tolerance else "")]
        for what, wd in (("other parameters nominal", self.windows),
                         ("for the whole uncertainty box", self.robust_windows)):
            for k, ws in wd.items():
                lines.append(f"certified stable windows of {k} ({what}): "
                             + ("not available (no certified box decisions)" if ws is None else
                                ", ".join(f"[{_fmt(a)}, {_fmt(b)}]" for a, b in ws) or "none"))
        for which in ("baseline", "optimum"):
            x = getattr(self, which)
            p = self.p_squeal[which]
            ps = ("n/a" if p["value"] is None or not math.isfinite(p["value"]) else
                  f"{p['value']:.4f} [{p['ci'][0]:.4f}, {p['ci'][1]:.4f}] ({p['squealing']} of {p['with_verdict']})")
            m = self.margin[which]
            c = self.certified[which]
            lines.append(f"{which}: " + ", ".join(f"{k}={_fmt(v)}" for k, v in x.items())
                         + f"; P(squeal) = {ps}, {pct}; certified margin {'n/a' if m is None else f'{m:.4f}'}"
                         + f"; uncertainty box: {c['verdict']}"
                         + (f" ({c['reason']})" if c.get("reason") else "")
                         + (" (witness " + ", ".join(f"{k}={_fmt(v)}" for k, v in c["witness"].items()
                                                      if k not in ("max_real", "frequency")) + ")"
                            if c.get("witness") else ""))
        lines.append(f"search: {self.method}; {self.evaluations} candidates, {self.generations} generations; "
                     f"{self.message}")
        return "\n".join(lines) + "\n"


def draw_samples(distributions: Mapping[str, Distribution], n: int, seed: int, method: str = "lhs"
                 ) -> dict[str, np.ndarray]:
    """The common draws: ``n`` points of the distributions (Latin hypercube, scrambled Sobol' or random, seeded
    exactly as a study file's ``[samples]`` draws them: :meth:`brakesqueal.sweep.Study.samples`).

    Parameters
    ----------
    distributions : Mapping[str, Distribution]
        Uncertain parameter -> its distribution.
    n, seed : int
        Draws and seed.
    method : {"lhs", "sobol", "random"}
        Sampling method.

    Returns
    -------
    dict
        Name -> ndarray of shape (n,).
    """
    from ..sweep.study import SampleRange, Study

    ranges = tuple(SampleRange(k, *d.support[:2], False, d) for k, d in distributions.items())
    st = Study(source="<design>", text="", name="design", preset=None, values={}, tied={}, kind="samples", axes=(),
               ranges=ranges, n_samples=n, seed=seed, method=method, quantities=(), critical_speed_range=(1.0, 2.0),
               chunks=(n,), store=None)
    return st.samples()


def uncertainty_box(distributions: Mapping[str, Distribution], tail: float = TAIL) -> dict[str, tuple[float, float]]:
    """The default uncertainty box: a bounded distribution's support, else its central ``1 - tail`` interval.

    Parameters
    ----------
    distributions : Mapping[str, Distribution]
        The study's uncertain inputs.
    tail : float
        Probability left outside the box of an unbounded (or lognormal) distribution, half on each side.

    Returns
    -------
    dict of str to (float, float)
        Name -> ``(lo, hi)``.
    """
    out = {}
    for k, d in distributions.items():
        lo, hi, _, _ = d.support
        if not math.isfinite(lo):
            lo = float(d.ppf(np.array([tail / 2]))[0])
        if not math.isfinite(hi):
            hi = float(d.ppf(np.array([1 - tail / 2]))[0])
        if d.kind == "lognormal":
            lo = float(d.ppf(np.array([tail / 2]))[0])
        out[k] = (float(lo), float(hi))
    return out


def _check_valid(space: ParameterSpace, variables: Mapping[str, tuple[float, float]],
                 uncertain: Mapping[str, tuple[float, float]]) -> None:
    """Every corner of the variables' bounds times the uncertainty box is a valid parameter set (one line)."""
    names = (*variables, *uncertain)
    sides = [*variables.values(), *uncertain.values()]
    P = np.array(list(itertools.product(*sides)), dtype=float)
    ok = np.asarray(space.valid(space.arrays({n: P[:, j] for j, n in enumerate(names)})), dtype=bool).reshape(-1)
    if ok.all():
        return
    i = int(np.flatnonzero(~ok)[0])
    point = {n: float(P[i, j]) for j, n in enumerate(names)}
    where = ", ".join(f"{n}={_fmt(v)}" for n, v in point.items())
    try:
        space.resolve(point)
        why = "invalid parameters"
    except ParameterError as exc:
        why = str(exc)
    bad = next((n for n in variables), names[0])
    raise ParameterError(f"robust_design: the bounds of the design variables and the uncertainty box reach an "
                         f"invalid parameter set at {where}: {why}", parameter=bad)


@validated
def robust_design(engine: Engine, space: ParameterSpace, variables: Mapping[str, Sequence[float]], *,
                  objective: Literal["p_squeal", "margin"] = "p_squeal",
                  distributions: Mapping[str, Distribution] | None = None,
                  draws: Mapping[str, Any] | None = None,
                  n: Annotated[int, Range(1, 10**6)] = 1024,
                  seed: Annotated[int, Range(0)] = 0,
                  uncertain: Mapping[str, Sequence[float]] | None = None,
                  tolerance: Annotated[float, Range(0.0, 0.5)] = 0.0,
                  max_scale: Annotated[float, Range(0.0, 100.0, open_low=True)] = 1.0,
                  maxiter: Annotated[int, Range(1, 10_000)] = 30,
                  popsize: Annotated[int, Range(2, 1000)] = 10,
                  confidence: Annotated[float, Range(0.0, 1.0, open_low=True, open_high=True)] = 0.95,
                  windows: bool = True,
                  progress: Callable[[float], None] | None = None) -> DesignResult:
    """Choose design variables (pad stiffnesses, dampers, friction asymmetry at a fixed sum through a tie, ...)
    that minimise the probability of squeal or maximise the certified stability margin.

    **Objectives.** ``"p_squeal"``: the fraction of the draws of the uncertain parameters whose silent motion is
    certified unstable (the certified verdict of :func:`brakesqueal.analysis.points.evaluate`, as ``brakesqueal
    uq``; draws without a verdict are left out). The *same* seeded draws are used for every candidate (common
    random numbers), so the objective is a deterministic function of the design and differences between designs
    are not sampling noise. ``"margin"``: the largest scale ``t`` in ``(0, max_scale]`` such that the uncertainty
    box scaled by ``t`` about its centre, times the design tolerance box, is certified stable by the branch and
    bound of :func:`brakesqueal.robust.decide_boxes` (never by sampling); ``t = 1`` is the whole uncertainty box.

    Both objectives are piecewise constant in the design (P(squeal) over a finite sample is a step function; the
    certified scale is resolved to ``max_scale / 2048``). Ties are broken lexicographically by the largest
    ``max Re λ`` over the draws (or over the box's corners and centre): among designs that are equally good, the
    one whose least-damped draw is most damped wins, which puts the optimum inside a stable window rather than on
    its edge. The tie-break is scaled below the objective's resolution, so it never trades a squealing draw or a
    step of margin for damping.

    **Search.** :func:`scipy.optimize.differential_evolution` (seeded, ``polish=False``, vectorised over the
    population, ``init="sobol"``) in the variables' search coordinates: ``log10`` for a positive variable whose
    bounds span at least a factor 100, else linear. A gradient or simplex method (Nelder-Mead, Powell, L-BFGS-B)
    stalls on a step function (zero gradient almost everywhere, and a simplex collapses on a plateau); a seeded
    population-based global search needs no gradient, covers disjoint stable windows, and is reproducible. The
    baseline and the optimum are then evaluated with the same draws (P(squeal) with a Wilson interval), and the
    whole uncertainty box (times the design tolerance) is decided at each: stable for every point / unstable with
    a witness / undecided.

    Parameters
    ----------
    engine : Engine
        The model's engine (:func:`brakesqueal.engine`).
    space : ParameterSpace
        The parameter space; its values of the design variables are the baseline, of the uncertain parameters the
        nominal design (for :attr:`DesignResult.windows`).
    variables : Mapping[str, sequence of float]
        Settable name -> bounds ``(lo, hi)``, ``lo < hi`` finite.
    objective : {"p_squeal", "margin"}
        What to optimise.
    distributions : Mapping[str, Distribution], optional
        Uncertain parameter -> distribution (:func:`brakesqueal.uq.parse_distribution`). Needed for
        ``"p_squeal"`` unless ``draws`` are given.
    draws : Mapping[str, array_like], optional
        The common draws themselves (e.g. a study's ``samples()``), instead of drawing ``n`` from
        ``distributions``.
    n, seed : int
        Draws (Latin hypercube) and seed.
    uncertain : Mapping[str, sequence of float], optional
        The uncertainty box of the certified statement and the margin; default: the distributions' supports (an
        unbounded distribution's central ``1 - 1e-3`` interval) or the draws' ranges.
    tolerance : float
        Relative tolerance of the design variables in the certified box (``x (1 ± tolerance)``).
    max_scale : float
        Largest scale of the uncertainty box the ``"margin"`` objective tries.
    maxiter, popsize : int
        Generations and population size (per variable) of the search.
    confidence : float
        Confidence level of the Wilson intervals.
    windows : bool
        Also find the certified-stable windows of each design variable within its bounds (nominal parameters).
    progress : callable, optional
        Called with the fraction done.

    Returns
    -------
    DesignResult

    Raises
    ------
    ParameterError
        A design variable that is not settable (unknown or tied) or is also uncertain, empty, degenerate, reversed
        or non-finite bounds, no draws (zero samples), bounds reaching invalid parameters, a certified objective on a
        model without a closed form.
    """
    from scipy.optimize import differential_evolution

    from ..uq import probability_interval

    if not variables:
        raise ParameterError("robust_design: give at least one design variable (name -> (lo, hi))")
    bounds: dict[str, tuple[float, float]] = {}
    for k, v in variables.items():
        space.check_axis(k)
        if len(v) != 2:
            raise ParameterError(f"design variable '{k}': bounds must be [lo, hi]; got {list(v)!r}", parameter=k)
        a, b = float(v[0]), float(v[1])
        if not (math.isfinite(a) and math.isfinite(b)):
            raise ParameterError(f"design variable '{k}': bounds must be finite; got [{a!r}, {b!r}]", parameter=k)
        if not a < b:
            raise ParameterError(f"design variable '{k}': empty or degenerate bounds [{_fmt(a)}, {_fmt(b)}]; "
                                 "give lo < hi", parameter=k)
        bounds[k] = (a, b)
    if draws is None:
        if distributions:
            for k in distributions:
                space.check_axis(k)
            draws = draw_samples(distributions, n, seed)
    S_draws: dict[str, np.ndarray] = {k: np.asarray(v, dtype=float).reshape(-1) for k, v in (draws or {}).items()}
    if S_draws:
        sizes = {v.size for v in S_draws.values()}
        if len(sizes) != 1 or 0 in sizes:
            raise ParameterError("robust_design: the draws must be non-empty arrays of one length (zero samples?); "
                                 f"got lengths {sorted(sizes)}", parameter=next(iter(S_draws)))
    for k in S_draws:
        if k in bounds:
            raise ParameterError(f"'{k}' is both a design variable and an uncertain parameter; give it one role",
                                 parameter=k)
    if objective == "p_squeal" and not S_draws:
        raise ParameterError("robust_design: objective 'p_squeal' needs distributions (or draws) of the uncertain "
                             "parameters", parameter="distributions")
    if uncertain is not None:
        box = {}
        for k, v in uncertain.items():
            space.check_axis(k)
            a, b = (float(t) for t in v)
            if not (math.isfinite(a) and math.isfinite(b) and a < b):
                raise ParameterError(f"uncertain parameter '{k}': empty, degenerate or non-finite box "
                                     f"[{_fmt(a)}, {_fmt(b)}]; give lo < hi", parameter=k)
            if k in bounds:
                raise ParameterError(f"'{k}' is both a design variable and an uncertain parameter; give it one "
                                     "role", parameter=k)
            box[k] = (a, b)
    elif distributions:
        box = uncertainty_box({k: d for k, d in distributions.items()})
    else:
        box = {k: (float(v.min()), float(v.max())) for k, v in S_draws.items() if v.max() > v.min()}
    if objective == "margin" and not box:
        raise ParameterError("robust_design: objective 'margin' needs an uncertainty box (uncertain = {name = "
                             "[lo, hi]}) or distributions", parameter="uncertain")
    _check_valid(space, bounds, box)
    names = tuple(bounds)
    scales = {k: "log" if a > 0 and b / a >= 100 else "linear" for k, (a, b) in bounds.items()}

    def to_x(z: np.ndarray) -> dict[str, np.ndarray]:
        return {k: (10.0 ** z[j] if scales[k] == "log" else z[j]) for j, k in enumerate(names)}

    zb = [(math.log10(a), math.log10(b)) if scales[k] == "log" else (a, b) for k, (a, b) in bounds.items()]
    n_draws = len(next(iter(S_draws.values()))) if S_draws else 0
    probe = {k: np.array([0.5 * (a + b)]) for k, (a, b) in box.items()}
    corners = {k: np.array([c for c in v]) for k, v in zip(box, zip(*itertools.product(*box.values())))} \
        if box else {}
    tie_pts = S_draws or {k: np.concatenate([probe[k], corners[k]]) for k in box}
    hist_x: list[np.ndarray] = []
    hist_f: list[np.ndarray] = []

    def tie(worst: np.ndarray) -> np.ndarray:
        """In [0, 1): larger for a less damped worst draw (NaN: no verdict, worst)."""
        w = np.where(np.isfinite(worst), worst, np.inf)
        return 0.5 + np.arctan(w) / np.pi * (1 - 1e-12)

    failures: list[ParameterError] = []

    def f(z: np.ndarray) -> np.ndarray:
        try:
            return objective_of(z)
        except ParameterError as exc:
            failures.append(exc)
            raise

    def objective_of(z: np.ndarray) -> np.ndarray:
        Z = np.asarray(z, dtype=float)
        Z = Z[:, None] if Z.ndim == 1 else Z  # (d, S): the population at once
        X = to_x(Z)
        if objective == "p_squeal":
            c = squeal_counts(engine, space, X, S_draws)
            p = np.where(c.decided > 0, c.squealing / np.maximum(c.decided, 1), 1.0)
            val = p + 0.25 / n_draws ** 2 * tie(c.worst)
        else:
            t = certified_scales(engine, space, X, box, tolerance, max_scale=max_scale, levels=_SCALE_LEVELS,
                                 steps=_SCALE_STEPS)
            worst = squeal_counts(engine, space, X, tie_pts).worst
            val = -t + 0.25 * max_scale / (_SCALE_LEVELS * 2 ** _SCALE_STEPS) * tie(worst)
        hist_x.append(np.column_stack([X[k] for k in names]))
        hist_f.append(val)
        return val

    gen = [0]

    def cb(*_: Any) -> None:
        gen[0] += 1
        if progress is not None:
            progress(min(0.9, 0.9 * gen[0] / maxiter))

    try:
        res = differential_evolution(f, zb, seed=seed, polish=False, maxiter=maxiter, popsize=popsize, tol=0.0,
                                     init="sobol", vectorized=True, updating="deferred", callback=cb)
    except RuntimeError:  # scipy wraps what the objective raised (a one-line ParameterError): raise that
        if failures:
            raise failures[0] from None
        raise
    opt = {k: float(v[0]) for k, v in to_x(np.asarray(res.x, dtype=float)[:, None]).items()}
    opt = {k: min(max(v, bounds[k][0]), bounds[k][1]) for k, v in opt.items()}
    base = {k: float(space.value(k)) for k in names}

    def p_of(x: dict[str, float]) -> dict[str, Any]:
        if not S_draws:
            return {"value": None, "ci": [None, None], "squealing": 0, "with_verdict": 0, "no_verdict": 0}
        c = squeal_counts(engine, space, {k: np.array([v]) for k, v in x.items()}, S_draws)
        k_, m_ = int(c.squealing[0]), int(c.decided[0])
        p, lo, hi = probability_interval(k_, m_, confidence)
        return {"value": p, "ci": [lo, hi], "squealing": k_, "with_verdict": m_, "no_verdict": n_draws - m_}

    def cert(x: dict[str, float]) -> tuple[dict[str, Any], float | None]:
        if not box:
            return {"verdict": "not available", "reason": "no uncertainty box"}, None
        from ..robust import robust_box

        try:
            r = robust_box(engine, space, {**design_box(x, tolerance), **box})
            t = float(certified_scales(engine, space, {k: np.array([v]) for k, v in x.items()}, box, tolerance,
                                       max_scale=max_scale, levels=_SCALE_LEVELS, steps=_SCALE_STEPS)[0])
        except ParameterError as exc:
            return {"verdict": "not available", "reason": str(exc)}, None
        return r.to_dict(), t

    p_base, p_opt = p_of(base), p_of(opt)
    (c_base, m_base), (c_opt, m_opt) = cert(base), cert(opt)
    if progress is not None:
        progress(0.95)
    wins: dict[str, list[tuple[float, float]] | None] = {}
    rwins: dict[str, list[tuple[float, float]] | None] = {}
    if windows:
        for k, (a, b) in bounds.items():
            others = space.with_values({j: v for j, v in opt.items() if j != k})
            try:
                wins[k] = stable_windows(engine, others, k, (a, b))
            except ParameterError:  # no certified decisions on this model or over these bounds
                wins[k] = None
            try:
                rwins[k] = stable_windows(engine, others, k, (a, b), box=box) if box else None
            except ParameterError:
                rwins[k] = None
    if progress is not None:
        progress(1.0)
    H = np.concatenate(hist_x) if hist_x else np.zeros((0, len(names)))
    F = np.concatenate(hist_f) if hist_f else np.zeros(0)
    method = ("scipy.optimize.differential_evolution (seeded, Sobol' initial population, no polish) on "
              + ", ".join(f"{'log10 ' if scales[k] == 'log' else ''}{k}" for k in names)
              + (f"; P(squeal) over {n_draws} common draws, certified verdicts" if objective == "p_squeal" else
                 "; certified scale of the uncertainty box by branch and bound")
              + "; ties broken by the largest max Re lambda of the draws")
    return DesignResult(objective, bounds, scales, base, opt, {"baseline": p_base, "optimum": p_opt},
                        {"baseline": m_base, "optimum": m_opt}, {"baseline": c_base, "optimum": c_opt}, box, wins,
                        rwins, float(tolerance), float(confidence), n_draws, int(seed), int(F.size), int(res.nit),
                        str(res.message), H, F, method)
