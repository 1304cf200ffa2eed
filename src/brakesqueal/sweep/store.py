"""The Zarr result store of a study: layout, creation record, verification, repair, completion markers.

Layout (Zarr format 3, one directory)::

    STORE/zarr.json                 group; attributes: study text, study hash, package version, ...;
                                    consolidated metadata of every node
    STORE/<dim>/                    coordinates (grid axes, or ``sample`` + sampled names)
    STORE/stable, status, ...       data variables, chunked exactly like the study
    STORE/_sweep_chunks/<id>.json   completion marker of chunk ``id``: its region and the
                                    BLAKE2b checksum of every variable's values
    STORE/_sweep_chunks/_creation.json
                                    creation record: the exact metadata (``zarr.json``) of every
                                    node and the checksum of every coordinate array
    STORE/_sweep_chunks/.brakesqueal-store
                                    ownership marker (JSON: kind, format, study hash; beside
                                    the chunk markers, where Zarr readers do not look)

**Only our own stores are ever deleted.**  ``--overwrite`` (:func:`remove_store`)
deletes a directory only if this package made it (:func:`is_own_store`: its
marker, its creation record, or, for stores of versions before the marker,
metadata naming a study hash and a brakesqueal version); anything else, a
directory that merely holds a file named ``zarr.json`` or another program's
Zarr store, is refused in one line and left as it is.

**Creation is atomic.**  The skeleton (metadata, coordinates, consolidated
metadata, creation record last) is built in a hidden sibling directory
``.STORE.creating-*`` and renamed into place, so a store either does not exist
or is complete; an interrupted creation leaves only the sibling, removed by
the next run.

**Every array is verified.**  Metadata and coordinates are checked against the
creation record (coordinates are also recomputed from the study and compared),
data chunks against their markers.  Damaged metadata or coordinates are
rewritten (they follow from the study); damaged data chunks are recomputed.
All reads use the metadata of the creation record, so a deleted or damaged
``zarr.json`` on disk never changes what is read.  A marker is only ever
replaced by a newer one (never deleted), so a failed run never loses
completed chunks.

**Writes are atomic per file** (:func:`write_file`: temporary file +
``os.replace``): data chunks first, the chunk's marker last.  Only the process
that holds the store's lock (:mod:`.lock`) writes.
"""

from __future__ import annotations

import asyncio
import errno
import hashlib
import json
import os
import shutil
import tempfile
import time
import uuid
import warnings
from contextlib import suppress
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..labels import unit
from ..status import PointStatus

if TYPE_CHECKING:
    import zarr
    from zarr.codecs import ZstdCodec

    from .study import Study

__all__ = ["StoreError", "MARKERS", "MANIFEST", "STORE_MARKER", "is_own_store", "check_overwrite", "study_attrs",
           "variable_attrs", "coordinates", "create_store", "prepare_store", "inspect_store", "check_skeleton",
           "read_manifest", "open_group", "write_chunk", "write_file", "completed_chunks", "verified_chunks",
           "remove_store", "check_location", "check_writable", "checksum", "StoreCheck", "io_error"]

MARKERS = "_sweep_chunks"
MANIFEST = f"{MARKERS}/_creation.json"
#: Ownership marker written into every store this package creates (see :func:`is_own_store`).
STORE_MARKER = f"{MARKERS}/.brakesqueal-store"
_FORMAT = "brakesqueal-sweep-store/1"
_STORE_KIND = "brakesqueal sweep store"
#: ``status`` codes (:class:`~brakesqueal.status.PointStatus`); chunks not yet written read as ``NOT_COMPUTED``.
_STATUS_FILL = int(PointStatus.NOT_COMPUTED)


class StoreError(BrakesquealError):
    """A sweep store cannot be created, locked, read, repaired or written (one line naming the store)."""


class _NotWritable(StoreError):
    """The store's location cannot be written (a complete store may still be read)."""


def checksum(a: np.ndarray) -> str:
    """BLAKE2b-128 of an array's values (C order)."""
    return hashlib.blake2b(np.ascontiguousarray(a).tobytes(), digest_size=16).hexdigest()


def _variables(study: Study) -> list[str]:
    return list(study.variables())


