"""Study files: what a parameter study sweeps and computes, validated, hashed and chunked.

A study file is a TOML superset of a parameter file (see ``docs/sweeps.md``)::

    name = "fig2-omega"
    preset = "paper-fig2"            # or: params = "my-parameters.toml"
    [parameters]                     # fixed values of free/fixed names
    h = 0.02
    [tied]                           # extra (or replaced) tie expressions
    N0 = "3600/mu"
    [axes]                           # one dimension per entry, in this order
    k_ip = "1e5:1e10:400:log"        # START:STOP:N[:log]
    mu = { start = 0.05, stop = 1.0, num = 300 }
    Omega = { values = [10, 50.26548, 100] }
    [compute]
    quantities = ["stable", "margin", "max_real", "frequency"]
    [execution]
    chunk_points = 1048576
    [output]
    store = "fig2-omega.zarr"

Instead of ``[axes]``, ``[samples]`` draws ``n`` random, Latin-hypercube or
scrambled Sobol' points (``method = "random" | "lhs" | "sobol"``, ``seed``)
from ``[samples.ranges]`` (the same range syntax without ``num``) and/or from
``[distributions]`` (``mu = { uniform = [0.35, 0.55] }``, normal, truncnormal,
lognormal, beta: :mod:`brakesqueal.uq`; their support must lie in the
parameter's allowed range); the result then has one dimension ``sample``.  Every problem raises a one-line
:class:`~brakesqueal.errors.ParameterError` naming the file and the key.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeGuard, Union

import numpy as np

from ..validation import validated
from ..errors import ParameterError
from ..model.parameters import Value

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..uq import Distribution

__all__ = ["Study", "StudySource", "GridAxis", "SampleRange", "load_study", "QUANTITIES", "DEFAULT_QUANTITIES",
           "MAX_AXIS_POINTS", "MAX_POINTS", "MAX_CHUNKS", "MAX_CHUNK_POINTS"]

#: Quantities a study may compute per point (``stable`` and ``status`` are always computed).
#: The quantities of the built-in list a study may ask for (any registered quantity is allowed:
#: :data:`brakesqueal.analysis.quantities.QUANTITIES`).
QUANTITIES = ("stable", "margin", "max_real", "frequency", "carrier", "route", "critical_speed")
DEFAULT_QUANTITIES = ("stable", "margin", "max_real", "frequency")
#: Points per chunk by default: verdict-only studies / studies with eigenvalues.
DEFAULT_CHUNK_POINTS = (1 << 22, 1 << 18)
_TOP_KEYS = ("name", "description", "preset", "params", "model", "parameters", "tied", "axes", "samples", "compute",
             "execution", "output", "distributions", "design")
_MAX_SAMPLES = 10**7
#: Size limits of a study, checked from the study's numbers before anything is allocated:
#: points of one grid axis (its values are held in memory by every process: 0.8 GB at the limit),
MAX_AXIS_POINTS = 10**8
#: points of a study (the store then holds 2-34 TB uncompressed),
MAX_POINTS = 10**12
#: chunks of a study (one completion marker file per chunk, all verified on resume),
MAX_CHUNKS = 10**6
#: points of one chunk, which is computed in memory: verdict-only grids (about 3 bytes per point
#: of working memory) / eigenvalue quantities, samples or built models (about 600 bytes per point).
MAX_CHUNK_POINTS = (1 << 26, 1 << 22)


def _is_num(v: object) -> TypeGuard[float]:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


@dataclass(frozen=True)
class GridAxis:
    """One grid dimension: a linear/log range or explicit values."""

    name: str
    values: np.ndarray = field(repr=False, compare=False)
    scale: str  # "linear", "log" or "values"
    spec: tuple[float, ...]  # (start, stop, num) or the values, for the hash
    ref: float  # magnitude used to scale polynomials in this axis (same for every chunk)

    @property
    def size(self) -> int:
        return int(self.values.size)


@dataclass(frozen=True)
class SampleRange:
    """The range of one sampled parameter (``distribution``: drawn from it instead, ``[distributions]``;
    ``start``/``stop`` are then its support)."""

    name: str
    start: float
    stop: float
    log: bool
    distribution: Distribution | None = None


@dataclass(frozen=True, eq=False)
class Study:
    """A validated parameter study (see the module docstring for the file format).

    Attributes
    ----------
    source : str
        Where it came from (file path or ``"<dict>"``), used in error messages.
    text : str
        The study file's text (stored with the results).
    name : str
        Label.
    preset : str or None
        Preset name; ``None`` for a complete parameter set.
    values : dict
        Overrides of the preset's settable names, or all 17 model parameters.
    tied : dict
        Tie expressions added or replaced by the study.
    kind : str
        ``"grid"`` or ``"samples"``.
    axes : tuple of GridAxis
        Grid dimensions (``kind == "grid"``).
    ranges : tuple of SampleRange
        Sampled parameters (``kind == "samples"``).
    n_samples, seed, method : int, int, str
        Sampling settings.
    quantities : tuple of str
        What to compute besides ``stable`` and ``status``.
    critical_speed_range : tuple of float
        Ω range [rad/s] searched for the critical speed.
    chunks : tuple of int
        Chunk shape (one entry per dimension).
    store : str or None
        Default result store (relative paths are relative to the study file).
    model : str or None
        A built model (canonical JSON of its description) instead of a preset;
        ``values`` then override the model's parameters.
    """

    source: str
    text: str
    name: str
    preset: str | None
    values: Mapping[str, Value]
    tied: Mapping[str, str]
    kind: str
    axes: tuple[GridAxis, ...]
    ranges: tuple[SampleRange, ...]
    n_samples: int
    seed: int
    method: str
    quantities: tuple[str, ...]
    critical_speed_range: tuple[float, float]
    chunks: tuple[int, ...]
    store: str | None
    model: str | None = None

    # ------------------------------------------------------------ layout
    @property
    def dims(self) -> tuple[str, ...]:
        """Dimension names of the result."""
        return tuple(a.name for a in self.axes) if self.kind == "grid" else ("sample",)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(a.size for a in self.axes) if self.kind == "grid" else (self.n_samples,)

    @property
    def n_points(self) -> int:
        return math.prod(self.shape)

    @property
    def chunk_grid(self) -> tuple[int, ...]:
        """Number of chunks along each dimension."""
        return tuple(-(-s // c) for s, c in zip(self.shape, self.chunks))

    @property
    def n_chunks(self) -> int:
        return math.prod(self.chunk_grid)

    def region(self, chunk: int) -> tuple[slice, ...]:
        """Index region of chunk number ``chunk`` (C order over the chunk grid)."""
        idx = np.unravel_index(chunk, self.chunk_grid)
        return tuple(slice(int(i) * c, min(int(i) * c + c, s)) for i, c, s in zip(idx, self.chunks, self.shape))

    def chunk_points(self, chunk: int) -> int:
        return math.prod(s.stop - s.start for s in self.region(chunk))

    @property
    def sample_names(self) -> tuple[str, ...]:
        return tuple(r.name for r in self.ranges)

    def samples(self) -> dict[str, np.ndarray]:
        """The sampled parameter values (deterministic in ``seed``; computed once)."""
        if "_samples" in self.__dict__:
            return self.__dict__["_samples"]
        d, n = len(self.ranges), self.n_samples
        if self.method == "lhs":
            from scipy.stats import qmc

            u = qmc.LatinHypercube(d=d, seed=np.random.default_rng(self.seed)).random(n)
        elif self.method == "sobol":
            import warnings

            from scipy.stats import qmc

            with warnings.catch_warnings():  # n not a power of 2: fine for a sample, not for a Sobol' index design
                warnings.filterwarnings("ignore", message=".*balance properties.*")
                u = qmc.Sobol(d=d, scramble=True, seed=np.random.default_rng(self.seed)).random(n)
        else:
            u = np.random.default_rng(self.seed).random((n, d))
        out = {}
        for k, r in enumerate(self.ranges):
            if r.distribution is not None:
                out[r.name] = r.distribution.ppf(u[:, k])
            elif r.log:
                lo, hi = math.log(r.start), math.log(r.stop)
                out[r.name] = np.exp(lo + (hi - lo) * u[:, k])
            else:
                out[r.name] = r.start + (r.stop - r.start) * u[:, k]
        self.__dict__["_samples"] = out
        return out

    # ------------------------------------------------------------ identity
    def canonical(self) -> dict[str, Any]:
        """Everything that determines the stored results (hashed by :meth:`hash`)."""
        space = self.space()
        d: dict[str, Any] = {
            "space": {"label": space.label, "definitions": {k: str(v) for k, v in sorted(space.definitions().items())},
                      "tied": dict(sorted(space.tied.items()))},
            "kind": self.kind, "quantities": list(self.quantities), "chunks": list(self.chunks),
        }
        if self.model is not None:
            d["model"] = json.loads(self.model)
        if "critical_speed" in self.quantities:
            d["critical_speed_range"] = list(self.critical_speed_range)
        if self.kind == "grid":
            d["axes"] = [{"name": a.name, "scale": a.scale, "spec": [repr(x) for x in a.spec],
                          "values_sha256": hashlib.sha256(np.ascontiguousarray(a.values).tobytes()).hexdigest()}
                         for a in self.axes]
        else:
            d["samples"] = {"method": self.method, "n": self.n_samples, "seed": self.seed,
                            "ranges": [[r.name, repr(r.start), repr(r.stop), r.log]
                                       + ([r.distribution.spec()] if r.distribution is not None else [])
                                       for r in self.ranges]}
        return d

    def hash(self) -> str:
        """SHA-256 of :meth:`canonical` (identifies the study in a store)."""
        if "_hash" not in self.__dict__:
            self.__dict__["_hash"] = hashlib.sha256(json.dumps(self.canonical(), sort_keys=True).encode()).hexdigest()
        return self.__dict__["_hash"]

    def space(self) -> ParameterSpace:
        """The :class:`~brakesqueal.model.parameters.ParameterSpace` of the study (cached per process)."""
        from .compute import build_space

        return build_space(self.preset, tuple(self.values.items()), tuple(self.tied.items()), self.model)

    def engine(self) -> Engine:
        """The engine of the study's model (a study file is an entry point: its model is built where it is read)."""
        from ..codegen import build

        return build(self.space().model)

    def variables(self) -> list[str]:
        """The stored variables: ``stable``, ``status`` and the study's other quantities, in registry order."""
        from ..analysis.quantities import ALWAYS, QUANTITIES as REGISTERED

        return [*ALWAYS, *[q for q in REGISTERED if q in self.quantities and q not in ALWAYS]]


