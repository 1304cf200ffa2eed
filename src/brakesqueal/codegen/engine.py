r"""One engine per model: everything generated from a model, built once at an entry point and passed down.

:func:`build` turns a :class:`~brakesqueal.model.components.ModelSpec` into
an :class:`Engine`.  The entry points (the public API in
:mod:`brakesqueal.api`, the command line, the explorer) build it once per
model; every layer below receives it as a value and never compiles or
derives anything itself.  The engine

* decides the model's **capabilities** once (:class:`Capabilities`): its
  coordinates and pad deformations, how each pad's deformation is treated
  (:attr:`Pad.treatment <brakesqueal.model.components.Pad.treatment>`: from the
  friction law's declared rate dependence and the damper, never from a law's
  name), whether the closed-form and critical-speed kernels apply;
* gives **lazy access** to every generated artefact: the compiled equations
  (:attr:`compiled`), the batched silent-motion kernel, the stability
  kernels of a parameter space and its axes (:meth:`grid_kernel`,
  :meth:`charpoly_table`), the bounded and exact closed-form entries, the
  pads' simplified rate blocks, the exact univariate quartic of a path
  (:meth:`univariate`).

Each artefact is generated at most once per process and kept in the on-disk
cache (:mod:`.cache`), so that a warm start imports no computer algebra: the
SymPy work lives in :mod:`brakesqueal.symbolic.stability_forms` and runs only on
a cache miss.
"""

from __future__ import annotations

import types
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, cast

from .compiled import CompiledModel, compile_model, model_key

if TYPE_CHECKING:
    from ..model.components import ModelSpec
    from ..model.parameters import ParameterSpace
    from ..symbolic.stability_forms import ModelForm
    from .stability import CharpolyTable, GridKernel, MapKernel, RateBlocks

__all__ = ["Engine", "Capabilities", "build"]


@dataclass(frozen=True)
class Capabilities:
    """What a model allows, decided once when its engine is built.

    Attributes
    ----------
    n : int
        Number of coordinates ``Q``.
    m : int
        Number of pad deformations ``L`` (massless pads with a finite tangential stiffness).
    coords, algebraic : tuple of str
        Names of ``Q`` and ``L``.
    treatment : tuple of str
        Per pad deformation, ``"quasi-static"`` or ``"dynamic"``
        (:attr:`Pad.treatment <brakesqueal.model.components.Pad.treatment>`).
    rate_free_at_zero : tuple of bool
        Per pad deformation: its rate blocks vanish identically at the zero state (checked symbolically).
    closed_form : bool
        Two coordinates, rate-free pads provably in sliding contact at the zero state and Laurent-polynomial
        entries: the closed-form kernels apply (where the silent motion is trivial).
    omega_kernel : bool
        The closed form is a Laurent polynomial in a named spin and the zero-state residuals do not depend on
        it: the compiled critical-speed kernel applies.
    tilting : bool
        The disk tilts (``q1``, ``q2`` are coordinates).
    kind : str
        ``"components"`` (a model of disk, pads and calipers: equations derived and generated) or ``"matrices"``
        (coefficient matrices, :mod:`.matrices`: linear, silent motion ``x = 0``).
    """

    n: int
    m: int
    coords: tuple[str, ...]
    algebraic: tuple[str, ...]
    treatment: tuple[str, ...]
    rate_free_at_zero: tuple[bool, ...]
    closed_form: bool
    omega_kernel: bool
    tilting: bool
    kind: str = "components"

    @property
    def dynamic_pads(self) -> bool:
        """Whether some pad keeps a first-order rate state."""
        return "dynamic" in self.treatment