def _compressor() -> ZstdCodec:
    from zarr.codecs import ZstdCodec

    return ZstdCodec(level=1, checksum=True)


# ---------------------------------------------------------------- errors
_WHY = {errno.ENOSPC: "no space left on device", errno.EDQUOT: "disk quota exceeded",
        errno.EROFS: "read-only file system", errno.EACCES: "permission denied", errno.EPERM: "permission denied"}


def io_error(exc: OSError, doing: str, path: Path, *, resume: bool = True) -> StoreError:
    """One-line :class:`StoreError` for an I/O error while ``doing`` something to the store ``path``."""
    why = _WHY.get(exc.errno or 0) or (exc.strerror or str(exc) or type(exc).__name__).lower()
    tail = "; completed chunks are kept: fix this and run the same command again to resume" if resume else ""
    cls = _NotWritable if exc.errno in (errno.EROFS, errno.EACCES, errno.EPERM) else StoreError
    return cls(f"{why} while {doing} of store '{path}'{tail}")


# ---------------------------------------------------------------- file writes
def write_file(path: Path, data: Any) -> None:
    """Write ``data`` (bytes-like) to ``path`` atomically: a temporary sibling file, then ``os.replace``.

    Every file of a store is written through this function (Zarr chunks and
    metadata via the store class, markers and the creation record directly).
    """
    tmp = path.parent / f".{path.name}.{uuid.uuid4().hex[:12]}.partial"
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        with suppress(OSError):
            tmp.unlink()
        raise


def _zarr_store_class() -> type:
    from zarr.core.buffer import default_buffer_prototype
    from zarr.storage import LocalStore

    class SweepZarrStore(LocalStore):
        """LocalStore writing through :func:`write_file`, optionally reading ``zarr.json`` from a fixed record."""

        def __init__(self, root: Any, *, read_only: bool = False, metadata: dict[str, str] | None = None) -> None:
            super().__init__(root, read_only=read_only)
            self.metadata = metadata or {}

        def with_read_only(self, read_only: bool = False) -> Any:
            return type(self)(self.root, read_only=read_only, metadata=self.metadata)

        def _pinned(self, key: str, prototype: Any) -> Any:
            return (prototype or default_buffer_prototype()).buffer.from_bytes(self.metadata[key].encode())

        async def get(self, key: str, prototype: Any = None, byte_range: Any = None) -> Any:
            if key in self.metadata and byte_range is None:
                return self._pinned(key, prototype)
            return await super().get(key, prototype, byte_range)

        def get_sync(self, key: str, *, prototype: Any = None, byte_range: Any = None) -> Any:
            if key in self.metadata and byte_range is None:
                return self._pinned(key, prototype)
            return super().get_sync(key, prototype=prototype, byte_range=byte_range)

        def _put(self, key: str, value: Any, exclusive: bool) -> None:
            self._check_writable()
            path = self.root / key
            if exclusive and path.exists():
                raise FileExistsError(str(path))
            path.parent.mkdir(parents=True, exist_ok=True)
            write_file(path, value.as_buffer_like())

        async def set(self, key: str, value: Any) -> None:
            if not self._is_open:
                await self._open()
            await asyncio.to_thread(self._put, key, value, False)

        async def set_if_not_exists(self, key: str, value: Any) -> None:
            if not self._is_open:
                await self._open()
            with suppress(FileExistsError):
                await asyncio.to_thread(self._put, key, value, True)

        def set_sync(self, key: str, value: Any) -> None:
            self._ensure_open_sync()
            self._put(key, value, False)

    return SweepZarrStore


_STORE_CLASS: list[type] = []


def _zstore(root: Path, *, read_only: bool = False, metadata: dict[str, str] | None = None) -> Any:
    if not _STORE_CLASS:
        _STORE_CLASS.append(_zarr_store_class())
    return _STORE_CLASS[0](root, read_only=read_only, metadata=metadata)


# ---------------------------------------------------------------- attributes and coordinates
def study_attrs(study: Study) -> dict[str, Any]:
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
        "criterion": "certified verdict from every eigenvalue of the linear model about the silent motion "
                     "(Lienard-Chipart on the exact quartic where the closed form applies)",
        "chunk_shape": list(study.chunks),
        "n_chunks": study.n_chunks,
    }


