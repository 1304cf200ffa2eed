r"""Built-in finite-element squeal models: the public disk-brake benchmark matrices shipped with brakesqueal.

Both are quadratic eigenvalue problems of industrial disk brakes from the group
of the source paper's second author (TU Berlin; Gräbner, Mehrmann, Quraishi,
Schröder & von Wagner, "Numerical methods for parametric model reduction in the
simulation of disc brake squeal", ZAMM 96 (12) (2016) 1388–1405), in scaled
units, studied for 2π ≤ Ω ≤ 8π rad/s.  The matrices and their BSD licences are
in ``brakesqueal/data/fe/``.  Each model adds a friction scale ``s``
multiplying the friction matrices (1: the published model), so that maps over
(Ω, s) show where friction makes the brake squeal.

============== ======= ==================================================================
name           DOF     coefficients
============== ======= ==================================================================
disk_brake100  100     ``M``; ``D1 + s DR/Ω + Ω DG``; ``K1 + s KR`` (NLEVP ``disk_brake100``)
disk_brake4669 4669    ``M1``; ``D1 + s DR Ω_ref/Ω + DG Ω/Ω_ref + D4/F_ref``;
                       ``K1 + s KR + KGeo (Ω/Ω_ref)²`` with Ω_ref = 1, F_ref = 1600 (sparse)
============== ======= ==================================================================
"""

from __future__ import annotations

import math
import os
from functools import lru_cache
from importlib import resources

from ..errors import ParameterError
from .matrices import MatrixSpec

__all__ = ["FE_MODELS", "FE_DOF", "fe_model", "fe_data_dir"]

#: Coordinates of each built-in finite-element model (without reading its matrices).
FE_DOF = {"disk_brake100": 100, "disk_brake4669": 4669}

_FRICTION_SCALE = "friction scale: multiplies the friction matrices (1 = the published model)"

#: name -> (folder, files, coefficients, description)
FE_MODELS: dict[str, tuple[str, tuple[str, ...], dict[str, str], str]] = {
    "disk_brake100": (
        "nlevp-disk-brake-100", ("disk_brake100.mat",),
        {"M": "M", "D": "D1 + s*DR/Omega + Omega*DG", "K": "K1 + s*KR"},
        "NLEVP disk_brake100: a 100-DOF disk brake (dense), D = D1 + DR/Omega + Omega DG, K = K1 + KR"),
    "disk_brake4669": (
        "tu-berlin-disk-brake-4669",
        ("BMLL00.mat", "BDLL00.mat", "BYLL00.mat", "BDIWLL00.mat", "BHLL00.mat", "BKLL00.mat", "BKQLL00.mat",
         "BWLL00.mat"),
        {"M": "BMLL", "D": "BDLL + s*BDIWLL/Omega + Omega*BYLL + BHLL/1600", "K": "BKLL + s*BKQLL + Omega**2*BWLL"},
        "TU Berlin 4669-DOF disk brake (sparse): D = D1 + DR/Omega + Omega DG + D4/1600, "
        "K = K1 + KR + Omega^2 KGeo"),
}


def fe_data_dir() -> str:
    """The folder of the shipped finite-element benchmark matrices (``brakesqueal/data/fe``)."""
    return str(resources.files("brakesqueal").joinpath("data", "fe"))


@lru_cache(maxsize=4)
def fe_model(name: str) -> MatrixSpec:
    """A built-in finite-element model (module table), its matrices read from the shipped files.

    Parameters
    ----------
    name : str
        ``"disk_brake100"`` or ``"disk_brake4669"``.

    Returns
    -------
    MatrixSpec
        Parameters ``Omega`` (default 2π rad/s) and ``s`` (default 1).
    """
    from .matrix_files import read_matrix_file

    if name not in FE_MODELS:
        from ..suggest import did_you_mean

        raise ParameterError(f"unknown finite-element model {name!r}{did_you_mean(name, list(FE_MODELS))}; "
                             f"built-in ones: {', '.join(FE_MODELS)}")
    folder, files, coeffs, desc = FE_MODELS[name]
    base = os.path.join(fe_data_dir(), folder)
    mats = {}
    sources = []
    for f in files:
        mf = read_matrix_file(os.path.join(base, f), "mat")
        mats.update(mf.matrices)
        sources.append({"file": os.path.join(base, f), "format": "mat"})
    return MatrixSpec(name=name, matrices=mats, coefficients=coeffs, parameters={"Omega": 2 * math.pi, "s": 1.0},
                      ranges={"s": (0.0, 1e3)}, descriptions={"s": _FRICTION_SCALE}, spin="Omega",
                      description=desc, sources=tuple(sources),
                      reference="Gräbner, Mehrmann, Quraishi, Schröder, von Wagner, ZAMM 96(12) (2016) 1388-1405; "
                                "NLEVP (Betcke, Higham, Mehrmann, Negri Porzio, Schröder, Tisseur)")