#: What :func:`load_study` reads: a loaded study, a TOML study file or its content as a dict.
StudySource = Union[Study, str, Path, Mapping[str, Any]]


# ---------------------------------------------------------------- parsing helpers
class _Ctx:
    def __init__(self, source: str) -> None:
        self.source = source

    def err(self, key: str, msg: str) -> ParameterError:
        return ParameterError(f"study file '{self.source}': key '{key}': {msg}")

    def table(self, data: object, key: str, allowed: tuple[str, ...] | None = None) -> dict[str, Any]:
        if not isinstance(data, dict):
            raise self.err(key, f"must be a table; got {data!r}")
        if allowed is not None:
            for k in data:
                if k not in allowed:
                    raise self.err(k if key == "<top>" else f"{key}.{k}",
                                   "unknown key; allowed keys: " + ", ".join(allowed))
        return data

    def number(self, v: object, key: str) -> float:
        from ..model.expressions import evaluate

        if isinstance(v, str):
            try:
                x = evaluate(v, {}, what=f"value of '{key}'")
            except ParameterError as exc:
                raise self.err(key, str(exc)) from None
        elif _is_num(v):
            x = float(v)
        else:
            raise self.err(key, f"must be a number or an expression string; got {v!r}")
        if not math.isfinite(x):
            raise self.err(key, f"must be finite; got {v!r}")
        return x

    def integer(self, v: object, key: str, low: int) -> int:
        if not isinstance(v, int) or isinstance(v, bool):
            raise self.err(key, f"must be an integer; got {v!r}")
        if v < low:
            raise self.err(key, f"must be >= {low}; got {v}")
        return v