def variable_attrs(study: Study) -> dict[str, dict[str, Any]]:
    """Attributes of every data variable."""
    from ..analysis.quantities import attributes

    extra = {"coordinates": " ".join(study.sample_names)} if study.kind == "samples" else {}
    engine = study.engine()
    out: dict[str, dict[str, Any]] = {}
    for q in _variables(study):
        a = attributes(q, engine)
        out[q] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in a.items()} | extra
    return out


def coordinates(study: Study) -> dict[str, np.ndarray]:
    """The coordinate arrays of a study's store (recomputed from the study): name -> values."""
    if study.kind == "grid":
        return {ax.name: ax.values for ax in study.axes}
    return {"sample": np.arange(study.n_samples, dtype=np.int64), **study.samples()}


# ---------------------------------------------------------------- creation
def _build_skeleton(root: Path, study: Study, attrs: dict[str, Any], *,
                    write_coordinates: bool = True) -> dict[str, Any]:
    """Create the store skeleton at ``root`` (must not exist); return its creation record (also written last)."""
    import zarr

    dims, shape, chunks = study.dims, study.shape, study.chunks
    coords = coordinates(study)
    store = _zstore(root)
    g = zarr.open_group(store=store, mode="w-", zarr_format=3, attributes=attrs)
    if study.kind == "grid":
        for ax in study.axes:
            a = g.create_array(ax.name, shape=(ax.size,), dtype="f8", chunks=(ax.size,), dimension_names=(ax.name,),
                               attributes={"units": unit(ax.name, study.space()), "scale": ax.scale})
            if write_coordinates:
                a[:] = coords[ax.name]
    else:
        n = study.n_samples
        a = g.create_array("sample", shape=(n,), dtype="i8", chunks=(chunks[0],), dimension_names=("sample",),
                           attributes={"long_name": "sample number"})
        if write_coordinates:
            a[:] = coords["sample"]
        for r in study.ranges:
            a = g.create_array(r.name, shape=(n,), dtype="f8", chunks=(chunks[0],), dimension_names=("sample",),
                               attributes={"units": unit(r.name, study.space()), "scale": "log" if r.log else "linear",
                                           "sampling": f"{study.method} seed={study.seed}"})
            if write_coordinates:
                a[:] = coords[r.name]
    from ..analysis.quantities import quantity

    va = variable_attrs(study)
    comp = _compressor()
    for name in _variables(study):
        q = quantity(name)
        fill = _STATUS_FILL if name == "status" else q.fill
        g.create_array(name, shape=shape, dtype=q.dtype, chunks=chunks, dimension_names=dims, fill_value=fill,
                       compressors=comp, attributes=va[name])
    g.create_group(MARKERS, attributes={"description": "completion markers: <chunk>.json, written after the data"})
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*[Cc]onsolidated metadata.*")
        zarr.consolidate_metadata(store)
    nodes = {p.relative_to(root).as_posix(): p.read_text(encoding="utf-8") for p in sorted(root.rglob("zarr.json"))}
    manifest = {"format": _FORMAT, "study_hash": study.hash(), "created": attrs.get("created"),
                "brakesqueal_version": attrs.get("brakesqueal_version"), "variables": _variables(study),
                "coordinates": {k: checksum(v) for k, v in coords.items()}, "nodes": nodes}
    write_file(root / MANIFEST, _record_bytes(manifest))
    return manifest


def _record_sum(manifest: dict[str, Any]) -> str:
    body = {k: v for k, v in manifest.items() if k != "record_sha256"}
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def _record_bytes(manifest: dict[str, Any]) -> bytes:
    """The creation record as written: its content plus a SHA-256 of that content (so damage is detected)."""
    return json.dumps({**manifest, "record_sha256": _record_sum(manifest)}, indent=1).encode()


def _siblings(path: Path, kind: str) -> list[Path]:
    try:
        return [p for p in path.parent.iterdir() if p.name.startswith(f".{path.name}.{kind}-")]
    except OSError:
        return []


