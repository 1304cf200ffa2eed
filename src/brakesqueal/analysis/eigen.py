r"""Eigen-analysis of a linear model ``M q'' + D q' + K q = 0`` (paper eq. 47).

* eigenvalues, frequencies [Hz], modal damping ratios, mode shapes;
* the splits ``D = D_s + G`` (symmetric damping + skew gyroscopic) and
  ``K = K_s + N`` (symmetric stiffness + skew circulatory);
* first-order sensitivities of every eigenvalue to every matrix entry,
  ``dλ/dX_jk = -λ^p conj(y_j) x_k / (y^H (2λM + D) x)`` (``p = 2, 1, 0`` for
  ``X = M, D, K``; ``x``, ``y`` right / left null vectors of ``λ²M + λD + K``),
  and, by the chain rule with central differences of the linearization, to
  every model parameter;
* a stability verdict with an explicit error bound: each eigenvalue of the
  state matrix ``A`` is accurate to about ``κ_i · ε · ‖A‖`` (``κ_i`` its
  condition number), and the verdict is ``"undecided"`` when the largest
  real part is within that bound of zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .linear import EXTENDED_MAX_SIZE, LinearModel, linearize

__all__ = ["EigenAnalysis", "eigen_analysis", "Verdict"]

_EPS = np.finfo(float).eps


@dataclass(frozen=True)
class Verdict:
    """Stability verdict with what carries it and how certain it is.

    Attributes
    ----------
    status : str
        ``"stable"``, ``"unstable"`` or ``"undecided"`` (not certifiable), the
        certified verdict of the one dispatcher (:func:`~.verdict.decide_model`).
    max_real : float
        Largest real part [1/s] of the judged eigenvalues.
    error_bound : float
        Error bound of ``max_real`` [1/s] where it is smaller than ``|max_real|`` (the bound of the route that
        certified the verdict through the eigenvalues, or the listed eigenvalue's own componentwise bound);
        NaN where no such bound is at hand: the verdict is then certified otherwise (``method``, e.g. an exact
        Routh-Hurwitz test), and no bound larger than the margin is ever reported.
    relative_margin : float
        ``max_real / |λ|`` of the least-stable eigenvalue.
    carrier : str or None
        The mode carrying the verdict: ``"disk"``, ``"pad <name>"``, ``"caliper <name>"`` or
        ``"pad <name> tangential rate"`` (a non-oscillatory mode of a massless pad alone).
    method : str
        The route that decided (:data:`~.verdict.ROUTES`).
    frequency : float
        Frequency of the least-stable judged eigenvalue [Hz].
    pad_damping : float or None
        For a verdict carried by a massless pad's tangential rate: that pad's effective tangential damping
        ``G_dL`` [N s/m] (normalised to a positive stiffness; negative: the pad's own mode grows).
    disk : Verdict or None
        The verdict of the disk's modes alone when the verdict is carried by a pad's tangential rate.
    listed : float
        The largest real part of the listed eigenvalues (those of the matrices in double precision); it can
        differ in sign from a verdict decided exactly on the parameters where rounding the matrices' entries
        moves the roots (entries spanning ~1e50); see :attr:`listed_resolved`.
    listed_bound : float
        The listed eigenvalue's error bound.
    """

    status: str
    max_real: float
    error_bound: float
    relative_margin: float
    carrier: str | None = None
    method: str = "none"
    frequency: float = math.nan
    pad_damping: float | None = None
    disk: Verdict | None = None
    listed: float = math.nan
    listed_bound: float = math.nan

    @property
    def listed_resolved(self) -> bool:
        """Whether the listed eigenvalues agree with the verdict (or their largest real part is resolved)."""
        if self.status == "undecided" or not math.isfinite(self.listed):
            return True
        return (self.listed < 0) == (self.status == "stable") or not abs(self.listed) <= self.listed_bound

    @property
    def stable(self) -> bool:
        """True only for a decided ``"stable"``."""
        return self.status == "stable"

    @property
    def pad_mode(self) -> bool:
        """Whether the verdict is carried by a massless pad's own tangential-rate mode."""
        return bool(self.carrier and self.carrier.endswith("tangential rate"))


@dataclass(frozen=True)
class EigenAnalysis:
    """Eigenvalues, modes, splits and sensitivities of a linear model.

    Attributes
    ----------
    model : LinearModel
        The analysed model.
    eigenvalues : ndarray (2n,)
        Sorted by decreasing real part [1/s].
    modes : ndarray (n, 2n)
        Mode shapes (columns; displacement part, unit 2-norm, largest entry real positive).
    left : ndarray (n, 2n)
        Left null vectors ``y`` of ``λ²M + λD + K``.
    condition : ndarray (2n,)
        Eigenvalue condition numbers of the state matrix.
    """

    model: LinearModel
    eigenvalues: np.ndarray
    modes: np.ndarray
    left: np.ndarray
    condition: np.ndarray
    _cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def __repr__(self) -> str:
        v = self.verdict()
        return (f"EigenAnalysis(model={self.model.model.name!r}, n={self.model.n}, "
                f"eigenvalues={self.eigenvalues.size}, verdict={v.status!r}, max_real={v.max_real:.6g})")

    def _repr_html_(self) -> str:
        """The linear model's HTML summary (verdict, carrier, least stable eigenvalues), for notebooks."""
        return self.model._repr_html_()

    # -------------------------------------------------------------- basic quantities
    @property
    def frequencies(self) -> np.ndarray:
        """``|Im λ| / 2π`` [Hz]."""
        return np.abs(self.eigenvalues.imag) / (2 * math.pi)

    @property
    def damping_ratios(self) -> np.ndarray:
        """Modal damping ratios ``-Re λ / |λ|`` (negative: growing mode)."""
        return -self.eigenvalues.real / np.abs(self.eigenvalues)

    @property
    def max_real(self) -> float:
        """Largest real part [1/s]."""
        return float(self.eigenvalues.real.max())

    def split(self) -> dict[str, np.ndarray]:
        """``{"D_s", "G", "K_s", "N"}``: symmetric / skew parts of ``Dbar`` and ``Kbar``."""
        D, K = self.model.D, self.model.K
        return {"D_s": (D + D.T) / 2, "G": (D - D.T) / 2, "K_s": (K + K.T) / 2, "N": (K - K.T) / 2}

    def verdict(self, safety: float = 100.0, modes: str = "all") -> Verdict:
        """Stability verdict: the certified one of the one dispatcher (:func:`~.verdict.decide_model`).

        ``status``, ``carrier`` and ``method`` come from the dispatcher, the same as maps, sweeps and the command
        line report.  ``max_real`` is that of the listed eigenvalues (extended precision up to
        :data:`~.robust.EXTENDED_VERDICT_MAX_SIZE`); where they contradict the certified verdict by more than
        the listed eigenvalue's bound the status is ``"undecided"`` (within it, at a point on the boundary to
        rounding, the certified verdict and its ``max_real`` stand).  ``error_bound`` is reported only where
        it is smaller than ``|max_real|`` (see :class:`Verdict`).  A verdict carried by a massless pad's
        tangential rate also gives the pad's effective damping and the disk modes' own verdict.

        Parameters
        ----------
        safety : float
            Factor of the first-order estimate ``safety · κ · ε · ‖A‖`` used above the extended-precision size.
        modes : {"all", "disk"}
            Judge every eigenvalue, or only the disk's (a massless pad's own tangential-rate mode left out).
        """
        from .robust import EXTENDED_VERDICT_MAX_SIZE, STABLE, UNSTABLE, extended_eigen
        from .verdict import decide_model

        lm = self.model
        v = decide_model(lm, modes=modes)
        code, mr = int(v.code[0]), float(v.max_real[0])
        route_bound, freq = float(v.bound[0]), float(v.frequency[0])
        carrier, method = v.carrier_name(0), v.method_name(0)
        i = int(np.argmax(self.eigenvalues.real))
        E, A = lm.descriptor
        if E.shape[0] <= EXTENDED_VERDICT_MAX_SIZE:
            # componentwise bound of the extended-precision route: the norm-wise one below is dominated by the
            # largest modes (pads' own modes up to 1e25 at tilted silent motions) and says little of the slow ones
            ext = extended_eigen(E, A, len(lm.pad_states))
            listed_bound = math.inf if ext is None or not ext[0].size else float(ext[1][int(np.argmax(ext[0].real))])
        else:
            listed_bound = safety * float(self.condition[i]) * _EPS * float(np.linalg.norm(lm.A, 2))
        status = "stable" if code == STABLE else "unstable" if code == UNSTABLE else "undecided"
        listed = float(self.eigenvalues[i].real)
        exact = lm.pad_states or 2 * lm.n <= EXTENDED_MAX_SIZE  # listed in extended precision
        bound = route_bound
        if modes == "all":
            if (code == STABLE and not listed < 0) or (code == UNSTABLE and not listed > 0):
                if not (exact and abs(listed) <= listed_bound):
                    # the listed eigenvalues and the route disagree beyond the listed one's bound: neither is certain
                    status, mr, bound = "undecided", listed, listed_bound
                # else: a point on the boundary to rounding, the float matrices' eigenvalue within its bound of
                # 0; the verdict (and its max Re) of the exact route on the parameters stands
            elif exact:
                mr, freq = listed, float(abs(self.eigenvalues[i].imag) / (2 * math.pi))
                bound = listed_bound  # the listed eigenvalue's own bound
        if status != "undecided" and not (math.isfinite(bound) and bound < abs(mr)):
            bound = math.nan  # certified otherwise (the route): no bound larger than the margin is reported
        lam = self.eigenvalues[i] if modes == "all" else complex(mr, 2 * math.pi * freq)
        margin = mr / abs(lam) if abs(lam) > 0 else math.nan
        pad_damping = disk = None
        if carrier is not None and carrier.endswith("tangential rate") and modes == "all":
            pad_damping = self._pad_damping(carrier)
            disk = self.verdict(safety, modes="disk")
        return Verdict(status, mr, bound, margin, carrier, method, freq, pad_damping, disk, listed, listed_bound)

    def _pad_damping(self, carrier: str) -> float | None:
        """The effective tangential damping ``G_dL`` [N s/m] of the pad named in a carrier label."""
        lm = self.model
        pad = carrier.removeprefix("pad ").removesuffix(" tangential rate")
        names = [p.name for p in lm.model.pads]
        if pad not in names or lm.G_dL is None or lm.G_L is None:
            return None
        from ..model.components import state_name

        state = state_name("l", pad)
        if state not in lm.pad_states:
            return None
        j = list(lm.pad_states).index(state)
        spec_pad = lm.model.pads[names.index(pad)]
        k_ip = lm.params[spec_pad.k_ip] if isinstance(spec_pad.k_ip, str) else float(spec_pad.k_ip)
        g_l = float(lm.G_L[j, j])
        if g_l == 0 or not math.isfinite(k_ip):
            return None
        # the pad's own balance G_L l + G_dL ldot + ... = 0 has the time constant G_dL / G_L; times the pad's
        # tangential stiffness it is the damping of a spring-damper with that time constant [N s/m]
        return float(lm.G_dL[j, j]) / g_l * float(k_ip)

    # -------------------------------------------------------------- sensitivities
    def entry_sensitivities(self) -> dict[str, np.ndarray]:
        """``{"M", "D", "K"}`` → complex array ``(2n, n, n)``: ``dλ_i / dX_jk``."""
        if "entry" not in self._cache:
            M, D = self.model.M, self.model.D
            out = {k: np.zeros((self.eigenvalues.size, *M.shape), dtype=complex) for k in "MDK"}
            for i, lam in enumerate(self.eigenvalues):
                x, y = self.modes[:, i], self.left[:, i]
                den = np.conj(y) @ (2 * lam * M + D) @ x
                outer = np.outer(np.conj(y), x) / den
                out["M"][i], out["D"][i], out["K"][i] = -lam ** 2 * outer, -lam * outer, -outer
            self._cache["entry"] = out
        return self._cache["entry"]

    def matrix_derivatives(self, rel_step: float = 1e-6) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """``d(M, D, K)/d ln p`` for every parameter of the model (central differences of the linearization).

        Parameters at ``inf`` (rigid pads) and zero-valued ones give zero
        matrices (a logarithmic derivative does not exist there), as do
        parameters whose perturbation leaves the allowed range.
        """
        if "dmat" not in self._cache:
            from ..errors import BrakesquealError

            p0 = self.model.params
            rates = self.model.pad_rates
            out = {}
            for name in p0.names:
                v = p0[name]
                z = np.zeros_like(self.model.M)
                if not math.isfinite(v) or v == 0.0:
                    out[name] = (z, z, z)
                    continue
                hp, hm = v * math.exp(rel_step), v * math.exp(-rel_step)
                try:
                    lp = linearize(self.model.engine, p0.replace(**{name: hp}), pad_rates=rates)
                    lm = linearize(self.model.engine, p0.replace(**{name: hm}), pad_rates=rates)
                except BrakesquealError:
                    out[name] = (z, z, z)
                    continue
                out[name] = tuple((getattr(lp, k) - getattr(lm, k)) / (2 * rel_step) for k in "MDK")  # type: ignore[assignment]
            self._cache["dmat"] = out
        return self._cache["dmat"]

    def parameter_sensitivities(self) -> dict[str, np.ndarray]:
        """``{name: dλ_i / d ln p}`` (complex, one entry per eigenvalue) for every parameter of the model.

        For a descriptor model (pads with first-order dynamics) the
        eigenvalues of the perturbed linearizations are differenced directly
        (each matched to the nearest unperturbed one).
        """
        if self.model.pad_states:
            return self._direct_sensitivities()
        # dλ_i = -y_i^H (λ_i² dM + λ_i dD + dK) x_i / y_i^H (2 λ_i M + D) x_i: the sum over the entries of
        # entry_sensitivities, without its (2n, n, n) arrays (a 1000-DOF model would need 48 GB for them)
        lam, X, Y = self.eigenvalues, self.modes, self.left
        M, D = self.model.M, self.model.D
        den = np.einsum("ji,ji->i", np.conj(Y), 2 * lam * (M @ X) + D @ X)
        out = {}
        for name, (dM, dD, dK) in self.matrix_derivatives().items():
            num = np.einsum("ji,ji->i", np.conj(Y), lam ** 2 * (dM @ X) + lam * (dD @ X) + dK @ X)
            out[name] = -num / den
        return out

    def _direct_sensitivities(self, rel_step: float = 1e-6) -> dict[str, np.ndarray]:
        from ..errors import BrakesquealError

        p0, lam0 = self.model.params, self.eigenvalues
        out = {}
        for name in p0.names:
            v = p0[name]
            if not math.isfinite(v) or v == 0.0:
                out[name] = np.zeros(lam0.size, dtype=complex)
                continue
            try:
                lp = linearize(self.model.engine, p0.replace(**{name: v * math.exp(rel_step)})).eigenvalues
                lm = linearize(self.model.engine, p0.replace(**{name: v * math.exp(-rel_step)})).eigenvalues
            except BrakesquealError:
                out[name] = np.zeros(lam0.size, dtype=complex)
                continue
            near = lambda lam, z: lam[np.argmin(np.abs(lam - z))]  # noqa: E731
            out[name] = np.array([(near(lp, z) - near(lm, z)) / (2 * rel_step) for z in lam0])
        return out

    def contributions(self, name: str, mode: int = 0) -> dict[str, float]:
        """Contribution of each matrix entry to ``d Re λ_mode / d ln name`` (keys like ``"D11"``)."""
        es, dm = self.entry_sensitivities(), self.matrix_derivatives()[name]
        out = {}
        for k, d in zip("MDK", dm):
            for j in range(d.shape[0]):
                for l in range(d.shape[1]):
                    out[f"{k}{j + 1}{l + 1}"] = float((es[k][mode, j, l] * d[j, l]).real)
        return out

    # -------------------------------------------------------------- output
    def to_xarray(self) -> Any:
        """Dataset over ``mode``: eigenvalue parts, frequency, damping ratio, condition, mode shapes."""
        import xarray as xr

        n = self.modes.shape[0]
        return xr.Dataset(
            {"real": ("mode", self.eigenvalues.real, {"units": "1/s"}),
             "imag": ("mode", self.eigenvalues.imag, {"units": "1/s"}),
             "frequency": ("mode", self.frequencies, {"units": "Hz"}),
             "damping_ratio": ("mode", self.damping_ratios),
             "condition": ("mode", self.condition),
             "shape_real": (("dof", "mode"), self.modes.real), "shape_imag": (("dof", "mode"), self.modes.imag)},
            coords={"mode": np.arange(self.eigenvalues.size), "dof": list(self.model.coords)[:n]},
            attrs={"verdict": self.verdict().status})

    def plot(self, ax: Any = None) -> Any:
        """Eigenvalues in the complex plane; returns the figure."""
        from ..plotting import new_figure

        fig, ax = new_figure(ax)
        lam = self.eigenvalues
        ax.plot(lam.real, lam.imag / (2 * math.pi), "o")
        ax.axvline(0, color="0.5", lw=0.8)
        ax.set_xscale("symlog", linthresh=1e-2)
        ax.set_xlabel("Re λ [1/s]")
        ax.set_ylabel("Im λ / 2π [Hz]")
        ax.set_title(f"eigenvalues ({self.verdict().status})")
        return fig


def _null_vectors(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    U, _, Vh = np.linalg.svd(Q)
    return Vh[-1].conj(), U[:, -1]


def _eig_left_right(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalues, left and right eigenvectors (columns) of ``A``: NumPy's ``eig``, the left ones from ``V^-1``.

    The rows of ``V^-1`` are left eigenvectors paired with the columns of ``V`` (``y_i^H x_i = 1``); this keeps
    SciPy (about 0.15 s of imports) off the command line's ``linearize``.  A singular ``V`` (a defective
    matrix) falls back to LAPACK's left eigenvectors through :func:`scipy.linalg.eig`.
    """
    w, vr = np.linalg.eig(A)
    try:
        vl = np.linalg.inv(vr).conj().T
    except np.linalg.LinAlgError:
        vl = None
    if vl is None or not np.all(np.isfinite(vl)):
        import scipy.linalg

        w, vl, vr = scipy.linalg.eig(A, left=True, right=True)
    return w, vl, vr


def eigen_analysis(model: Any, engine: Any = None) -> EigenAnalysis:
    """Eigen-analysis of a linear model (or of ``linearize(params)``), for any model.

    The eigenvalues are those of the first-order state matrix of eq. (47)
    (including the pads kept as first-order states), computed with
    :func:`numpy.linalg.eig`; the left eigenvectors are the rows of the inverse
    of the right ones (LAPACK's own for a defective matrix).

    Parameters
    ----------
    model : LinearModel or Parameters
        A linear model (eq. 48), or a parameter set that is first linearized
        about its silent motion with :func:`~brakesqueal.analysis.linear.linearize`.
    engine : Engine, optional
        The model's engine (needed for a parameter set).

    Returns
    -------
    EigenAnalysis
        The eigenvalues [1/s] sorted by decreasing real part, then
        decreasing imaginary part; mode shapes ``(n, N)`` (the displacement
        part of the right eigenvectors, unit 2-norm, largest entry real
        positive); left eigenvectors' displacement parts; and the eigenvalue
        condition numbers of the state matrix.

    Raises
    ------
    SilentMotionError
        If ``model`` is a parameter set without a usable silent motion.
    """
    if isinstance(model, LinearModel):
        lm = model
    else:
        if engine is None:
            raise TypeError("eigen_analysis of a parameter set needs its model's engine")
        lm = linearize(engine, model)
    A = lm.A
    w, vl, vr = _eig_left_right(A)
    order = np.lexsort((-w.imag, -w.real))
    w, vl, vr = w[order], vl[:, order], vr[:, order]
    matrices = lm.silent.method == "matrices"  # a model given by coefficient matrices (often many DOF)
    if (lm.pad_states or matrices or 2 * lm.n <= EXTENDED_MAX_SIZE) and lm.eigenvalues.size == w.size:
        # the eigenvalues themselves from the linear model (extended precision: double-precision E^-1 A moves the
        # structural modes' real parts by percents beside 1e15 pad modes), each with the vectors of its nearest
        # double-precision eigenvalue, so `eigen` lists what `linearize` lists
        acc = lm.eigenvalues
        free = list(range(w.size))
        pick = []
        for z in acc:
            j = min(free, key=lambda i: abs(w[i] - z) / max(abs(z), 1e-300))
            free.remove(j)
            pick.append(j)
        w, vl, vr = acc.copy(), vl[:, pick], vr[:, pick]
    with np.errstate(divide="ignore", invalid="ignore"):  # a defective eigenvalue: infinite condition
        cond = np.array([np.linalg.norm(vl[:, i]) * np.linalg.norm(vr[:, i]) / abs(np.vdot(vl[:, i], vr[:, i]))
                         for i in range(w.size)])
    n = lm.n
    modes = np.zeros((n, w.size), dtype=complex)
    left = np.zeros((n, w.size), dtype=complex)
    if matrices:  # the state matrix's vectors: x its displacement part, y = M^-H w2 from its left vector w
        Y = np.linalg.solve(lm.M.conj().T, vl[n:2 * n, :])
    for i, lam in enumerate(w):
        if matrices:
            x, y = vr[:n, i] + 0.0, Y[:, i]
        elif not lm.pad_states:
            x, y = _null_vectors(lam ** 2 * lm.M + lam * lm.D + lm.K)
        else:
            x, y = vr[:n, i], vl[n:2 * n, i].conj()
            if np.linalg.norm(x) == 0:
                x = vr[:n, i] + 0.0
        k = int(np.argmax(np.abs(x)))
        if abs(x[k]) > 0:
            x = x * (abs(x[k]) / x[k]) / np.linalg.norm(x)
        modes[:, i], left[:, i] = x, y
    return EigenAnalysis(lm, w, modes, left, cond)
