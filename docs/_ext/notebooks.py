"""Sphinx extension: the tutorial notebooks of ``examples/`` in the docs, executed by myst-nb.

The notebooks are committed without outputs (``tests/test_notebooks.py``) and live outside the
documentation's source folder.  At ``config-inited`` this extension

* copies ``examples/*.ipynb`` into ``docs/examples/`` (a file is rewritten only when it changed, copies of
  deleted notebooks are removed; ``docs/examples/.gitignore`` keeps the copies out of git), where the
  toctree of ``docs/examples/index.md`` lists them;
* writes a kernel spec for this interpreter (``sys.executable``, ``MPLBACKEND=Agg``) to
  ``docs/_build/.kernels`` and puts it first on ``JUPYTER_PATH``, so that myst-nb runs the notebooks
  with the package being documented and never with a reader's own ``python3`` kernel
  (``nb_kernel_rgx_aliases`` in ``conf.py`` maps ``python3`` to it);
* points myst-nb's execution cache (``nb_execution_mode = "cache"``) at
  ``docs/_build/.jupyter_cache/<hash of src/brakesqueal>``: a notebook is executed again when it or the
  package's source changed, and a rebuild with neither changed reuses the outputs.  Caches of older
  sources are deleted.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx
from sphinx.config import Config
from sphinx.util import logging

logger = logging.getLogger(__name__)

#: Name of the kernel the notebooks run in (``conf.py`` aliases their ``python3`` to it).
KERNEL = "brakesqueal-docs"
#: Folder of the copies, relative to the documentation's source folder.
TARGET = "examples"


def source_hash(src: Path) -> str:
    """A short hash of every file of the package's source (names and contents), caches excluded."""
    h = hashlib.sha256()
    for f in sorted(p for p in src.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        h.update(f.relative_to(src).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def copy_notebooks(examples: Path, target: Path) -> list[str]:
    """Copy ``examples/*.ipynb`` into ``target`` (unchanged files untouched, stale copies removed)."""
    target.mkdir(parents=True, exist_ok=True)
    names = sorted(p.name for p in examples.glob("*.ipynb"))
    for name in names:
        src, dst = examples / name, target / name
        if not dst.exists() or dst.read_bytes() != src.read_bytes():
            shutil.copyfile(src, dst)
    for stale in target.glob("*.ipynb"):
        if stale.name not in names:
            stale.unlink()
    return names


def write_kernel(root: Path) -> Path:
    """A kernel spec ``KERNEL`` for this interpreter under ``root/kernels``; returns ``root``."""
    spec = root / "kernels" / KERNEL
    spec.mkdir(parents=True, exist_ok=True)
    (spec / "kernel.json").write_text(json.dumps({
        # errors only: a kernel started by a build says nothing else (its warning about TCP on the loopback is noise)
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}", "--IPKernelApp.log_level=40"],
        "display_name": "brakesqueal docs", "language": "python",
        "env": {"MPLBACKEND": "Agg", "PYDEVD_DISABLE_FILE_VALIDATION": "1"},
    }, indent=1))
    return root


def prepare(app: Sphinx, config: Config) -> None:
    """``config-inited``: copy the notebooks, register the kernel, choose the execution cache."""
    srcdir = Path(app.srcdir)
    repo = srcdir.parent
    names = copy_notebooks(repo / "examples", srcdir / TARGET)
    if not names:
        logger.warning("notebooks: no examples/*.ipynb found next to the docs")
    build = srcdir / "_build"
    kernels = write_kernel(build / ".kernels")
    os.environ["JUPYTER_PATH"] = os.pathsep.join(
        [str(kernels)] + [p for p in os.environ.get("JUPYTER_PATH", "").split(os.pathsep) if p])
    if not config.nb_execution_cache_path:
        caches = build / ".jupyter_cache"
        current = caches / source_hash(repo / "src" / "brakesqueal")
        if caches.is_dir():
            for old in caches.iterdir():
                if old != current:
                    shutil.rmtree(old, ignore_errors=True)
        config.nb_execution_cache_path = str(current)


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the hook (myst-nb itself is in ``conf.py``'s extensions)."""
    app.connect("config-inited", prepare)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
