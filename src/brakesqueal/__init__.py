"""brakesqueal: derive, linearize and analyse wobbling-disk models of disk-brake squeal.

The public API follows the layers of the package:

* :func:`derive_equations` — nonlinear equations of motion (paper eqs. 2-45),
* :func:`closed_form` — closed-form ``Mbar, Dbar, Kbar`` about the trivial
  silent motion (eqs. 47-61),
* :class:`ModelSpec`, :func:`get_model`, :func:`load_model` — models (the
  paper's and any other), :class:`Parameters`, :func:`get_preset`,
  :class:`ParameterSpace`, :func:`resolve_space` — validated parameter sets,
  presets and parameter spaces,
* :func:`silent_motion`, :func:`linearize` — numeric silent motion and linear
  model (eqs. 46-48) of any model,
* :func:`stability_map`, :func:`crossings`, :func:`critical_speeds` — the
  stability routes of every model (closed-form kernels where the model allows
  them, certified per-point eigenvalue verdicts otherwise),
* :func:`simulate`, :func:`hopf_points`, :func:`limit_cycles` — the nonlinear
  time simulation and the nonlinear analysis after onset (:mod:`.api_nonlinear`).

Heavy symbolic modules are imported lazily.  Every public function checks
its arguments against its type hints before it runs
(:func:`brakesqueal.validation.validated`): a wrong argument is one
:class:`ParameterError` line naming it.
"""

from __future__ import annotations

from typing import Any

from .errors import BrakesquealError, BrakesquealWarning, ParameterError, SilentMotionError

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "BrakesquealError",
    "BrakesquealWarning",
    "ParameterError",
    "SilentMotionError",
    "Parameters",
    "Preset",
    "PRESETS",
    "get_preset",
    "resolve_parameters",
    "resolve_space",
    "derive_equations",
    "closed_form",
    "engine",
    "evaluate",
    "write_map",
    "modes_along",
    "silent_motion",
    "SilentMotion",
    "linearize",
    "LinearModel",
    "pad_rate_eigenvalues",
    "simulate",
    "simulation_model",
    "Trajectory",
    "SimulationModel",
    "hopf_points",
    "limit_cycles",
    "squeal_branch",
    "harmonic_branch",
    "model_system",
    "model_piecewise_system",
    "exact_lyapunov",
    "model_flow",
    "ModelSpec",
    "Disk",
    "Pad",
    "Caliper",
    "FrictionLaw",
    "get_model",
    "load_model",
    "build_equations",
    "stability_map",
    "evaluate_point",
    "crossings",
    "critical_speeds",
    "critical_speeds_many",
    "eigen_analysis",
    "EigenAnalysis",
    "Verdict",
    "ParameterSpace",
    "Axis",
    "StabilityMap",
    "CrossingResult",
    "CriticalSpeedResult",
    "open_map",
    "sweep_status",
    "open_sweep",
    "load_study",
    "Study",
    "SweepStatus",
    "run_sweep",
    "plot_sweep",
    "parse_axis",
    "export_code",
    "import_matrices",
    "box_eigenvalues",
    "reduce_matrix_model",
    "reproduce_fig2",
    "reproduce_fig3",
    "run_uq",
    "hopf_curves",
    "region_diagram",
    "robust_box",
    "run_design",
]

_LAZY = {
    "Parameters": "model",
    "Preset": "model",
    "PRESETS": "model.library",
    "get_preset": "model",
    "resolve_parameters": "model",
    "resolve_space": "model",
    "derive_equations": "symbolic.model",
    "closed_form": "symbolic.linearize",
    "silent_motion": "api",
    "SilentMotion": "analysis.equilibrium",
    "engine": "api",
    "evaluate": "api",
    "write_map": "api",
    "modes_along": "api",
    "linearize": "api",
    "LinearModel": "analysis.linear",
    "pad_rate_eigenvalues": "api",
    "simulate": "api_nonlinear",
    "simulation_model": "api_nonlinear",
    "hopf_points": "api_nonlinear",
    "limit_cycles": "api_nonlinear",
    "squeal_branch": "api_nonlinear",
    "harmonic_branch": "api_nonlinear",
    "model_system": "api_nonlinear",
    "model_piecewise_system": "api_nonlinear",
    "exact_lyapunov": "api_nonlinear",
    "model_flow": "api_nonlinear",
    "Trajectory": "simulation",
    "SimulationModel": "simulation",
    "ModelSpec": "model",
    "Disk": "model",
    "Pad": "model",
    "Caliper": "model",
    "FrictionLaw": "model",
    "get_model": "model",
    "load_model": "model",
    "build_equations": "symbolic.assemble",
    "stability_map": "api",
    "evaluate_point": "api",
    "crossings": "api",
    "critical_speeds": "api",
    "critical_speeds_many": "api",
    "eigen_analysis": "api",
    "EigenAnalysis": "analysis.eigen",
    "Verdict": "analysis.eigen",
    "ParameterSpace": "model",
    "Axis": "analysis.maps",
    "StabilityMap": "results",
    "CrossingResult": "results",
    "CriticalSpeedResult": "results",
    "open_map": "results",
    "sweep_status": "sweep",
    "open_sweep": "sweep",
    "load_study": "sweep",
    "Study": "sweep",
    "SweepStatus": "sweep",
    "run_sweep": "sweep",
    "plot_sweep": "sweep",
    "parse_axis": "analysis.maps",
    "export_code": "export",
    "import_matrices": "model.matrices",
    "box_eigenvalues": "api",
    "reduce_matrix_model": "api",
    "reproduce_fig2": "reproduce",
    "reproduce_fig3": "reproduce",
    "run_uq": "uq",
    "hopf_curves": "api_nonlinear",
    "region_diagram": "api_nonlinear",
    "robust_box": "api",
    "run_design": "design",
}


_CHECKED: dict[str, Any] = {}


def __getattr__(name: str) -> Any:
    if name in _CHECKED:
        return _CHECKED[name]
    if name in _LAZY:
        import importlib
        import types

        obj = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        if isinstance(obj, types.FunctionType) and not obj.__dict__.get("__validated__"):
            from .validation import validated  # every public function checks its arguments against its hints

            obj = _CHECKED[name] = validated(obj)
        return obj
    raise AttributeError(f"module 'brakesqueal' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