def _parse_range(ctx: _Ctx, key: str, v: object, with_num: bool) -> tuple[float, float, int, bool]:
    """A range entry: ``"START:STOP:N[:log]"`` or ``{start, stop, num, scale}``."""
    if isinstance(v, str):
        from ..analysis.maps import parse_axis

        name = key.rsplit(".", 1)[-1]
        parts = [p.strip() for p in v.split(":")]
        log = parts[-1].lower() == "log"
        core = parts[:-1] if parts[-1].lower() in ("log", "lin", "linear") else parts
        if with_num and len(core) == 3 and core[2].lstrip("+-").isdigit() and int(core[2]) < 1:
            raise ctx.err(key, f"empty axis (N = {core[2]}); give N >= 2 points")
        try:
            ax = parse_axis(f"{name}={v}", with_num=with_num)
        except ParameterError as exc:
            raise ctx.err(key, str(exc)) from None
        return ax.start, ax.stop, ax.num, log
    tab = ctx.table(v, key, ("start", "stop", "num", "scale") if with_num else ("start", "stop", "scale"))
    for req in ("start", "stop", "num") if with_num else ("start", "stop"):
        if req not in tab:
            raise ctx.err(f"{key}.{req}", "missing")
    start, stop = ctx.number(tab["start"], f"{key}.start"), ctx.number(tab["stop"], f"{key}.stop")
    num = 2
    if with_num:
        num = tab["num"]
        if not isinstance(num, int) or isinstance(num, bool):
            raise ctx.err(f"{key}.num", f"must be an integer; got {num!r}")
        if num < 1:
            raise ctx.err(f"{key}.num", f"empty axis (num = {num}); give num >= 2 points")
    scale = tab.get("scale", "linear")
    if scale not in ("linear", "log"):
        raise ctx.err(f"{key}.scale", f"must be 'linear' or 'log'; got {scale!r}")
    return start, stop, num, scale == "log"


