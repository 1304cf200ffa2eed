"""Polynomial chaos surrogates of a study's quantity: a small QMC design of the study's ``[distributions]``,
evaluated by the sweep evaluator, fitted by :func:`~brakesqueal.uq.fit_pce`."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

import numpy as np

from ..errors import ParameterError
from ..status import DECIDED
from ..sweep import Study, load_study
from ..validation import validated
from ._distributions import Distribution
from ._surrogate import PCESurrogate, fit_pce

__all__ = ["pce_design", "StudySurrogate", "fit_study_pce", "SURROGATE_QUANTITIES"]

#: Quantities a study surrogate can be fitted to (real-valued, smooth where the leading mode does not change): of the
#: sweep evaluator, max Re λ [1/s] and the damping ratio ``margin`` (P(squeal) is read from their sign); and, at the
#: squeal onset along the spin rate (the first destabilising crossing in ``ONSET_RANGE``), the expensive nonlinear
#: ones: ``onset_l1``, the first Lyapunov coefficient with the pads' true rates (its sign: sub- or supercritical,
#: read as P(subcritical onset)), and ``onset_amplitude``, the growth coefficient ``a`` of the limit cycles' tilt
#: amplitude ``a sqrt(|Omega - Omega_crit|)`` (the norm over the model's coordinates).
SURROGATE_QUANTITIES = ("max_real", "margin", "onset_l1", "onset_amplitude")
#: The spin-rate range [rad/s] searched for the onset of the ``onset_*`` quantities.
ONSET_RANGE = (1.0, 1e5)


@validated
def pce_design(distributions: Sequence[Distribution], n: int, seed: int = 0) -> dict[str, np.ndarray]:
    """``n`` runs of a scrambled, seeded Sobol' sequence mapped through the inputs' inverse CDFs.

    Parameters
    ----------
    distributions : sequence of Distribution
        The inputs.
    n : int
        Runs, in ``[2, 2**20]`` (a power of two keeps the sequence balanced).
    seed : int
        Seed of the scrambling.

    Returns
    -------
    dict
        ``{name: values}`` in physical units.
    """
    if not 2 <= n <= 1 << 20:
        raise ParameterError(f"pce_design(): n must be in [2, {1 << 20}]; got {n}")
    if not distributions:
        raise ParameterError("pce_design(): distributions must name at least one input")
    from scipy.stats import qmc

    sob = qmc.Sobol(d=len(distributions), scramble=True, seed=np.random.default_rng(seed))
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*balance properties.*")
        u = sob.random_base2(int(math.log2(n))) if n & (n - 1) == 0 else sob.random(n)
    return {d.name: d.ppf(u[:, i]) for i, d in enumerate(distributions)}


@dataclass(frozen=True)
class StudySurrogate:
    """A surrogate of one quantity of a study.

    Attributes
    ----------
    surrogate : PCESurrogate
        The expansion (indices: ``surrogate.first``, ``surrogate.total``; error: ``surrogate.loo_error``).
    quantity : str
        The quantity fitted (:data:`SURROGATE_QUANTITIES`).
    runs : int
        Design points evaluated.
    left_out : int
        Of them, points without a verdict or a finite value (never fitted).
    p_squeal : float
        ``P(max Re λ > 0)`` (``P(margin <= 0)``) from ``samples`` evaluations of the surrogate; for ``onset_l1``
        the probability of a subcritical onset ``P(l1 > 0)``; NaN for ``onset_amplitude``.
    samples : int
        Evaluations of the surrogate behind ``p_squeal``.
    """

    surrogate: PCESurrogate
    quantity: str
    runs: int
    left_out: int
    p_squeal: float
    samples: int

    def summary(self) -> dict[str, Any]:
        """JSON form (:meth:`PCESurrogate.summary` with the study's counts and ``p_squeal``; for ``onset_l1``
        ``p_subcritical`` instead)."""
        key = "p_subcritical" if self.quantity == "onset_l1" else "p_squeal"
        p = None if not math.isfinite(self.p_squeal) else self.p_squeal
        return {"quantity": self.quantity, **self.surrogate.summary(), "design_runs": self.runs,
                "left_out": self.left_out, key: p, f"{key}_samples": self.samples}


def _onset_values(space: Any, values: Mapping[str, np.ndarray], quantity: str) -> np.ndarray:
    """``onset_l1`` or ``onset_amplitude`` at every design point (NaN: no onset in :data:`ONSET_RANGE`, an
    undecided search, or no normal form there)."""
    from ..analysis.crossings import critical_speeds_many, omega_name
    from ..errors import BrakesquealError
    from ..nonlinear.implicit import exact_lyapunov
    from ..status import PointStatus
    from ..sweep.compute import engine_of

    engine = engine_of(space).require_nonlinear(f"the surrogate quantity {quantity!r}")
    spin = omega_name(space)
    lo, hi = ONSET_RANGE
    at = {k: np.asarray(v, dtype=float) for k, v in values.items() if k != spin}
    roots, dirs, counts, _, cst = critical_speeds_many(engine, space, at, lo, hi, return_status=True)
    k = np.arange(roots.shape[1])
    onset = (dirs == -1) & (k[None, :] < counts[:, None])
    out = np.full(roots.shape[0], np.nan)
    n = engine.caps.n
    for i in np.flatnonzero(onset.any(axis=1) & (cst == int(PointStatus.OK))):
        w = float(roots[i, int(np.argmax(onset[i]))])
        sp = space.with_values({name: float(v[i]) for name, v in at.items()})
        try:
            h = exact_lyapunov(engine, sp, spin, w).hopf
        except (BrakesquealError, np.linalg.LinAlgError, ValueError):
            continue
        out[i] = float(h.l1) if quantity == "onset_l1" else float(np.linalg.norm(h.amplitude_coefficients[:n]))
    return out


@validated
def fit_study_pce(study: Union[Study, str, Path, Mapping[str, Any]], *, runs: int = 256, degree: int = 4,
                  sparse: bool = False, q: float = 1.0, quantity: str = "max_real", seed: int | None = None,
                  samples: int = 1 << 20) -> StudySurrogate:
    """Polynomial chaos surrogate of a study's quantity from a few hundred runs.

    The runs are :func:`pce_design` of the study's ``[distributions]`` (seeded by ``[samples] seed`` unless
    ``seed`` is given), evaluated by the sweep evaluator (certified verdicts); points without a verdict or a
    finite value are left out (counted in ``left_out``).

    Parameters
    ----------
    study : Study, str, Path or dict
        A study file with ``[distributions]`` and ``[samples]`` (its ``n`` is not used: ``runs`` is).
    runs : int
        Design points, in ``[10, 65536]``.
    degree, sparse, q
        As :func:`~brakesqueal.uq.fit_pce`.
    quantity : str
        One of :data:`SURROGATE_QUANTITIES`.
    seed : int, optional
        Seed of the design (default: the study's).
    samples : int
        Surrogate evaluations behind ``p_squeal``.

    Returns
    -------
    StudySurrogate

    Raises
    ------
    ParameterError
        A bad study, quantity or option (one line naming it), too few runs with a verdict for the basis.
    """
    if quantity not in SURROGATE_QUANTITIES:
        raise ParameterError(f"fit_study_pce(): quantity must be one of {', '.join(SURROGATE_QUANTITIES)}; "
                             f"got {quantity!r}")
    if not 10 <= runs <= 1 << 16:
        raise ParameterError(f"fit_study_pce(): runs must be in [10, {1 << 16}]; got {runs}")
    st = load_study(study)
    if st.kind != "samples" or not st.ranges or any(r.distribution is None for r in st.ranges):
        raise ParameterError(f"study file '{st.source}': key 'distributions': a surrogate needs [samples] and every "
                             "sampled input in [distributions] (e.g. mu = { uniform = [0.35, 0.55] })")
    dists = [r.distribution for r in st.ranges if r.distribution is not None]
    values = pce_design(dists, runs, st.seed if seed is None else seed)
    import dataclasses

    from ..sweep.compute import ChunkSpec, compute_chunk

    quants = tuple(dict.fromkeys((*st.quantities, quantity, "stable")))
    spec = ChunkSpec.from_study(dataclasses.replace(st, quantities=quants))
    space = st.space()
    valid = np.asarray(space.valid(space.arrays(values)), dtype=bool).reshape(-1)
    if not valid.all():
        j = int(np.flatnonzero(~valid)[0])
        raise ParameterError(f"study file '{st.source}': key 'distributions': design points give parameters outside "
                             "their allowed ranges (through the ties), e.g. "
                             + ", ".join(f"{k} = {v[j]:.6g}" for k, v in values.items()))
    if quantity.startswith("onset_"):
        y = _onset_values(space, values, quantity)
        ok = np.isfinite(y)
    else:
        res = compute_chunk(spec, values)
        y = np.asarray(res[quantity], dtype=float)
        ok = np.isin(np.asarray(res["status"]), [int(s) for s in DECIDED]) & np.isfinite(y)
    fit = fit_pce({k: v[ok] for k, v in values.items()}, y[ok], dists, degree=degree, sparse=sparse, q=q)
    if quantity == "onset_amplitude":
        p = math.nan
    else:
        above = fit.probability(0.0, n=samples, seed=st.seed)
        p = 1.0 - above if quantity == "margin" else above  # margin = -Re λ / |λ| <= 0: squeal; l1 > 0: subcritical
    return StudySurrogate(fit, quantity, runs, int((~ok).sum()), p, samples)
