"""Probability distributions of study inputs (``[distributions]`` of a study file), checked against the
parameters' allowed ranges.

Parameterisation (every number may be an expression string such as ``"pi/4"``):

============ ======================= ==========================================================
kind         values                  meaning
============ ======================= ==========================================================
uniform      ``[lo, hi]``            uniform on ``[lo, hi]``
normal       ``[mean, sd]``          normal; support ``(-inf, inf)``
truncnormal  ``[mean, sd, lo, hi]``  normal of ``mean``, ``sd`` truncated to ``[lo, hi]``
lognormal    ``[median, sigma]``     ``median * exp(sigma Z)``, ``Z`` standard normal (``sigma``
                                     is the standard deviation of ``ln X``); support ``(0, inf)``
beta         ``[a, b, lo, hi]``      beta of shapes ``a``, ``b`` scaled to ``[lo, hi]``
============ ======================= ==========================================================

A distribution's support must lie in the allowed range of the parameter it is given to
(:mod:`brakesqueal.model.roles`): ``normal`` on a friction coefficient (allowed ``[0, inf)``) is
refused, ``truncnormal`` with ``lo >= 0`` is not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..validation import validated

if TYPE_CHECKING:
    from ..model.parameters import ParameterSpace

__all__ = ["Distribution", "KINDS", "parse_distribution", "check_support"]

#: Distribution kinds and the names of their values, in order.
KINDS: dict[str, tuple[str, ...]] = {
    "uniform": ("lo", "hi"),
    "normal": ("mean", "sd"),
    "truncnormal": ("mean", "sd", "lo", "hi"),
    "lognormal": ("median", "sigma"),
    "beta": ("a", "b", "lo", "hi"),
}


@dataclass(frozen=True)
class Distribution:
    """The distribution of one input.

    Attributes
    ----------
    name : str
        The parameter it is given to.
    kind : str
        One of :data:`KINDS`.
    params : tuple of float
        Its values in the order of :data:`KINDS` (see the module docstring).
    """

    name: str
    kind: str
    params: tuple[float, ...]

    def frozen(self) -> Any:
        """The ``scipy.stats`` frozen distribution."""
        from scipy import stats

        p = self.params
        if self.kind == "uniform":
            return stats.uniform(loc=p[0], scale=p[1] - p[0])
        if self.kind == "normal":
            return stats.norm(loc=p[0], scale=p[1])
        if self.kind == "truncnormal":
            return stats.truncnorm((p[2] - p[0]) / p[1], (p[3] - p[0]) / p[1], loc=p[0], scale=p[1])
        if self.kind == "lognormal":
            return stats.lognorm(s=p[1], scale=p[0])
        return stats.beta(p[0], p[1], loc=p[2], scale=p[3] - p[2])

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Inverse CDF at probabilities ``u`` in (0, 1), clipped into the support (rounding)."""
        lo, hi, _, _ = self.support
        x = np.asarray(self.frozen().ppf(np.asarray(u, dtype=float)), dtype=float)
        return np.clip(x, lo, hi)

    @property
    def support(self) -> tuple[float, float, bool, bool]:
        """``(lo, hi, lo_open, hi_open)``: the values the distribution can take."""
        p = self.params
        if self.kind in ("uniform", "truncnormal", "beta"):
            lo, hi = (p[0], p[1]) if self.kind == "uniform" else (p[-2], p[-1])
            return lo, hi, False, False
        if self.kind == "lognormal":
            return 0.0, math.inf, True, True
        return -math.inf, math.inf, True, True

    def spec(self) -> dict[str, list[float]]:
        """The study-file form, ``{kind: [values]}`` (also what identifies it in a study's hash)."""
        return {self.kind: [float(x) for x in self.params]}

    def describe(self) -> str:
        """``"uniform(0.35, 0.55)"``."""
        return f"{self.kind}({', '.join(f'{x:g}' for x in self.params)})"