def _grid_axis(ctx: _Ctx, name: str, v: object) -> GridAxis:
    from ..analysis.maps import Axis

    key = f"axes.{name}"
    values: list[Any] | None = None
    if isinstance(v, list):
        values = v
    elif isinstance(v, dict) and "values" in v:
        ctx.table(v, key, ("values",))
        values = v["values"]
        if not isinstance(values, list):
            raise ctx.err(f"{key}.values", f"must be a list of numbers; got {values!r}")
    if values is not None:
        if not values:
            raise ctx.err(key, "empty axis (no values)")
        if len(values) > MAX_AXIS_POINTS:
            raise ctx.err(key, f"{len(values)} values exceed the limit of {MAX_AXIS_POINTS:.0e} points per axis")
        arr = np.array([ctx.number(x, f"{key}.values[{i}]") for i, x in enumerate(values)])
        if np.unique(arr).size != arr.size:
            raise ctx.err(key, "values must be distinct")
        ref = float(np.max(np.abs(arr))) or 1.0
        if np.all(arr > 0):
            ref = float(math.sqrt(arr.min() * arr.max()))
        return GridAxis(name, arr, "values", tuple(float(x) for x in arr), ref)
    start, stop, num, log = _parse_range(ctx, key, v, True)
    nkey = f"{key}.num" if isinstance(v, dict) else key
    if num > MAX_AXIS_POINTS:
        raise ctx.err(nkey, f"{num} points ({num:.3g}) exceed the limit of {MAX_AXIS_POINTS:.0e} points per axis "
                            f"(its values alone would take {_size(8 * num)} of memory); use fewer points or split "
                            "the study")
    _check_resolution(ctx, nkey, start, stop, num, log)
    try:
        ax = Axis(name, start, stop, num, log)
    except ParameterError as exc:
        raise ctx.err(key, str(exc)) from None
    return GridAxis(name, ax.values(), "log" if log else "linear", (start, stop, num), ax.ref)


def _distributions(ctx: _Ctx, dtab: dict[str, Any], rtab: dict[str, Any], space: ParameterSpace) -> list[SampleRange]:
    """The ``[distributions]`` entries as sampled ranges (parsed and checked by :mod:`brakesqueal.uq`)."""
    from ..uq import check_support, parse_distribution

    out = []
    for k, v in dtab.items():
        if k in rtab:
            raise ctx.err(f"distributions.{k}", f"'{k}' is also in [samples.ranges]; give it one of the two")
        try:
            space.check_axis(k)
        except ParameterError as exc:
            raise ctx.err(f"distributions.{k}", str(exc)) from None
        dist = parse_distribution(k, v, ctx.err, ctx.number)
        check_support(dist, space, ctx.err)
        lo, hi, _, _ = dist.support
        out.append(SampleRange(k, lo, hi, False, dist))
    return out


