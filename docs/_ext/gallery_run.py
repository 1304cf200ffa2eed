"""Sphinx extension: the figure gallery, made by running the documented commands at build time.

``builder-inited`` runs every command of :data:`COMMANDS` (the ``brakesqueal``
command line, in a fresh process, as a user runs it) into
``docs/_generated/gallery/`` — so ``make docs`` regenerates every figure from
the code being documented — and ``.. brakesqueal-gallery-run::`` shows each
figure under its command.  A command that fails is a Sphinx warning, hence an
error under ``-W``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

OUT = "_generated/gallery"

#: (title, figure file, arguments of ``brakesqueal``, what it shows)
COMMANDS: list[tuple[str, str, list[str], str]] = [
    ("Stability map (paper's Fig. 2)", "map.svg",
     ["map", "--x", "k_ip=1e5:1e10:400:log", "--y", "mu=0.05:1:300", "--out", "map.nc", "--plot", "map.svg"],
     "Certified verdicts of the paper's model over the tangential stiffness and the friction coefficient, with the "
     "stability boundary located by bisection onto it (points A and B lie on the line mu = 0.5)."),
    ("Stability map coloured by max Re λ", "map-max-real.png",
     ["map", "--x", "k_ip=1e5:1e10:400:log", "--y", "mu=0.05:1:300", "--out", "map2.nc", "--plot",
      "map-max-real.png", "--color", "max_real"],
     "The same map coloured by the largest real part of the eigenvalues (symmetric log scale)."),
    ("Stability map of a built model", "map-eight-dof.png",
     ["map", "--model", "eight-dof", "--x", "Omega=5:200:80:log", "--y", "N0=500:5000:40", "--out", "map8.nc",
      "--plot", "map-eight-dof.png"],
     "Any model gets the same map: here the eight-DOF model with pad and caliper masses."),
    ("Crossings along a path", "crossings.svg",
     ["crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.5", "--plot", "crossings.svg"],
     "Largest real part along k_ip at mu = 0.5 with the exact stability changes (points B and A)."),
    ("Critical speeds", "critical-speed.svg",
     ["critical-speed", "--preset", "paper-fig3", "--set", "mu1=0.6", "--set", "mu2=0.4", "--plot",
      "critical-speed.svg"],
     "Onset and re-stabilisation of squeal along the spin rate for asymmetric friction."),
    ("Squeal region (paper's Fig. 3)", "fig3.png", ["reproduce", "fig3", "--out", "."],
     "The critical speed versus the friction asymmetry, joined with the re-stabilisation speeds into closed "
     "squeal regions whose tips are located by bisection."),
    ("Squeal regions in two parameters (Fig. 3's set)", "region.png",
     ["region", "--preset", "paper-fig3", "--set", "k_ip=inf", "--set", "mu2=0.5", "--x", "mu1=0:1", "--y",
      "Omega=10:20000:log", "--no-progress", "--plot", "region.png"],
     "The Hopf curve over the certified map, supercritical (blue) at the onset and subcritical (red) at the upper "
     "re-stabilisation, joined at a generalised-Hopf point (GH); the fold-of-cycles slices from GH find the "
     "cycles losing contact (crosses) before they fold."),
    ("Mode coupling", "modes.svg",
     ["modes", "--along", "mu=0.05:1", "--out", "modes.nc", "--plot", "modes.svg"],
     "Frequencies and real parts of the modes along mu, tracked by eigenvector correlation; the dashed line "
     "marks the onset of squeal."),
    ("Limit cycles after onset", "cycles.png",
     ["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--along", "Omega=30:40",
      "--max-points", "25", "--plot", "cycles.png"],
     "The supercritical Hopf branch of the paper's model continued in Omega up to the first contact loss."),
    ("Nonlinear simulation", "simulate.png",
     ["simulate", "--preset", "paper-fig2", "--set", "mu=1", "--t-end", "0.5", "--no-progress", "--plot",
      "simulate.png"],
     "Time history with its envelope, phase portrait of the last periods and spectrum of a growing squeal."),
]


def run_commands(app: Sphinx) -> None:
    """Run every gallery command into ``docs/_generated/gallery`` (fresh processes, the package under test)."""
    out = Path(app.srcdir) / OUT
    out.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "MPLBACKEND": "Agg", "BRAKESQUEAL_PROGRESS_EVERY": "1e9"}
    src = str(Path(app.srcdir).parent / "src")
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")

    def run(fig: str, args: list[str]) -> tuple[str, list[str], subprocess.CompletedProcess[str], float]:
        t0 = time.perf_counter()
        r = subprocess.run([sys.executable, "-m", "brakesqueal", *args], cwd=out, env=env, capture_output=True,
                           text=True, timeout=900)
        return fig, args, r, time.perf_counter() - t0

    # two commands at a time (each writes its own files): the build machines have two cores
    with ThreadPoolExecutor(max(1, min(2, os.cpu_count() or 1))) as pool:
        done = list(pool.map(lambda c: run(c[1], c[2]), COMMANDS))
    for fig, args, r, dt in done:
        if r.returncode != 0 or not (out / fig).exists():
            logger.warning("gallery: 'brakesqueal %s' failed (%s): %s", " ".join(args), r.returncode,
                           r.stderr.strip().splitlines()[-1:] or "")
        else:
            logger.info("gallery: %s in %.1f s", fig, dt)


class GalleryRunDirective(SphinxDirective):
    """``.. brakesqueal-gallery-run::`` — every generated figure under its title and command."""

    def run(self) -> list[Any]:
        lines: list[str] = []
        for title, fig, args, what in COMMANDS:
            shown = " ".join(a if " " not in a else repr(a) for a in args)
            lines += [title, "-" * len(title), "", what, "", ".. code-block:: console", "   :class: bs-command", "",
                      f"   $ brakesqueal {shown}", "", f".. image:: /{OUT}/{fig}", "   :width: 100%", ""]
        node_list: list[Any] = []
        from docutils import nodes

        container = nodes.section()
        nested_parse_with_titles(self.state, StringList(lines, source="gallery"), container)
        node_list.extend(container.children)
        return node_list


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the command runner and the directive."""
    app.connect("builder-inited", run_commands)
    app.add_directive("brakesqueal-gallery-run", GalleryRunDirective)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
