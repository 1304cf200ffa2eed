r"""The engine of a model given by coefficient matrices (:class:`~brakesqueal.model.matrices.MatrixSpec`).

Nothing is derived or generated: the linear system at a parameter point is
the combination of the model's matrices (``λ² M + λ D + K``, every term's
factor evaluated on the parameters), and the silent motion is ``x = 0``
everywhere.  The engine states this in its capabilities (``kind =
"matrices"``, no pad deformations, no closed form) so that the verdict
dispatcher's linear routes apply unchanged, and refuses the generated
artefacts of component models (simulation kernels, silent-motion kernels,
closed forms) with a one-line error.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .engine import Capabilities, Engine

if TYPE_CHECKING:
    from ..model.matrices import MatrixSpec
    from ..model.parameters import ParameterSpace

__all__ = ["MatrixEngine", "build_matrix_engine", "MAX_DENSE_DOF"]

#: Largest matrix model analysed with dense eigenvalues (``2n`` states: about 10 s per point at this size on
#: one core; a 4669-DOF model's dense QZ takes tens of minutes).  Larger models: the sparse box route or a
#: reduced model.
MAX_DENSE_DOF = 1500



@dataclass(frozen=True, eq=False)
class MatrixEngine(Engine):
    """The engine of a matrix model: ``caps.kind == "matrices"``; :meth:`linear_batch` gives its systems."""

    @property
    def matrix_spec(self) -> MatrixSpec:
        """The model."""
        return cast("MatrixSpec", self.spec)

    def __repr__(self) -> str:
        return f"MatrixEngine(model={self.spec.name!r}, key={self.key!r}, n={self.caps.n})"

    def require_dense(self, what: str) -> None:
        """A one-line refusal where the model is too large for dense eigenvalues (:data:`MAX_DENSE_DOF`)."""
        if self.caps.n > MAX_DENSE_DOF:
            from ..errors import ParameterError

            raise ParameterError(f"{what}: model '{self.spec.name}' has {self.caps.n} DOF; dense eigenvalues are "
                                 f"limited to {MAX_DENSE_DOF} DOF (a {self.caps.n}-DOF dense QZ takes minutes per "
                                 "point): reduce the model, or use the sparse box analysis of a frequency band")

    def linear_batch(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Dense ``M, D, K`` of shape ``(N, n, n)`` at parameter rows ``P`` (packing order, shape ``(N, p)``)."""
        self.require_dense("stability verdicts")
        spec = self.matrix_spec
        P = np.atleast_2d(np.asarray(P, dtype=float))
        arrays = {k: P[:, j] for j, k in enumerate(spec.parameters)}
        return spec.dense_batch(arrays)

    def linear_at(self, values: Any) -> tuple[Any, Any, Any]:
        """``M, D, K`` at one parameter set (a mapping of every parameter; sparse where the model is)."""
        return self.matrix_spec.at(values)

    def _refuse(self, what: str) -> Any:
        from ..model.matrices import require_equations

        require_equations(self.spec, what)

    # component-model artefacts do not exist here
    def closed_form(self) -> Any:
        return None

    def quartic(self, space: ParameterSpace, names: tuple[str, ...]) -> Any:
        return None

    def closed_route(self, space: ParameterSpace, names: tuple[str, ...]) -> bool:
        return False

    def grid_kernel(self, space: ParameterSpace, names: tuple[str, ...]) -> Any:
        return None

    def map_kernel(self, space: ParameterSpace, x: str, y: str) -> Any:
        return None

    def univariate(self, space: ParameterSpace, name: str) -> Any:
        return None

    def charpoly_table(self, space: ParameterSpace, outer: str, inner: str) -> Any:
        return None

    def omega_kernel(self) -> Any:
        return None

    def silent_kernel(self, use_cache: bool | None = None) -> Any:
        return self._refuse("no silent-motion kernel")

    def simulation_kernels(self, variational: bool = False, use_cache: bool = True) -> Any:
        return self._refuse("no simulation kernels")

    def rate_blocks(self) -> Any:
        return self._refuse("no pad rate blocks")


_MATRIX_ENGINES: dict[tuple[str, bool], MatrixEngine] = {}


def build_matrix_engine(spec: MatrixSpec, *, use_cache: bool = True) -> MatrixEngine:
    """The engine of a matrix model (memoized per process by the hash of its matrices and coefficients).

    Parameters
    ----------
    spec : MatrixSpec
        The model.
    use_cache : bool
        Kept for the engine's interface (nothing is generated for a matrix model).

    Returns
    -------
    MatrixEngine
    """
    key = spec.key()
    eng = _MATRIX_ENGINES.get((key, use_cache))
    if eng is None or eng.spec is not spec:
        caps = Capabilities(n=spec.n, m=0, coords=tuple(spec.dofs), algebraic=(), treatment=(), rate_free_at_zero=(),
                            closed_form=False, omega_kernel=False, tilting=False, kind="matrices")
        eng = MatrixEngine(spec=cast(Any, spec), key=key, compiled=cast(Any, None), caps=caps, use_cache=use_cache)
        if len(_MATRIX_ENGINES) >= 16:
            _MATRIX_ENGINES.pop(next(iter(_MATRIX_ENGINES)))
        _MATRIX_ENGINES[(key, use_cache)] = eng
    return eng
