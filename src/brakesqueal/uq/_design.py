"""The Saltelli design of a study: matrices A, B and AB_i from one scrambled, seeded Sobol' sequence, mapped
through the inputs' inverse CDFs, as a sample study that the sweep runner computes (in memory or into a
resumable Zarr store)."""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..sweep import Study
from ..validation import validated

__all__ = ["SaltelliStudy", "saltelli_design", "design_study", "base_size"]


def base_size(n: int) -> int:
    """The base sample count ``N`` of a design: ``n`` rounded up to a power of two (at least 2)."""
    return max(2, 1 << max(0, math.ceil(math.log2(n))))


@validated
def saltelli_design(n: int, d: int, seed: int) -> np.ndarray:
    """Unit-cube Saltelli design: ``A``, ``B`` and the ``d`` matrices ``AB_i`` (Saltelli et al. 2010).

    ``A`` and ``B`` are the first and last ``d`` columns of one scrambled Sobol' sequence of dimension
    ``2 d`` (:class:`scipy.stats.qmc.Sobol`, seeded); ``AB_i`` is ``A`` with its column ``i`` from ``B``.

    Parameters
    ----------
    n : int
        Base sample count ``N`` (a power of two).
    d : int
        Number of inputs.
    seed : int
        Seed of the scrambling.

    Returns
    -------
    ndarray, shape (d + 2, N, d)
        The blocks in the order ``A, B, AB_1, ..., AB_d``, values in (0, 1).

    Raises
    ------
    ParameterError
        ``n`` is not a power of two, or ``d < 1``.
    """
    if n < 2 or n & (n - 1):
        raise ParameterError(f"saltelli_design(): n must be a power of two >= 2; got {n}")
    if d < 1:
        raise ParameterError(f"saltelli_design(): d must be >= 1; got {d}")
    from scipy.stats import qmc

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*balance properties.*")
        base = qmc.Sobol(d=2 * d, scramble=True, seed=np.random.default_rng(seed)).random_base2(int(math.log2(n)))
    a, b = base[:, :d], base[:, d:]
    out = np.empty((d + 2, n, d))
    out[0], out[1] = a, b
    for i in range(d):
        out[2 + i] = a
        out[2 + i, :, i] = b[:, i]
    return out


class SaltelliStudy(Study):
    """A sample study whose points are the Saltelli design of a study's distributions.

    The samples are the blocks ``A, B, AB_1, ..., AB_d`` (each of ``n_base`` points) one after the other;
    the hash adds the design to the study's, so a store of this design is resumed, never mixed with
    another one.
    """

    n_base: int

    def samples(self) -> dict[str, np.ndarray]:
        """The design's parameter values, block after block (computed once)."""
        if "_samples" in self.__dict__:
            return self.__dict__["_samples"]
        d = len(self.ranges)
        u = saltelli_design(self.n_base, d, self.seed).reshape(-1, d)
        out = {}
        for k, r in enumerate(self.ranges):
            assert r.distribution is not None
            out[r.name] = r.distribution.ppf(u[:, k])
        self.__dict__["_samples"] = out
        return out

    def canonical(self) -> dict[str, Any]:
        """The study's canonical form and the design (what the store's hash identifies)."""
        return {**super().canonical(), "uq_design": {"kind": "saltelli-sobol-scrambled", "n_base": self.n_base}}


def design_study(study: Study, quantities: tuple[str, ...]) -> SaltelliStudy:
    """The Saltelli design of ``study`` (its ``[distributions]``, ``[samples] n, seed``) as a sample study.

    Parameters
    ----------
    study : Study
        A sample study whose every sampled input has a distribution.
    quantities : tuple of str
        Quantities to compute at every point (besides ``stable`` and ``status``).

    Returns
    -------
    SaltelliStudy
        ``(d + 2) N`` samples, ``N = `` :func:`base_size` ``(n)``; chunks of at most ``N`` points (at most
        the study's chunk size), so a block of the design is never split over more chunks than needed.

    Raises
    ------
    ParameterError
        The study is a grid, or samples a parameter from a range instead of a distribution.
    """
    where = f"study file '{study.source}'"
    if study.kind != "samples" or not study.ranges:
        raise ParameterError(f"{where}: key 'distributions': uq needs [samples] (n, seed) and [distributions] "
                             "(e.g. mu = { uniform = [0.35, 0.55] })")
    plain = [r.name for r in study.ranges if r.distribution is None]
    if plain:
        raise ParameterError(f"{where}: key 'samples.ranges.{plain[0]}': uq draws its inputs from [distributions]; "
                             f"write {plain[0]} = {{ uniform = [{plain[0]} start, stop] }} there instead")
    n_base = base_size(study.n_samples)
    d = len(study.ranges)
    total = n_base * (d + 2)
    from ..sweep.study import MAX_CHUNKS, MAX_POINTS

    if total > MAX_POINTS:  # pragma: no cover - n is at most 1e7 in a study file
        raise ParameterError(f"{where}: key 'samples.n': {total} evaluations exceed {MAX_POINTS:.0e}")
    chunk = min(n_base, study.chunks[0])
    if -(-total // chunk) > MAX_CHUNKS:  # pragma: no cover - needs chunks of a few points
        chunk = -(-total // MAX_CHUNKS)
    fields = {f.name: getattr(study, f.name) for f in dataclasses.fields(Study)}
    from ..analysis.quantities import QUANTITIES

    quant = tuple(q for q in QUANTITIES if (q in quantities or q in study.quantities or q == "stable")
                  and q != "status")
    fields.update(n_samples=total, method="saltelli", chunks=(chunk,), quantities=quant)
    st = SaltelliStudy(**fields)
    object.__setattr__(st, "n_base", n_base)
    return st