def create_store(path: Path, study: Study) -> dict[str, Any]:
    """Create the store atomically (build in a hidden sibling directory, then rename); return its record.

    ``path`` must not exist or be an empty directory.  Raises
    :class:`StoreError` (one line) if the skeleton cannot be written; nothing
    is then left at ``path``.
    """
    tmp = path.parent / f".{path.name}.creating-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    try:
        manifest = _build_skeleton(tmp, study, study_attrs(study))
        write_file(tmp / STORE_MARKER, _marker_bytes(manifest))
        os.rename(tmp, path)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise io_error(exc, "creating the skeleton", path, resume=False) from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return manifest


def _expected_manifest(study: Study, created: str | None, version: str | None) -> dict[str, Any]:
    """The creation record a store of ``study`` has (built in a temporary directory, without coordinates)."""
    attrs = study_attrs(study)
    if created:
        attrs["created"] = created
    if version:
        attrs["brakesqueal_version"] = version
    with tempfile.TemporaryDirectory(prefix="brakesqueal-skeleton-") as d:
        return _build_skeleton(Path(d) / "s.zarr", study, attrs, write_coordinates=False)


# ---------------------------------------------------------------- inspection and repair
def _read_json(p: Path) -> Any:
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def read_manifest(path: Path) -> dict[str, Any] | None:
    """The store's creation record, or None if it is missing, unreadable or damaged (its SHA-256 differs)."""
    m = _read_json(path / MANIFEST)
    if not (isinstance(m, dict) and m.get("format") == _FORMAT and m.get("record_sha256") == _record_sum(m)
            and isinstance(m.get("nodes"), dict) and isinstance(m.get("coordinates"), dict)
            and isinstance(m.get("study_hash"), str) and "zarr.json" in m["nodes"]
            and all(isinstance(v, str) for v in m["nodes"].values())):
        return None
    m.pop("record_sha256")
    return m


@dataclass
class StoreCheck:
    """What :func:`inspect_store` found (read-only).

    Attributes
    ----------
    manifest : dict
        The creation record (read from the store, or rebuilt from the study).
    record_missing : bool
        The store had no valid creation record (interrupted repair, or made by an older version).
    metadata : list of str
        Keys of ``zarr.json`` files that are missing or differ from the record.
    coords : list of str
        Coordinate arrays that are missing, unreadable or changed.
    problems : list of str
        The same, as short sentences.
    """

    manifest: dict[str, Any]
    record_missing: bool = False
    metadata: list[str] = field(default_factory=list)
    coords: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    @property
    def damaged(self) -> bool:
        return bool(self.problems)


def _different(path: Path, study: Study, h: object, source: object) -> ParameterError:
    return ParameterError(
        f"store '{path}' holds results of a different study (key 'study_hash' = {str(h)[:12]}..., "
        f"this study {study.hash()[:12]}..., written from '{source or '?'}'); "
        "pass --overwrite to replace it or choose another store")


def inspect_store(path: Path, study: Study) -> StoreCheck:
    """Identify the study of an existing store and check its metadata and coordinates (read-only).

    Raises
    ------
    ParameterError
        The store holds a different study, or ``path`` is not a sweep store.
    StoreError
        The store is damaged beyond repair (no metadata and no creation
        record name its study), or this installation computes different
        coordinates for the study than those stored.
    """
    if not path.is_dir():
        raise StoreError(f"'{path}' is a file, not a sweep store; choose another store (--out)")
    manifest = read_manifest(path)
    root = _read_json(path / "zarr.json")
    attrs = root.get("attributes") if isinstance(root, dict) and isinstance(root.get("attributes"), dict) else None
    h = manifest["study_hash"] if manifest else (attrs or {}).get("study_hash")
    if h is None:
        if not is_own_store(path):
            raise ParameterError(f"'{path}' exists and is not a sweep store made by brakesqueal (no {STORE_MARKER} "
                                 "marker, creation record or brakesqueal metadata); choose another store (--out) "
                                 "or remove it by hand")
        if attrs is not None:
            raise ParameterError(f"store '{path}' is not a brakesqueal sweep store (no key 'study_hash'); "
                                 "pass --overwrite to replace it")
        raise StoreError(f"store '{path}' is damaged beyond repair: neither its metadata (zarr.json) nor its "
                         f"creation record ({MANIFEST}) can be read; pass --overwrite to recompute it")
    if h != study.hash():
        src = (manifest and _read_study_file(manifest)) or (attrs or {}).get("study_file")
        raise _different(path, study, h, src)
    coords = coordinates(study)
    check = StoreCheck(manifest={})
    if manifest is None:
        created = (attrs or {}).get("created")
        version = (attrs or {}).get("brakesqueal_version")
        manifest = _expected_manifest(study, created if isinstance(created, str) else None,
                                      version if isinstance(version, str) else None)
        check.record_missing = True
        check.problems.append(f"creation record {MANIFEST} missing or unreadable")
    else:
        want = {k: checksum(v) for k, v in coords.items()}
        if want != manifest["coordinates"]:
            have = manifest["coordinates"]
            bad = sorted(k for k in set(want) | set(have) if want.get(k) != have.get(k))
            raise StoreError(f"store '{path}': this installation computes coordinates {', '.join(bad)} of the study "
                             "differently from those stored (another SciPy/NumPy version?); results would not "
                             "match: pass --overwrite to recompute the store, or use the installation that made it")
    found = check_skeleton(path, manifest)
    found.record_missing = check.record_missing
    found.problems[:0] = check.problems
    return found


