r"""Route ``eigen-bounds``: every eigenvalue of the linear system with a first-order error bound.

Applies to every linear system (:mod:`._linear`; any size, pads kept as
first-order states included).  The state matrix — the balanced ``2n × 2n``
matrix of eq. (47), or ``E^-1 A`` of a descriptor system — is balanced by
powers of two and its eigenvalues computed with their condition numbers
``κ``; each eigenvalue's error is bounded by ``10 κ (INPUT_REL + 4 m u)
‖B‖_F`` (:func:`~..robust.state_analysis`).  The verdict is certified when
every bound keeps its eigenvalue on one side of the imaginary axis.  Each
eigenvalue is attributed to the component holding the largest share of its
balanced eigenvector (the carrier); with ``modes="disk"`` the modes carried
by a massless pad's own tangential rate are left out of the verdict.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..robust import state_analysis
from ._base import Context, LinearGroup, Result, Route
from ._linear import linear_groups

__all__ = ["EigenBounds", "state_labels"]


def state_labels(ctx: Context, g: LinearGroup) -> np.ndarray:
    """The carrier label of every state of a group's systems (coordinates, their rates, kept pad states)."""
    n = g.n
    coord = ctx.coord_label if ctx.coord_label.size == n else np.zeros(n, dtype=np.int64)
    size = g.descriptor()[0].shape[-1] if g.E is not None else 2 * n
    k = size - 2 * n
    pads = ctx.pad_label[g.states[:k]] if ctx.pad_label.size and g.states.size >= k else np.zeros(k, np.int64)
    return np.concatenate([coord, coord, pads]).astype(np.int64)


def excluded(ctx: Context) -> np.ndarray | None:
    """Labels left out of the verdict: the massless pads' tangential rates with ``modes="disk"``."""
    if ctx.modes != "disk" or not ctx.pad_label.size:
        return None
    return np.unique(ctx.pad_label)


#: A verdict of one system from its pencil ``(E, A)``, its count ``k`` of pad states, its states' carrier labels
#: and the labels left out: ``(code, max_real, frequency, bound, carrier)``.
PencilVerdict = Callable[[np.ndarray, np.ndarray, int, np.ndarray, "np.ndarray | None"],
                         tuple[int, float, float, float, int]]


def pencil_route(ctx: Context, idx: np.ndarray, max_size: int, verdict: PencilVerdict) -> Result:
    """A route's result deciding each point's pencil ``A - λE`` alone (the systems of at most ``max_size`` states;
    the larger ones left undecided): the per-point routes :mod:`.extended` and :mod:`.pencil_refined`."""
    res = Result.empty(idx.size)
    pos = {int(i): j for j, i in enumerate(idx)}
    skip = excluded(ctx)
    for g in linear_groups(ctx, idx):
        E, A = g.descriptor()
        if E.shape[-1] > max_size:
            continue
        k = E.shape[-1] - 2 * g.n
        labels = state_labels(ctx, g)
        for q, i in enumerate(g.idx):
            code, mr, fr, bd, car = verdict(E[q], A[q], k, labels, skip)
            j = pos[int(i)]
            res.code[j], res.max_real[j], res.frequency[j], res.bound[j], res.carrier[j] = code, mr, fr, bd, car
    return res


class EigenBounds(Route):
    """See the module docstring."""

    name = "eigen-bounds"
    description = "eigenvalues of the linearization with first-order condition-number error bounds"

    def applies(self, ctx: Context) -> bool:
        return True

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        res = Result.empty(idx.size)
        pos = {int(i): j for j, i in enumerate(idx)}
        for g in linear_groups(ctx, idx):
            S, good = g.states_matrices()
            sel = np.flatnonzero(good)
            if sel.size == 0:
                continue
            code, mr, fr, bd, car = state_analysis(S[sel], state_labels(ctx, g), excluded(ctx))
            at = np.array([pos[int(i)] for i in g.idx[sel]], dtype=np.int64)
            res.code[at], res.max_real[at], res.frequency[at], res.bound[at], res.carrier[at] = code, mr, fr, bd, car
        return res
