"""The Zarr result store of a study: layout, provenance, per-chunk completion markers, verification.

Layout (Zarr format 3, one directory)::

    STORE/zarr.json                 group; attributes: study text, study hash, package version, ...
    STORE/<dim>/                    coordinates (grid axes, or ``sample`` + sampled names)
    STORE/stable, status, ...       data variables, chunked exactly like the study
    STORE/_sweep_chunks/<id>.json   completion marker of chunk ``id``: its region and the
                                    BLAKE2b checksum of every variable's values

A chunk's data are written first and its marker last (temporary file +
``os.replace``, so a marker is either complete or absent).  On resume every
marker is verified by reading the chunk back and comparing checksums; a chunk
whose data are truncated, corrupt or missing is recomputed.  Only the process
that runs :func:`~brakesqueal.sweep.sweep` writes to the store.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from .compute import FLOAT_QUANTITIES

__all__ = ["MARKERS", "study_attrs", "variable_attrs", "create_store", "open_store", "write_chunk", "completed_chunks", "verified_chunks",
           "remove_store", "checksum"]

MARKERS = "_sweep_chunks"
_STATUS_MEANINGS = ("not_computed ok ok_nontrivial_silent_motion no_silent_motion pad_loses_contact invalid_parameters"
                    " undecided")


def _units(name: str) -> str:
    from ..results import _units as u

    return u(name)


def checksum(a: np.ndarray) -> str:
    """BLAKE2b-128 of an array's values (C order)."""
    return hashlib.blake2b(np.ascontiguousarray(a).tobytes(), digest_size=16).hexdigest()


def _variables(study: Any) -> list[str]:
    return ["stable", "status", *[q for q in FLOAT_QUANTITIES if q in study.quantities]]


def _compressor() -> Any:
    from zarr.codecs import ZstdCodec

    return ZstdCodec(level=1, checksum=True)


def study_attrs(study: Any) -> dict[str, Any]:
    """Provenance attributes stored with the results (study text and hash, package version, ...)."""
    from .. import __version__

    space = study.space()
    return {
        "title": f"brakesqueal parameter study '{study.name}'",
        "brakesqueal_version": __version__,
        "study_hash": study.hash(),
        "study_file": study.source,
        "study_text": study.text,
        "study_kind": study.kind,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "space": space.label,
        "settings": json.dumps({k: str(v) for k, v in space.definitions().items()}),
        "tied": json.dumps(dict(space.tied)),
        "criterion": "Lienard-Chipart on det(lambda^2 M + lambda D + K) (exact sign test)",
        "chunk_shape": list(study.chunks),
        "n_chunks": study.n_chunks,
    }


def variable_attrs(study: Any) -> dict[str, dict[str, Any]]:
    """Attributes of every data variable."""
    extra = {"coordinates": " ".join(study.sample_names)} if study.kind == "samples" else {}
    out = {"stable": {"long_name": "silent motion asymptotically stable (Hurwitz)", **extra},
           "status": {"flag_values": list(range(-1, 6)), "flag_meanings": _STATUS_MEANINGS, **extra}}
    for q, qa in FLOAT_QUANTITIES.items():
        if q in study.quantities:
            out[q] = {**qa, **extra}
    return out


def create_store(path: Path, study: Any) -> Any:
    """Create the store: metadata, coordinates and empty (fill-valued) variables."""
    import zarr

    dims, shape, chunks = study.dims, study.shape, study.chunks
    attrs = study_attrs(study)
    g = zarr.open_group(str(path), mode="w-", zarr_format=3, attributes=attrs)
    if study.kind == "grid":
        for ax in study.axes:
            a = g.create_array(ax.name, shape=(ax.size,), dtype="f8", chunks=(ax.size,), dimension_names=(ax.name,),
                               attributes={"units": _units(ax.name), "scale": ax.scale})
            a[:] = ax.values
    else:
        n = study.n_samples
        a = g.create_array("sample", shape=(n,), dtype="i8", chunks=(chunks[0],), dimension_names=("sample",),
                           attributes={"long_name": "sample number"})
        a[:] = np.arange(n)
        for name, vals in study.samples().items():
            r = next(r for r in study.ranges if r.name == name)
            a = g.create_array(name, shape=(n,), dtype="f8", chunks=(chunks[0],), dimension_names=("sample",),
                               attributes={"units": _units(name), "scale": "log" if r.log else "linear",
                                           "sampling": f"{study.method} seed={study.seed}"})
            a[:] = vals
    va = variable_attrs(study)
    comp = _compressor()
    g.create_array("stable", shape=shape, dtype="bool", chunks=chunks, dimension_names=dims, fill_value=False,
                   compressors=comp, attributes=va["stable"])
    g.create_array("status", shape=shape, dtype="i1", chunks=chunks, dimension_names=dims, fill_value=-1,
                   compressors=comp, attributes=va["status"])
    for q in FLOAT_QUANTITIES:
        if q in study.quantities:
            g.create_array(q, shape=shape, dtype="f8", chunks=chunks, dimension_names=dims, fill_value=np.nan,
                           compressors=comp, attributes=va[q])
    g.create_group(MARKERS, attributes={"description": "completion markers: <chunk>.json, written after the data"})
    return g