def check_skeleton(path: Path, manifest: dict[str, Any]) -> StoreCheck:
    """Compare every node's metadata and every coordinate array of a store with its creation record (read-only)."""
    check = StoreCheck(manifest=manifest)
    for key, text in manifest["nodes"].items():
        disk = _read_json(path / key)
        if disk is None:
            check.metadata.append(key)
            check.problems.append(f"metadata {key} missing or unreadable")
        elif disk != json.loads(text):
            check.metadata.append(key)
            check.problems.append(f"metadata {key} differs from the creation record")
    g = open_group(path, manifest, read_only=True)
    for name, want_sum in manifest["coordinates"].items():
        try:
            ok = checksum(np.asarray(_array(g, name)[...])) == want_sum
        except Exception:  # noqa: BLE001 - missing / truncated / corrupt chunk files raise codec-specific errors
            ok = False
        if not ok:
            check.coords.append(name)
            check.problems.append(f"coordinate '{name}' missing, unreadable or changed")
    return check


def _read_study_file(manifest: dict[str, Any]) -> str | None:
    root = _read_json_text(manifest["nodes"].get("zarr.json", ""))
    return (root or {}).get("attributes", {}).get("study_file")


def _read_json_text(text: str) -> Any:
    try:
        return json.loads(text)
    except ValueError:
        return None


def _array(g: zarr.Group, name: str) -> zarr.Array:
    """The coordinate or data variable ``name`` of a store's group (every node but the markers is an array)."""
    return cast("zarr.Array", g[name])


def open_group(path: Path, manifest: dict[str, Any], *, read_only: bool = False) -> zarr.Group:
    """The store's Zarr group, with every node's metadata taken from the creation record ``manifest``."""
    import zarr

    return zarr.open_group(store=_zstore(path, read_only=read_only, metadata=manifest["nodes"]),
                           mode="r" if read_only else "r+", zarr_format=3)


def _marker_bytes(manifest: dict[str, Any]) -> bytes:
    """The content of :data:`STORE_MARKER`: this store was made by brakesqueal, for the study of ``manifest``."""
    return json.dumps({"kind": _STORE_KIND, "format": _FORMAT, "study_hash": manifest["study_hash"]}).encode()


def _repair(path: Path, study: Study, check: StoreCheck) -> None:
    """Rewrite the creation record, the store marker, damaged metadata and coordinates (they follow from the
    study)."""
    m = check.manifest
    try:
        if check.record_missing:
            (path / MARKERS).mkdir(exist_ok=True)
            write_file(path / MANIFEST, _record_bytes(m))
        if not (path / STORE_MARKER).is_file():  # lost with the markers' directory (the store is ours: checked)
            (path / MARKERS).mkdir(exist_ok=True)
            write_file(path / STORE_MARKER, _marker_bytes(m))
        for key in check.metadata:
            (path / key).parent.mkdir(parents=True, exist_ok=True)
            write_file(path / key, m["nodes"][key].encode())
        if check.coords:
            g = open_group(path, m)
            coords = coordinates(study)
            for name in check.coords:
                _array(g, name)[...] = coords[name]
    except OSError as exc:
        raise io_error(exc, "repairing the metadata", path) from None