def _size(nbytes: float) -> str:
    """``nbytes`` in human units (decimal)."""
    for unit, f in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= f:
            return f"{nbytes / f:.3g} {unit}"
    return f"{int(nbytes)} bytes"


def _check_resolution(ctx: _Ctx, key: str, start: float, stop: float, num: int, log: bool) -> None:
    """Refuse a range whose ``num`` points would not be distinct floating-point numbers (the rule of every axis,
    :func:`~brakesqueal.analysis.maps.resolution_problem`)."""
    from ..analysis.maps import resolution_problem

    problem = resolution_problem(start, stop, num, log)
    if problem:
        raise ctx.err(key, problem)


def _default_chunks(shape: tuple[int, ...], points: int) -> tuple[int, ...]:
    """Chunk shape of at most ``points`` points: whole trailing dimensions, a block of the next one."""
    chunks = [1] * len(shape)
    acc = 1
    for k in reversed(range(len(shape))):
        if acc * shape[k] <= points:
            chunks[k] = shape[k]
            acc *= shape[k]
        else:
            chunks[k] = max(1, points // acc)
            break
    return tuple(chunks)


def _read(path: str) -> tuple[str, dict[str, Any]]:
    from ..model.io import read_toml_text

    return read_toml_text(path, "study file")


@validated
def load_study(study: StudySource) -> Study:
    """Read and validate a study.

    Parameters
    ----------
    study : Study, str, Path or dict
        A loaded study (returned as is), a TOML study file, or a dict of the
        same content (relative paths are then relative to the working directory).

    Returns
    -------
    Study
        The validated study.

    Raises
    ------
    ParameterError
        One line naming the file and the key.
    """
    if isinstance(study, Study):
        return study
    if isinstance(study, (str, Path)):
        text, data = _read(str(study))
        return _from_data(data, str(study), text, Path(study).resolve().parent)
    if isinstance(study, Mapping):
        from ..inputs import check_data

        check_data(study, "study <dict>")
        return _from_data(dict(study), "<dict>", json.dumps(study, sort_keys=True, default=str), Path.cwd())
    raise ParameterError(f"a study is a TOML file path, a dict or a Study; got {type(study).__name__}")


def _preset_space(ctx: _Ctx, data: dict[str, Any], base: Path) -> tuple[str | None, dict[str, Value],
                                                                        dict[str, Any], ParameterSpace, str | None]:
    """The preset / parameter-file / [parameters] / [tied] part of a study: (preset, values, tied, space, model)."""
    from ..model.io import load_parameter_file, spec_to_dict
    from ..model.library import get_model, get_preset, resolve_model

    paper_names = tuple(get_model("paper").parameters)
    preset_name = data.get("preset")
    if preset_name is not None and not isinstance(preset_name, str):
        raise ctx.err("preset", f"must be a string; got {preset_name!r}")
    values: dict[str, Value] = {}
    model_json = None
    spec = None
    if "params" in data:
        pfile = data["params"]
        if not isinstance(pfile, str):
            raise ctx.err("params", f"must be a file name; got {pfile!r}")
        path = pfile if Path(pfile).is_absolute() else str(base / pfile)
        try:
            f_model, f_preset, entries = load_parameter_file(path)
            spec = resolve_model(f_model) if f_model is not None else None
        except ParameterError as exc:
            raise ctx.err("params", str(exc)) from None
        if preset_name is not None and f_preset is not None and f_preset != preset_name:
            raise ctx.err("preset", f"'{preset_name}' conflicts with preset '{f_preset}' of '{pfile}'")
        preset_name = preset_name or f_preset
        values.update(entries)
        if spec is not None:
            model_json = json.dumps(spec_to_dict(spec), sort_keys=True)
    elif preset_name is None and not data.get("parameters"):
        raise ctx.err("preset", "missing: name a preset (e.g. preset = \"paper-fig2\"), a parameter file "
                                "(params = \"file.toml\") or all 17 model parameters in [parameters]")
    if preset_name is not None:
        try:
            spec.get_preset(preset_name) if spec is not None else get_preset(preset_name)
        except ParameterError as exc:
            raise ctx.err("preset", str(exc)) from None
    params_tab = ctx.table(data.get("parameters", {}), "parameters")
    for k, v in params_tab.items():
        if not (_is_num(v) or isinstance(v, str)):
            raise ctx.err(f"parameters.{k}", f"must be a number or an expression string; got {v!r}")
        values[k] = v
    if preset_name is None and spec is None and set(values) != set(paper_names):
        missing = [n for n in paper_names if n not in values]
        unknown = [n for n in values if n not in paper_names]
        if unknown:
            raise ctx.err(f"parameters.{unknown[0]}", "unknown parameter; valid names: " + ", ".join(paper_names))
        raise ctx.err("parameters", "missing " + ", ".join(missing) + " (no preset: give all 17 model parameters)")
    tied_tab = ctx.table(data.get("tied", {}), "tied")
    for k, v in tied_tab.items():
        if not isinstance(v, str):
            raise ctx.err(f"tied.{k}", f"must be an expression string; got {v!r}")
        if k in values:
            raise ctx.err(f"tied.{k}", f"'{k}' is also given in [parameters]; a name is either fixed or tied")
    from .compute import build_space

    try:
        space = build_space(preset_name, tuple(values.items()), tuple(tied_tab.items()), model_json)
    except ParameterError as exc:
        raise ctx.err(_offending_key(exc, values, tied_tab), str(exc)) from None

    return preset_name, values, tied_tab, space, model_json


def _offending_key(exc: ParameterError, values: Mapping[str, Any], tied: Mapping[str, Any]) -> str:
    """The study-file key a parameter error is about, from the names it carries (never from its text).

    The first of the error's names (the offending one first, then the others involved: the inputs of a
    tie, the members of a cycle) that the study gives in ``[parameters]`` or ``[tied]``; else ``parameters``.
    """
    for name in exc.names:
        if name in values:
            return f"parameters.{name}"
        if name in tied:
            return f"tied.{name}"
    return "parameters"


def _model_space(ctx: _Ctx, data: dict[str, Any], base: Path) -> tuple[str, dict[str, Value], ParameterSpace]:
    """The ``model = ...`` part of a study: (canonical model JSON, parameter overrides, space)."""
    from ..model.io import spec_to_dict
    from ..model.library import resolve_model

    for key in ("preset", "params", "tied"):
        if key in data:
            raise ctx.err(key, "cannot be combined with 'model' (give the model's parameters in [parameters])")
    m = data["model"]
    if not isinstance(m, str) or not m:
        raise ctx.err("model", f"must be a model file or a built-in model name; got {m!r}")
    path = Path(m) if Path(m).is_absolute() else base / m
    try:
        spec = resolve_model(str(path) if path.exists() else m)
    except ParameterError as exc:
        raise ctx.err("model", str(exc)) from None
    values: dict[str, Value] = {}
    for k, v in ctx.table(data.get("parameters", {}), "parameters").items():
        if not (_is_num(v) or isinstance(v, str)):
            raise ctx.err(f"parameters.{k}", f"must be a number or an expression string; got {v!r}")
        values[k] = v
    model_json = json.dumps(spec_to_dict(spec), sort_keys=True)
    from .compute import build_space

    try:
        space = build_space(None, tuple(values.items()), (), model_json)
    except ParameterError as exc:
        raise ctx.err(_offending_key(exc, values, {}), str(exc)) from None
    return model_json, values, space


def _from_data(data: dict[str, Any], source: str, text: str, base: Path) -> Study:
    ctx = _Ctx(source)
    ctx.table(data, "<top>", _TOP_KEYS)
    name = data.get("name", Path(source).stem if source != "<dict>" else "study")
    if not isinstance(name, str):
        raise ctx.err("name", f"must be a string; got {name!r}")
    model_json: str | None = None
    tied_tab: dict[str, Any] = {}
    if "model" in data:
        model_json, values, space = _model_space(ctx, data, base)
        preset_name = None
    else:
        preset_name, values, tied_tab, space, model_json = _preset_space(ctx, data, base)

    # ---- axes / samples
    if ("axes" in data) == ("samples" in data):
        raise ctx.err("axes", "give exactly one of [axes] (grid) or [samples] (random / Latin hypercube)")
    if "distributions" in data and "samples" not in data:
        raise ctx.err("distributions", "needs [samples] (n, seed): distributions are sampled, not gridded")
    axes: tuple[GridAxis, ...] = ()
    ranges: tuple[SampleRange, ...] = ()
    n_samples, seed, method = 0, 0, ""
    if "axes" in data:
        tab = ctx.table(data["axes"], "axes")
        if not tab:
            raise ctx.err("axes", "empty: give at least one axis")
        axes = tuple(_grid_axis(ctx, k, v) for k, v in tab.items())
        kind, names = "grid", [a.name for a in axes]
    else:
        tab = ctx.table(data["samples"], "samples", ("method", "n", "seed", "ranges"))
        method = tab.get("method", "lhs")
        if method not in ("lhs", "random", "sobol"):
            raise ctx.err("samples.method", f"must be 'lhs', 'random' or 'sobol'; got {method!r}")
        if "n" not in tab:
            raise ctx.err("samples.n", "missing (number of samples)")
        n_samples = tab["n"]
        if not isinstance(n_samples, int) or isinstance(n_samples, bool) or n_samples <= 0:
            raise ctx.err("samples.n", f"the sample count must be a positive integer; got {n_samples!r}")
        if n_samples > _MAX_SAMPLES:
            raise ctx.err("samples.n", f"at most {_MAX_SAMPLES:.0e} samples; got {n_samples}")
        seed = tab.get("seed", 0)
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise ctx.err("samples.seed", f"must be a non-negative integer; got {seed!r}")
        rtab = ctx.table(tab.get("ranges", {}), "samples.ranges")
        dtab = ctx.table(data.get("distributions", {}), "distributions")
        if not rtab and not dtab:
            raise ctx.err("samples.ranges", "empty: give at least one parameter range (or [distributions])")
        rl = []
        for k, v in rtab.items():
            start, stop, _, log = _parse_range(ctx, f"samples.ranges.{k}", v, False)
            if not stop > start:
                raise ctx.err(f"samples.ranges.{k}", f"empty or reversed range {start!r}:{stop!r}")
            if log and start <= 0:
                raise ctx.err(f"samples.ranges.{k}", f"a log range needs positive bounds; got start = {start!r}")
            rl.append(SampleRange(k, start, stop, log))
        rl += _distributions(ctx, dtab, rtab, space) if dtab else []
        ranges = tuple(rl)
        kind, names = "samples", [r.name for r in ranges]
    prefix = "axes" if kind == "grid" else "samples.ranges"
    for n in names:
        if n == "sample":
            raise ctx.err(f"{prefix}.{n}", "'sample' is reserved for the sample dimension")
        try:
            space.check_axis(n)
        except ParameterError as exc:
            raise ctx.err(f"{prefix}.{n}", str(exc)) from None

    # ---- compute
    ctab = ctx.table(data.get("compute", {}), "compute", ("quantities", "critical_speed_range"))
    quantities = ctab.get("quantities", list(DEFAULT_QUANTITIES))
    if not isinstance(quantities, list) or not all(isinstance(q, str) for q in quantities):
        raise ctx.err("compute.quantities", f"must be a list of names; got {quantities!r}")
    from ..analysis.quantities import QUANTITIES as REGISTERED

    for q in quantities:
        if q not in REGISTERED or q == "status":
            allowed = [n for n in REGISTERED if n != "status"]
            raise ctx.err("compute.quantities", f"unknown quantity {q!r}; allowed: " + ", ".join(allowed))
    quant = tuple(q for q in REGISTERED if (q in quantities or q == "stable") and q != "status")
    crit = (1.0, 1e5)
    if "critical_speed_range" in ctab:
        cr = ctab["critical_speed_range"]
        if not (isinstance(cr, list) and len(cr) == 2):
            raise ctx.err("compute.critical_speed_range", f"must be [LO, HI] in rad/s; got {cr!r}")
        crit = (ctx.number(cr[0], "compute.critical_speed_range[0]"),
                ctx.number(cr[1], "compute.critical_speed_range[1]"))
        if not 0 < crit[0] < crit[1]:
            raise ctx.err("compute.critical_speed_range", f"needs 0 < LO < HI; got {cr!r}")
    if "critical_speed" in quant:
        from ..codegen import build
        from ..model.expressions import names_in

        spin = space.model.spin
        # a study file is an entry point: its model's engine is built where the file is read
        if not isinstance(spin, str) or not build(space.model).caps.omega_kernel:
            raise ctx.err("compute.quantities", f"'critical_speed' in sweeps needs the certified critical-speed "
                                                f"kernel (models with two coordinates, rate-free pads and the spin "
                                                f"as a parameter); model '{space.model.name}' has none: use "
                                                f"brakesqueal critical-speed --model {space.model.name}")
        if spin in names:
            raise ctx.err("compute.quantities", f"'critical_speed' searches along {spin}; {spin} cannot also be swept")
        if spin not in space.settable() or any(spin in names_in(e) for e in space.tied.values()):
            raise ctx.err("compute.quantities", f"'critical_speed' needs {spin} to be a settable parameter that no "
                                                "tie expression uses")

    # ---- execution / output
    shape = tuple(a.size for a in axes) if kind == "grid" else (n_samples,)
    n_points = math.prod(shape)
    per_point = 2 + 8 * sum(q in quant for q in ("margin", "max_real", "frequency", "critical_speed"))
    if n_points > MAX_POINTS:
        dims_txt = " x ".join(f"{a.name}={a.size}" for a in axes)
        raise ctx.err("axes", f"the grid has {n_points:.3g} points ({dims_txt}), more than the limit of "
                              f"{MAX_POINTS:.0e} points per study (its store would hold {_size(per_point * n_points)} "
                              "uncompressed); use fewer points or split the study")
    etab = ctx.table(data.get("execution", {}), "execution", ("chunk_points", "chunks"))
    eigen = any(q in quant for q in ("margin", "max_real", "frequency", "critical_speed"))
    points = DEFAULT_CHUNK_POINTS[1 if eigen else 0]
    if "chunk_points" in etab:
        points = ctx.integer(etab["chunk_points"], "execution.chunk_points", 1)
    chunks = _default_chunks(shape, points)
    if "chunks" in etab:
        dims = names if kind == "grid" else ["sample"]
        ch = ctx.table(etab["chunks"], "execution.chunks", tuple(dims))
        chunks = tuple(min(ctx.integer(ch[d], f"execution.chunks.{d}", 1), s) if d in ch else c
                       for d, c, s in zip(dims, chunks, shape))
    ckey = "execution.chunks" if "chunks" in etab else "execution.chunk_points"
    heavy = eigen or kind == "samples" or model_json is not None
    limit = MAX_CHUNK_POINTS[1 if heavy else 0]
    if math.prod(chunks) > limit:
        mem = _size(math.prod(chunks) * (600 if heavy else 3 + per_point))
        raise ctx.err(ckey, f"chunks of {math.prod(chunks)} points exceed the limit of {limit} points per chunk "
                            f"for this study (each chunk is computed in memory: about {mem}); give smaller chunks")
    n_chunks = math.prod(-(-s // c) for s, c in zip(shape, chunks))
    if n_chunks > MAX_CHUNKS:
        raise ctx.err(ckey, f"{n_chunks} chunks exceed the limit of {MAX_CHUNKS:.0e} chunks per study (one "
                            "completion marker file each); give larger chunks")
    otab = ctx.table(data.get("output", {}), "output", ("store",))
    store = otab.get("store")
    if store is not None:
        if not isinstance(store, str) or not store:
            raise ctx.err("output.store", f"must be a path; got {store!r}")
        if not Path(store).is_absolute():
            store = str(base / store)
    desc = data.get("description", "")
    if not isinstance(desc, str):
        raise ctx.err("description", f"must be a string; got {desc!r}")
    return Study(source=source, text=text, name=name, preset=preset_name, values=values, tied=dict(tied_tab),
                 kind=kind, axes=axes, ranges=ranges, n_samples=n_samples, seed=seed, method=method,
                 quantities=quant, critical_speed_range=crit, chunks=chunks, store=store, model=model_json)