@dataclass(frozen=True, eq=False)
class Engine:
    """Everything generated from one model (see the module docstring); build it with :func:`build`.

    Attributes
    ----------
    spec : ModelSpec
        The model.
    key : str
        Its cache key (:func:`~.compiled.model_key`: a hash of its equations).
    compiled : CompiledModel
        Residuals, Jacobians and contact quantities (math- and NumPy-bound).
    caps : Capabilities
        What the model allows.
    use_cache : bool
        Whether generated artefacts are read from and written to the on-disk cache.
    """

    spec: ModelSpec
    key: str
    compiled: CompiledModel
    caps: Capabilities
    use_cache: bool = True
    _memo: dict[Any, Any] = field(default_factory=dict, repr=False, compare=False)

    def __repr__(self) -> str:
        return f"Engine(model={self.spec.name!r}, key={self.key!r}, n={self.caps.n}, m={self.caps.m})"

    def _get(self, key: Any, make: Callable[[], Any]) -> Any:
        if key not in self._memo:
            self._memo[key] = make()
        return self._memo[key]

    def require_nonlinear(self, what: str) -> Engine:
        """This engine, or a one-line :class:`~brakesqueal.errors.ParameterError` where the model has no nonlinear
        equations (a model given by coefficient matrices) and ``what`` needs them."""
        from ..model.matrices import require_equations

        require_equations(self.spec, what)
        return self

    # ---------------------------------------------------------------- closed forms (SymPy on a cache miss)
    def closed_form(self) -> ModelForm | None:
        """The model's closed form about the zero state (SymPy; ``None`` where :attr:`Capabilities.closed_form`
        is false).  Only generators and symbolic consumers need it; the kernels below are cached."""
        def make() -> Any:
            from ..symbolic.stability_forms import build_model_form

            cm = self.compiled
            return build_model_form(self.spec, self.key, cm.param_names, cm.n, cm.rate_free_at_zero)

        return self._get("form", make)  # type: ignore[no-any-return]

    def _require_form(self) -> ModelForm:
        form = self.closed_form()
        if form is None:
            from ..errors import ParameterError

            raise ParameterError(f"model '{self.spec.name}' has no closed-form kernel (two coordinates and rate-free "
                                 "pads at the zero state are needed); use the per-point routes")
        return form

    def _space_ident(self, space: ParameterSpace, names: tuple[str, ...]) -> str:
        return f"{self.key}|{space.key()}|{tuple(names)!r}"

    def quartic(self, space: ParameterSpace, names: tuple[str, ...]) -> Any:
        """:func:`~brakesqueal.symbolic.stability_forms.quartic_numerators` of a space with ``names`` symbolic
        (SymPy; memoized).  ``None`` where the closed-form route does not apply."""
        names = tuple(names)

        def make() -> Any:
            from ..symbolic.stability_forms import quartic_numerators

            return quartic_numerators(self.closed_form(), space, names)

        return self._get(("qn", space.key(), names), make)

    def closed_route(self, space: ParameterSpace, names: tuple[str, ...]) -> bool:
        """Whether the closed-form route applies on a grid over ``names``: the model has a closed form and the
        silent motion is identically trivial on the axes (decided once with SymPy, then read from disk).

        Parameters
        ----------
        space : ParameterSpace
            The parameter space.
        names : tuple of str
            The axes (settable names of ``space``).

        Returns
        -------
        bool
        """
        names = tuple(names)
        if not self.caps.closed_form:
            return False

        def make() -> bool:
            from .stability import disk_json

            ident = self._space_ident(space, names)
            return bool(disk_json("closed", ident, lambda: self.quartic(space, names) is not None,
                                  use_cache=self.use_cache))

        return self._get(("closed", space.key(), names), make)  # type: ignore[no-any-return]

    def grid_kernel(self, space: ParameterSpace, names: tuple[str, ...]) -> GridKernel | None:
        """The certified compiled Hurwitz classifier of a grid over ``names`` (``None`` where it does not apply:
        no closed form, a non-trivial silent motion somewhere on the grid, non-rational dependence, degrees
        above :data:`~brakesqueal.symbolic.stability_forms.MAX_INNER_DEGREE`)."""
        names = tuple(names)

        def make() -> Any:
            import numpy as np

            from .stability import GridKernel, disk_json, kernel_source, load_generated

            if not self.closed_route(space, names):
                return None

            def table() -> Any:
                from ..symbolic.stability_forms import grid_table

                return grid_table(self.quartic(space, names), names)

            tab = disk_json("grid", self._space_ident(space, names), table, use_cache=self.use_cache)
            if tab is None:
                return None
            degrees = tuple(int(d) for d in tab["degrees"])
            source = kernel_source(degrees)
            mod = load_generated(source, "map", use_cache=self.use_cache)
            nt = len(tab["slot"])
            return GridKernel(names=names, inner=int(tab["inner"]), degrees=degrees,
                              exps=np.array(tab["exps"], dtype=np.int64).reshape(nt, len(names) - 1),
                              ipow=np.array(tab["ipow"], dtype=np.int64), slot=np.array(tab["slot"], dtype=np.int64),
                              mant=np.array([float.fromhex(v) for v in tab["mant"]]),
                              e2=np.array(tab["e2"], dtype=np.int64), nops=np.array(tab["nops"], dtype=float),
                              classify=mod.classify, coefficients=mod.coefficients, source=source)

        return self._get(("grid", space.key(), names), make)  # type: ignore[no-any-return]

    def map_kernel(self, space: ParameterSpace, x: str, y: str) -> MapKernel | None:
        """The grid kernel of a map over ``x`` and ``y`` with the axis roles named (``None`` where it does not
        apply).  The result does not depend on the axes' ranges or signs."""
        from .stability import MapKernel

        g = self.grid_kernel(space, (x, y))
        if g is None:
            return None
        names = (x, y)
        return MapKernel(outer=names[1 - g.inner], inner=names[g.inner], degrees=g.degrees, grid=g)

    def univariate(self, space: ParameterSpace, name: str) -> dict[str, Any] | None:
        """Exact univariate coefficients of the quartic's numerators along ``name`` (for exact crossings), kept on
        disk; ``None`` where the closed-form route does not apply
        (:func:`~brakesqueal.symbolic.stability_forms.univariate_table`)."""
        def make() -> Any:
            from .stability import disk_json

            if not self.closed_route(space, (name,)):
                return None

            def table() -> Any:
                from ..symbolic.stability_forms import univariate_table

                return univariate_table(self.quartic(space, (name,)))

            return disk_json("univariate", self._space_ident(space, (name,)), table, use_cache=self.use_cache)

        return self._get(("univariate", space.key(), name), make)

    def charpoly_table(self, space: ParameterSpace, outer: str, inner: str) -> CharpolyTable | None:
        """The exact characteristic polynomial of a map's zero state in its two axes (any model size), or
        ``None`` where it does not apply (see :func:`~brakesqueal.symbolic.stability_forms.charpoly_data`)."""
        names = (outer, inner)

        def make() -> Any:
            from .stability import charpoly_from_data, disk_json

            def data() -> Any:
                from ..symbolic.stability_forms import charpoly_data, nd_form

                form = self._get("nd-form", lambda: nd_form(self.spec, self.compiled.rate_free_at_zero))
                return charpoly_data(form, space, names)

            return charpoly_from_data(outer, inner, disk_json("charpoly", self._space_ident(space, names), data,
                                                              use_cache=self.use_cache))

        return self._get(("charpoly", space.key(), names), make)  # type: ignore[no-any-return]

    # ---------------------------------------------------------------- closed-form entries (generated)
    def entries_kernel(self, plain: bool = False) -> types.ModuleType:
        """Compiled ``entries_batch(P, V, R)``: the 12 closed-form entries of ``M, D, K`` with rounding bounds
        (``plain``: the same source as plain Python, for a few points without importing numba)."""
        def make() -> Any:
            from .stability import bounded_source, load_keyed

            if not self.caps.closed_form:
                self._require_form()

            def source() -> str:
                from ..symbolic.stability_forms import entry_slots

                form = self._require_form()
                return bounded_source("entries_batch", entry_slots(form), "Mbar, Dbar, Kbar entries (row-major)",
                                      len(form.symbols))

            return load_keyed("entries", self.key, source, plain=plain, use_cache=self.use_cache)

        return self._get(("entries", plain), make)  # type: ignore[no-any-return]

    def omega_kernel(self) -> types.ModuleType | None:
        """Compiled ``entries_batch(P, V, R)``: Laurent coefficients in Ω of the 12 entries with rounding bounds
        (``None`` where :attr:`Capabilities.omega_kernel` is false)."""
        def make() -> Any:
            from .stability import bounded_source, load_keyed

            if not self.caps.omega_kernel:
                return None

            def source() -> str:
                from ..symbolic.stability_forms import omega_slots

                form = self._require_form()
                return bounded_source("entries_batch", omega_slots(form), "Laurent coefficients in Omega",
                                      len(form.symbols))

            return load_keyed("omega", self.key, source, use_cache=self.use_cache)

        return self._get("omega", make)  # type: ignore[no-any-return]

    def exact_entries(self) -> types.ModuleType:
        """Python module with ``entries(x)`` (the 12 entries at an exact rational parameter vector, Fraction
        arithmetic) and ``EXACT`` (false when irrational constants were rounded)."""
        def make() -> Any:
            from . import cache

            def source() -> str:
                from ..symbolic.stability_forms import exact_entries_source

                return exact_entries_source(self._require_form())

            if not self.caps.closed_form:
                self._require_form()
            return cache.load_module(self.key, "exact_entries.py", source, use_cache=self.use_cache)

        return self._get("exact-entries", make)  # type: ignore[no-any-return]

    def exact_omega(self) -> types.ModuleType:
        """Python module with ``omega_entries(x)``: the coefficients of ``Ω·entry`` in ``Ω^0..Ω^3`` (48 exact
        values; ``x`` an exact rational parameter vector) and ``EXACT``."""
        def make() -> Any:
            from . import cache

            def source() -> str:
                from ..symbolic.stability_forms import exact_omega_source

                return exact_omega_source(self._require_form())

            if not self.caps.omega_kernel:
                raise NotImplementedError(f"model '{self.spec.name}' has no Laurent form in its spin")
            return cache.load_module(self.key, "exact_omega.py", source, use_cache=self.use_cache)

        return self._get("exact-omega", make)  # type: ignore[no-any-return]

    def rate_blocks(self) -> RateBlocks:
        """The pads' zero-state rate blocks ``R_dL``, ``G_dL``, ``G_ddQ``, simplified (no cancellation noise)."""
        def make() -> Any:
            from . import cache
            from .stability import RateBlocks, rate_source

            def source() -> str:
                from ..symbolic.stability_forms import rate_block_exprs

                _, _, args, exprs = rate_block_exprs(self.spec)
                return rate_source(args, exprs)

            mod = cache.load_module(self.key, "rate_blocks.py", source, use_cache=self.use_cache)
            return RateBlocks(n=self.caps.n, m=self.caps.m, function=mod.rate_blocks)

        return self._get("rates", make)  # type: ignore[no-any-return]

    # ---------------------------------------------------------------- batched silent motions
    def silent_kernel(self, use_cache: bool | None = None) -> types.ModuleType:
        """The compiled batched silent-motion kernel (:mod:`.silent`; numba compiles it on first use)."""
        from .silent import load_kernel

        uc = self.use_cache if use_cache is None else use_cache
        mod = self._get(("silent", uc), lambda: load_kernel(self.compiled, self.key, uc))
        return mod  # type: ignore[no-any-return]

    def silent_ready(self, use_cache: bool | None = None) -> bool:
        """Whether the silent-motion kernel runs without compiling (already run here, or in numba's disk cache)."""
        from .silent import kernel_ready

        return kernel_ready(self.key, use_cache=self.use_cache if use_cache is None else use_cache)

    def mark_silent_ready(self, use_cache: bool | None = None) -> None:
        """Record that the silent-motion kernel has run in this process."""
        from .silent import mark_ready

        mark_ready(self.key, self.use_cache if use_cache is None else use_cache)

    # ---------------------------------------------------------------- variants
    def with_spec(self, spec: ModelSpec) -> Engine:
        """This engine for another description of the same equations (same :attr:`key`; artefacts shared)."""
        if spec is self.spec:
            return self
        cm = self.compiled
        cm2 = CompiledModel(spec=spec, coords=cm.coords, algebraic=cm.algebraic, param_names=cm.param_names,
                            residuals=cm.residuals, jacobians=cm.jacobians, contact=cm.contact,
                            vectorized=cm.vectorized, source=cm.source, rate_free_at_zero=cm.rate_free_at_zero)
        return Engine(spec=spec, key=self.key, compiled=cm2, caps=self.caps, use_cache=self.use_cache,
                      _memo=self._memo)

    # ---------------------------------------------------------------- simulation kernels (generated)
    def simulation_kernels(self, variational: bool = False, use_cache: bool = True) -> types.ModuleType:
        """The model's compiled simulation kernels (:mod:`.simulation`; numba compiles them on first use).

        Parameters
        ----------
        variational : bool, optional
            The variational module instead (the vector field with its exact Jacobian ``nl_f``, ``nl_jac``,
            ``nl_dfdp``, and every kernel).
        use_cache : bool, optional
            Read and write the on-disk cache.

        Returns
        -------
        module
            ``rhs``, ``solve_pads``, ``event_values``, ``contact``, ``energy``, ``post_process``, ``dop853``,
            ``META`` (pad treatment :attr:`caps.treatment <Capabilities.treatment>`).
        """
        from .simulation import load_kernels

        def make() -> Any:
            return load_kernels(self, variational=variational, use_cache=use_cache)

        return self._get(("simulation", variational, use_cache), make)  # type: ignore[no-any-return]