def _fmt_support(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


@validated
def parse_distribution(name: str, value: object, err: Callable[[str, str], ParameterError],
                       number: Callable[[object, str], float]) -> Distribution:
    """Read one ``[distributions]`` entry, ``NAME = { KIND = [values] }``.

    Parameters
    ----------
    name : str
        The parameter.
    value : object
        The entry's value (a one-key table).
    err : callable
        ``err(key, message) -> ParameterError`` naming the file and the key.
    number : callable
        ``number(value, key) -> float`` (numbers or expression strings).

    Returns
    -------
    Distribution
        Its values checked (``sd > 0``, ``lo < hi``, shapes > 0), not yet its support against the parameter's
        allowed range (:func:`check_support`).

    Raises
    ------
    ParameterError
        One line naming the key and what is allowed.
    """
    key = f"distributions.{name}"
    kinds = ", ".join(f"{k} = [{', '.join(v)}]" for k, v in KINDS.items())
    if not isinstance(value, dict) or len(value) != 1:
        raise err(key, f"must be a table with one distribution, e.g. {name} = {{ uniform = [0.35, 0.55] }}; "
                       f"allowed: {kinds}; got {value!r}")
    kind, vals = next(iter(value.items()))
    if kind not in KINDS:
        raise err(f"{key}.{kind}", f"unknown distribution {kind!r}; allowed: {kinds}")
    need = KINDS[kind]
    if not isinstance(vals, list) or len(vals) != len(need):
        raise err(f"{key}.{kind}", f"must be a list of {len(need)} numbers [{', '.join(need)}]; got {vals!r}")
    p = tuple(number(v, f"{key}.{kind}[{i}]") for i, v in enumerate(vals))
    d = dict(zip(need, p))
    form = f"{kind} = [{', '.join(need)}]"
    for pos in ("sd", "sigma", "a", "b"):
        if pos in d and not d[pos] > 0:
            raise err(f"{key}.{kind}", f"{form}: {pos} must be in (0, inf); got {d[pos]!r}")
    if "lo" in d and not d["hi"] > d["lo"]:
        raise err(f"{key}.{kind}", f"{form}: needs lo < hi; got lo = {d['lo']!r}, hi = {d['hi']!r}")
    if kind == "lognormal" and not d["median"] > 0:
        raise err(f"{key}.{kind}", f"{form}: median must be in (0, inf); got {d['median']!r}")
    if kind == "truncnormal":
        a, b = (d["lo"] - d["mean"]) / d["sd"], (d["hi"] - d["mean"]) / d["sd"]
        if a > 30 or b < -30:  # the truncation window holds no probability in double precision
            raise err(f"{key}.{kind}", f"{form}: [lo, hi] = [{d['lo']:g}, {d['hi']:g}] lies more than 30 sd from "
                                       f"the mean {d['mean']:g}; give a window that holds probability")
    return Distribution(name, kind, p)


@validated
def check_support(dist: Distribution, space: ParameterSpace, err: Callable[[str, str], ParameterError]) -> None:
    """Refuse a distribution that can take values outside its parameter's allowed range.

    Parameters
    ----------
    dist : Distribution
        The distribution.
    space : ParameterSpace
        The study's space (the parameter's roles give its allowed range).
    err : callable
        ``err(key, message) -> ParameterError``.

    Raises
    ------
    ParameterError
        ``study file 'F': key 'distributions.mu.normal': normal(0.45, 0.05) can take values in
        (-inf, inf), outside the allowed range [0, inf) of 'mu' ...``.
    """
    roles = space.model.roles()
    lo, hi, lo_open, hi_open = dist.support
    key = f"distributions.{dist.name}.{dist.kind}"
    hint = ("; use truncnormal = [mean, sd, lo, hi] or another bounded distribution"
            if dist.kind in ("normal", "lognormal") else "")
    where = f"{dist.describe()} can take values in {_fmt_support(lo, hi, lo_open, hi_open)}"
    for role, _owner in roles.uses.get(dist.name, ()):
        below = lo < role.low or (lo == role.low and role.low_open and not lo_open)
        above = hi > role.high or (hi == role.high and role.high_open and not hi_open)
        if below or above:
            raise err(key, f"{where}, outside the allowed range {roles.interval(dist.name)} of '{dist.name}'{hint}")
    # through the ties (a preset's own name such as mu, with mu1 = mu2 = mu): the extremes of the support, the
    # other parameters at their values (open ends just inside; infinite ends as the largest allowed magnitude)
    from ..model.roles import MAX_MAGNITUDE

    for x, is_open, p in ((lo, lo_open, 1e-15), (hi, hi_open, 1 - 1e-15)):
        if math.isinf(x):
            x = math.copysign(MAX_MAGNITUDE, x)
        elif is_open:
            x = float(dist.ppf(np.array([p]))[0])
        arrays = space.arrays({dist.name: np.array([x])})
        if not bool(np.all(space.valid(arrays))):
            try:
                space.resolve({dist.name: x})
                why = "invalid parameters"
            except ParameterError as exc:
                why = str(exc)
            raise err(key, f"{where}, outside the allowed range of '{dist.name}' (at {dist.name} = {x:g}: "
                           f"{why}){hint}")