def _remove_siblings(path: Path) -> None:
    """Remove the hidden sibling directories of interrupted creations and deletions of ``path``."""
    for p in _siblings(path, "creating") + _siblings(path, "deleting"):
        shutil.rmtree(p, ignore_errors=True)


def _remove_partials(path: Path) -> None:
    """Remove temporary files of interrupted writes inside a store (only call this on an identified store)."""
    for d, _, files in os.walk(path):
        for f in files:
            if f.endswith(".partial") or (f.startswith(".") and f.endswith(".tmp")):
                with suppress(OSError):
                    os.unlink(os.path.join(d, f))


def prepare_store(path: Path, study: Study, *, overwrite: bool) -> tuple[zarr.Group, list[str]]:
    """Create, or verify and repair, the store of ``study`` at ``path`` (the caller holds the lock).

    Returns
    -------
    group : zarr.Group
        The store's group (metadata from the creation record), open for writing.
    repaired : list of str
        What was damaged and has been rewritten (empty for a sound store).

    Raises
    ------
    ParameterError
        ``path`` is not a sweep store, or one of a different study (without ``overwrite``).
    StoreError
        The store cannot be created, repaired or written.
    """
    _remove_siblings(path)
    if overwrite and path.exists():
        remove_store(path)
    if not path.exists() or (path.is_dir() and not any(path.iterdir())):
        return open_group(path, create_store(path, study)), []
    check = inspect_store(path, study)
    _remove_partials(path)
    if check.damaged:
        _repair(path, study, check)
        again = inspect_store(path, study)
        if again.damaged:
            raise StoreError(f"store '{path}' could not be repaired ({'; '.join(again.problems)}); "
                             "pass --overwrite to recompute it")
    return open_group(path, check.manifest), check.problems


def is_own_store(path: Path) -> bool:
    """Whether ``path`` is a sweep store made by this package (so ``--overwrite`` may delete it).

    True for a directory (not a symbolic link) holding the ownership marker
    :data:`STORE_MARKER`, or an intact creation record (:data:`MANIFEST`), or
    (stores of versions before the marker) root metadata whose attributes
    name a study hash and a brakesqueal version.  A file merely named
    ``zarr.json``, or another program's Zarr store, is not.

    Parameters
    ----------
    path : Path
        The directory.

    Returns
    -------
    bool
    """
    if path.is_symlink() or not path.is_dir():
        return False
    m = _read_json(path / STORE_MARKER)
    if isinstance(m, dict) and m.get("kind") == _STORE_KIND:
        return True
    if read_manifest(path) is not None:
        return True
    root = _read_json(path / "zarr.json")
    attrs = root.get("attributes") if isinstance(root, dict) else None
    return (isinstance(attrs, dict) and isinstance(attrs.get("study_hash"), str)
            and isinstance(attrs.get("brakesqueal_version"), str))


def check_overwrite(path: Path) -> None:
    """Refuse (one line) to overwrite ``path`` unless it is absent, an empty directory or our own store.

    Raises
    ------
    ParameterError
        ``path`` exists and is not a store made by this package (:func:`is_own_store`).
    """
    if not os.path.lexists(path):
        return
    if path.is_dir() and not path.is_symlink() and not any(path.iterdir()):
        return
    if not is_own_store(path):
        what = "a symbolic link" if path.is_symlink() else "a file" if not path.is_dir() else "a directory"
        raise ParameterError(f"refusing to overwrite '{path}': it is {what} brakesqueal did not make (no "
                             f"{STORE_MARKER} marker or creation record of a sweep store); remove it by hand if "
                             "it should go, or choose another store (--out)", parameter="overwrite")