_ENGINES: dict[tuple[str, bool], Engine] = {}
_MAX_ENGINES = 64


def _form_info(spec: ModelSpec, key: str, cm: CompiledModel, use_cache: bool = True) -> dict[str, Any]:
    """``{"form": bool, "omega_kernel": bool}`` of a model, built once with SymPy and kept on disk."""
    from .stability import disk_json

    def make() -> dict[str, Any]:
        from ..symbolic.stability_forms import build_model_form, omega_slots

        form = build_model_form(spec, key, cm.param_names, cm.n, cm.rate_free_at_zero)
        ok = False
        if form is not None and form.omega is not None and form.omega_free:
            try:
                ok = bool(omega_slots(form))
            except NotImplementedError:
                ok = False
        return {"form": form is not None, "omega_kernel": ok}

    return disk_json("form", key, make, use_cache=use_cache)  # type: ignore[no-any-return]


def build(spec: ModelSpec | str, *, use_cache: bool = True) -> Engine:
    """The engine of a model (memoized per process by the model's equations).

    Parameters
    ----------
    spec : ModelSpec or str
        The model, or a built-in model name / model file.
    use_cache : bool, optional
        Read and write the on-disk cache (default ``True``).

    Returns
    -------
    Engine
    """
    from ..model.matrices import MatrixSpec
    from ..model.parameters import as_model_spec

    spec = cast("ModelSpec", as_model_spec(spec))
    if isinstance(spec, MatrixSpec):
        from .matrices import build_matrix_engine

        return build_matrix_engine(spec, use_cache=use_cache)
    key = model_key(spec)
    eng = _ENGINES.get((key, use_cache))
    if eng is None:
        cm = compile_model(spec, use_cache=use_cache)
        info = _form_info(spec, key, cm, use_cache)
        caps = Capabilities(n=cm.n, m=cm.m, coords=cm.coords, algebraic=cm.algebraic,
                            treatment=tuple(t for t in (p.treatment for p in spec.pads) if t is not None),
                            rate_free_at_zero=tuple(cm.rate_free_at_zero), closed_form=bool(info["form"]),
                            omega_kernel=bool(info["omega_kernel"]), tilting=bool(spec.disk.tilting))
        eng = Engine(spec=spec, key=key, compiled=cm, caps=caps, use_cache=use_cache)
        if len(_ENGINES) >= _MAX_ENGINES:
            _ENGINES.pop(next(iter(_ENGINES)))
        _ENGINES[(key, use_cache)] = eng
    return eng.with_spec(spec)