def open_store(path: Path, study: Any, *, overwrite: bool) -> Any:
    """Open the store of ``study`` at ``path``, creating it if needed.

    Raises ParameterError (one line, naming the store) if ``path`` holds
    something else, or results of a different study, unless ``overwrite``.
    """
    import zarr

    if path.exists():
        if overwrite:
            remove_store(path)
        else:
            check_study(_existing(path), path, study)
            g = zarr.open_group(str(path), mode="r+", zarr_format=3)
            if MARKERS not in g:
                g.create_group(MARKERS)
            return g
    path.parent.mkdir(parents=True, exist_ok=True)
    return create_store(path, study)


def _existing(path: Path) -> Any:
    import zarr

    if not (path / "zarr.json").is_file():
        raise ParameterError(f"'{path}' exists and is not a brakesqueal sweep store; "
                             "choose another store (--out) or remove it")
    try:
        g = zarr.open_group(str(path), mode="r", zarr_format=3)
    except Exception as exc:  # noqa: BLE001 - any unreadable store is reported the same way
        raise ParameterError(f"store '{path}' cannot be read ({type(exc).__name__}: {exc})") from None
    if "study_hash" not in g.attrs:
        raise ParameterError(f"store '{path}' is not a brakesqueal sweep store (no key 'study_hash'); "
                             "pass --overwrite to replace it")
    return g


def check_study(g: Any, path: Path, study: Any) -> None:
    """Raise ParameterError unless the store at ``path`` was written by ``study``."""
    h = g.attrs.get("study_hash")
    if h != study.hash():
        raise ParameterError(
            f"store '{path}' holds results of a different study (key 'study_hash' = {str(h)[:12]}..., "
            f"this study {study.hash()[:12]}..., written from '{g.attrs.get('study_file', '?')}'); "
            "pass --overwrite to replace it or choose another store")


def remove_store(path: Path) -> None:
    """Delete a store directory, refusing anything that does not look like a Zarr store."""
    if path.is_dir() and ((path / "zarr.json").is_file() or not any(path.iterdir())):
        shutil.rmtree(path)
    elif path.exists():
        raise ParameterError(f"refusing to overwrite '{path}': it is not a Zarr store")


def write_chunk(g: Any, path: Path, study: Any, chunk: int, result: dict[str, np.ndarray]) -> None:
    """Write one chunk's data, then its completion marker (atomically)."""
    region = study.region(chunk)
    sums = {}
    for name in _variables(study):
        data = result[name]
        g[name][region] = data
        sums[name] = checksum(data)
    marker = {"chunk": chunk, "region": [[s.start, s.stop] for s in region], "checksums": sums}
    d = path / MARKERS
    tmp = d / f".{chunk}.{os.getpid()}.tmp"
    tmp.write_text(json.dumps(marker), encoding="utf-8")
    os.replace(tmp, d / f"{chunk}.json")


def completed_chunks(path: Path) -> dict[int, dict[str, Any]]:
    """Markers found in the store (unverified): chunk id -> marker."""
    out: dict[int, dict[str, Any]] = {}
    d = path / MARKERS
    if not d.is_dir():
        return out
    for f in d.glob("[0-9]*.json"):
        try:
            m = json.loads(f.read_text(encoding="utf-8"))
            out[int(m["chunk"])] = m
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return out


def verified_chunks(g: Any, path: Path, study: Any, *, remove_bad: bool = True) -> tuple[set[int], set[int]]:
    """Verify every marker against the data: ``(good, bad)`` chunk ids; bad markers are removed if asked."""
    good, bad = set(), set()
    names = _variables(study)
    for chunk, m in sorted(completed_chunks(path).items()):
        ok = 0 <= chunk < study.n_chunks and m.get("region") == [[s.start, s.stop] for s in study.region(chunk)]
        if ok:
            region = study.region(chunk)
            try:
                ok = all(checksum(np.asarray(g[n][region])) == m["checksums"].get(n) for n in names)
            except Exception:  # noqa: BLE001 - truncated / corrupt chunk files raise codec-specific errors
                ok = False
        if ok:
            good.add(chunk)
        else:
            bad.add(chunk)
            if not remove_bad:
                continue
            try:
                (path / MARKERS / f"{chunk}.json").unlink()
            except OSError:
                pass
    return good, bad