def remove_store(path: Path) -> None:
    """Delete a store directory (renamed away first, so the path never holds a half-deleted store).

    Refuses (:func:`check_overwrite`) anything this package did not make.
    """
    check_overwrite(path)
    if path.is_dir():
        gone = path.parent / f".{path.name}.deleting-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        try:
            os.rename(path, gone)
        except OSError as exc:
            raise io_error(exc, "removing the old store", path, resume=False) from None
        shutil.rmtree(gone, ignore_errors=True)


# ---------------------------------------------------------------- location checks
def check_location(path: Path) -> None:
    """Check, before anything is computed, that a store can be made at ``path``.

    The rule of every output (:mod:`brakesqueal.outputs`): the directory that
    holds the store must exist; missing parents are never created.

    Raises
    ------
    StoreError
        ``path`` is a file, or its parent does not exist or is not a directory.
    """
    if path.exists() and not path.is_dir():
        raise StoreError(f"'{path}' is a file, not a sweep store; choose another store (--out)")
    parent = path.parent
    for anc in [parent, *parent.parents]:
        if anc.exists() and not anc.is_dir():
            raise StoreError(f"cannot create the store '{path}': '{anc}' is not a directory")
        if anc.exists():
            break
    if not parent.is_dir():
        raise StoreError(f"cannot create the store '{path}': the directory '{parent}' does not exist")


def check_writable(path: Path) -> None:
    """Check that an existing store can be written (a probe file in it and in its marker directory)."""
    for d in (path, path / MARKERS):
        if not d.is_dir():
            continue
        probe = d / f".write-probe-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        try:
            os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
            os.unlink(probe)
        except OSError as exc:
            raise _NotWritable(f"cannot write the store '{path}': {(exc.strerror or str(exc)).lower()} "
                               f"in '{d}'") from None


# ---------------------------------------------------------------- chunks
def write_chunk(g: zarr.Group, path: Path, study: Study, chunk: int, result: dict[str, np.ndarray]) -> None:
    """Write one chunk's data, then its completion marker (each file atomically).

    Raises
    ------
    StoreError
        One line if a file cannot be written (e.g. no space left); the
        chunk's old marker, if any, is left as it was, so the chunk stays
        unverified and is recomputed on resume.
    """
    region = study.region(chunk)
    sums = {}
    try:
        for name in _variables(study):
            data = result[name]
            _array(g, name)[region] = data
            sums[name] = checksum(data)
        marker = {"chunk": chunk, "region": [[s.start, s.stop] for s in region], "checksums": sums}
        d = path / MARKERS
        d.mkdir(exist_ok=True)
        write_file(d / f"{chunk}.json", json.dumps(marker).encode())
    except OSError as exc:
        raise io_error(exc, f"writing chunk {chunk}", path) from None


def completed_chunks(path: Path) -> dict[int, dict[str, Any] | None]:
    """Markers found in the store (unverified): chunk id -> marker (None if the marker file is unreadable)."""
    out: dict[int, dict[str, Any] | None] = {}
    d = path / MARKERS
    if not d.is_dir():
        return out
    for f in d.glob("[0-9]*.json"):
        if not f.stem.isdigit():
            continue
        try:
            m = json.loads(f.read_text(encoding="utf-8"))
            ok = isinstance(m, dict) and int(m["chunk"]) == int(f.stem) and isinstance(m.get("checksums"), dict)
        except (OSError, ValueError, KeyError, TypeError):
            ok = False
        out[int(f.stem)] = m if ok else None
    return out


def verified_chunks(g: zarr.Group, path: Path, study: Study) -> tuple[set[int], set[int]]:
    """Verify every marker against the data: ``(good, bad)`` chunk ids (markers are never removed)."""
    good: set[int] = set()
    bad: set[int] = set()
    names = _variables(study)
    for chunk, m in sorted(completed_chunks(path).items()):
        if not 0 <= chunk < study.n_chunks:
            continue
        region = study.region(chunk)
        ok = m is not None and m.get("region") == [[s.start, s.stop] for s in region]
        if ok and m is not None:
            try:
                ok = all(checksum(np.asarray(_array(g, n)[region])) == m["checksums"].get(n) for n in names)
            except Exception:  # noqa: BLE001 - truncated / corrupt chunk files raise codec-specific errors
                ok = False
        (good if ok else bad).add(chunk)
    return good, bad
