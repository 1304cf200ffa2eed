"""Running a study: in-process, on a local Dask cluster or on an existing one; resume; status.

Chunks are tasks for Dask (``dask.delayed`` with the synchronous scheduler
in-process; ``Client.submit`` + ``as_completed`` on a cluster, with a bounded
number of chunks in flight).  The calling process is the only writer: each
finished chunk is written to its own region of the Zarr store and then marked
complete (:mod:`.store`).
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import re
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO, Union, cast

import numpy as np

from ..errors import ParameterError
from ..labels import unit
from .compute import ChunkSpec, compute_chunk
from .lock import StoreLock, lock_holder
from .store import (StoreError, _NotWritable, check_location, check_overwrite, check_skeleton, check_writable,
                    inspect_store, open_group, prepare_store, read_manifest, study_attrs, variable_attrs,
                    verified_chunks, write_chunk)
from .study import Study, StudySource, load_study

if TYPE_CHECKING:
    import xarray as xr
    from dask.typing import Key
    from distributed import Client, Future, LocalCluster

__all__ = ["sweep", "run_sweep", "sweep_status", "open_sweep", "SweepRun", "SweepStatus", "default_store",
           "local_cluster", "check_scheduler_address", "max_workers", "MAX_WORKERS_ENV", "WORKERS_PER_CORE"]

#: Largest result (bytes) of a study computed in memory (no store).
_MAX_IN_MEMORY = 2 * 10**9

#: What ``progress=`` takes: a bar on stderr (``True``) or a stream, a callback of the completed fraction, or nothing.
Progress = Union[bool, TextIO, Callable[[float], None]]

_WORKER_ENV = {"OMP_WAIT_POLICY": "passive", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
               "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}


def default_store(study: Study) -> Path | None:
    """The study's store: ``[output] store``, else ``STUDY.zarr`` beside a study file, else None."""
    if study.store:
        return Path(study.store)
    if study.source != "<dict>":
        return Path(study.source).with_suffix(".zarr")
    return None


def _coords(study: Study, chunk: int) -> dict[str, np.ndarray]:
    region = study.region(chunk)
    if study.kind == "grid":
        return {a.name: a.values[r] for a, r in zip(study.axes, region)}
    return {n: v[region[0]] for n, v in study.samples().items()}


# ---------------------------------------------------------------- progress
class _Progress:
    """Reports the completed fraction of a study's chunks to a callback (or draws a text bar on a stream)."""

    def __init__(self, study: Study, todo: list[int], done: int, sink: TextIO | Callable[[float], None] | None) -> None:
        self.total, self.done = study.n_chunks, done
        self.callback: Callable[[float], None] | None = sink if callable(sink) and not hasattr(sink, "write") else None
        self.stream = cast("TextIO | None", sink if self.callback is None else None)  # what is not a callback
        self.points_left = sum(study.chunk_points(c) for c in todo)
        self.points_done, self.t0 = 0, time.perf_counter()
        self._draw()

    def update(self, points: int) -> None:
        self.done += 1
        self.points_done += points
        self.points_left -= points
        self._draw()

    def _draw(self) -> None:
        frac = self.done / max(self.total, 1)
        if self.callback is not None:
            self.callback(frac)
            return
        if self.stream is None:
            return
        el = time.perf_counter() - self.t0
        rate = self.points_done / el if el > 0 and self.points_done else 0.0
        eta = _hms(self.points_left / rate) if rate > 0 else "--:--:--"
        n = int(30 * frac)
        self.stream.write(f"\rsweep [{'#' * n}{'.' * (30 - n)}] {100 * frac:5.1f}% {self.done}/{self.total} chunks"
                          f"  {rate:9.3g} points/s  ETA {eta}")
        if self.done >= self.total:
            self.stream.write("\n")
        self.stream.flush()


def _hms(s: float) -> str:
    s = int(round(s))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


# ---------------------------------------------------------------- executors
_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
_HOST = re.compile(r"^(\[[0-9A-Fa-f:.%a-zA-Z]+\]|[A-Za-z0-9_]([A-Za-z0-9_.-]*[A-Za-z0-9_])?)$")


def check_scheduler_address(address: object) -> str:
    """Validate a Dask scheduler address without connecting; return it (``HOST:PORT`` gets ``tcp://``).

    Parameters
    ----------
    address : str
        ``tcp://HOST:PORT`` (or ``tls://``, ``ws://``, ``wss://``, ``ucx://``,
        ``inproc://...``), or ``HOST:PORT``.

    Returns
    -------
    str
        The address with its protocol.

    Raises
    ------
    ParameterError
        One line naming the address and the expected form.
    """
    form = "expected tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786; also tls://, ws://, wss://, ucx://)"
    if not isinstance(address, str) or not address.strip():
        raise ParameterError(f"--scheduler: {address!r} is not a scheduler address; {form}")
    a = address.strip()
    scheme, sep, loc = a.partition("://")
    if not sep:
        scheme, loc = "tcp", a
    scheme = scheme.lower()
    if scheme not in _SCHEMES:
        raise ParameterError(f"--scheduler: unknown protocol '{scheme}' in {address!r}; {form}")
    if scheme == "inproc":
        if not loc:
            raise ParameterError(f"--scheduler: {address!r} is not a scheduler address; {form}")
        return f"inproc://{loc}"
    if loc.startswith("["):
        host, _, rest = loc.partition("]")
        host += "]"
        port = rest[1:] if rest.startswith(":") else ""
    else:
        host, _, port = loc.rpartition(":")
    if not host or not _HOST.match(host) or not port.isdigit() or not 0 < int(port) < 65536:
        raise ParameterError(f"--scheduler: {address!r} is not a scheduler address; {form}")
    return f"{scheme}://{host}:{int(port)}"


@contextlib.contextmanager
def _quiet(logger: str) -> Iterator[None]:
    log = logging.getLogger(logger)
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        log.setLevel(level)


@contextlib.contextmanager
def _silent() -> Iterator[None]:
    """Every log record dropped (``logging.disable``): the scheduler of a local cluster logs from its own
    thread and its loggers' levels are its own, so one logger's level does not silence it."""
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(logging.NOTSET)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _probe_scheduler(address: str, timeout: float) -> None:
    """Open (and close) one connection to the scheduler with the Dask handshake, within ``timeout`` seconds."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect
    from distributed.security import Security

    async def probe() -> None:
        comm = await asyncio.wait_for(connect(address, timeout=timeout, **Security().get_connection_args("client")),
                                      timeout + 1.0)
        await comm.close()

    with _quiet("distributed"), ThreadPoolExecutor(1) as pool:  # own thread: works inside a running event loop too
        try:
            pool.submit(asyncio.run, probe()).result()
        except (OSError, TimeoutError) as exc:
            why = _first_line(exc)
        except Exception as exc:  # noqa: BLE001 - e.g. MemoryError reading a non-Dask server's bytes as a frame
            why = f"the server does not answer like a Dask scheduler ({type(exc).__name__})"
        else:
            return
    raise ParameterError(f"cannot reach the Dask scheduler at '{address}' within {timeout:g} s: {why}")


def _check_executor(workers: object, scheduler: object, client: object) -> str | None:
    """Validate the executor options before anything else happens; return the scheduler address."""
    if sum(x is not None for x in (workers, scheduler, client)) > 1:
        raise ParameterError("give at most one of --workers, --scheduler (or client=)")
    if workers is not None and (not isinstance(workers, int) or isinstance(workers, bool) or workers < 1):
        raise ParameterError(f"--workers must be a positive integer; got {workers!r}")
    if workers is not None:
        cap, why = max_workers()
        if workers > cap:
            raise ParameterError(f"--workers must be in [1, {cap}] ({why}; set {MAX_WORKERS_ENV}=N to allow "
                                 f"more); got {workers}", parameter="workers")
    return check_scheduler_address(scheduler) if scheduler is not None else None


#: Environment variable that sets the largest ``--workers`` (default: :data:`WORKERS_PER_CORE` × the usable cores).
MAX_WORKERS_ENV = "BRAKESQUEAL_MAX_WORKERS"
#: Worker processes allowed per usable core by default (the workers are single-threaded).
WORKERS_PER_CORE = 4


def _usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the platform tells, else all)."""
    import os

    count = getattr(os, "process_cpu_count", None)  # Python >= 3.13
    if count is not None:
        return max(int(count() or 1), 1)
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except (AttributeError, OSError):  # pragma: no cover - macOS, Windows
        return max(os.cpu_count() or 1, 1)


def max_workers() -> tuple[int, str]:
    """The largest number of local worker processes ``--workers`` may start, and why.

    Returns
    -------
    cap : int
        ``$BRAKESQUEAL_MAX_WORKERS`` if set, else :data:`WORKERS_PER_CORE` × the usable cores.
    reason : str
        Where the cap comes from (for the refusal's message).

    Raises
    ------
    ParameterError
        ``$BRAKESQUEAL_MAX_WORKERS`` is not a positive integer.
    """
    import os

    raw = os.environ.get(MAX_WORKERS_ENV, "").strip()
    if raw:
        if not raw.isdigit() or len(raw) > 9 or int(raw) < 1:
            raise ParameterError(f"{MAX_WORKERS_ENV} must be a positive integer (at most 999999999); got "
                                 f"{raw[:40]!r}{'...' if len(raw) > 40 else ''}")
        return int(raw), f"{MAX_WORKERS_ENV}={int(raw)}"
    cores = _usable_cores()
    return WORKERS_PER_CORE * cores, f"{WORKERS_PER_CORE} per usable core, {cores} core{'s' * (cores != 1)}"


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None, client: Client | None,
            timeout: float) -> Iterator[Client | None]:
    """``None`` (in-process) or a ``distributed.Client``."""
    scheduler = _check_executor(workers, scheduler, client)
    if client is not None:
        yield client
        return
    if scheduler is not None:
        from distributed import Client

        _probe_scheduler(scheduler, timeout)
        try:
            with _quiet("distributed"):
                c = Client(scheduler, timeout=f"{timeout}s", set_as_default=False)
        except Exception as exc:  # noqa: BLE001 - one line, whatever distributed raises
            raise ParameterError(f"cannot reach the Dask scheduler at '{scheduler}' within {timeout:g} s: "
                                 f"{_first_line(exc)}") from None
        try:
            yield c
        finally:
            c.close()
        return
    if workers is not None:
        from distributed import Client

        cluster = local_cluster(workers)
        c = Client(cluster, set_as_default=False)
        try:
            yield c
        except BaseException:
            with _silent():  # an interrupted run's cancelled gathers ("Couldn't gather keys") are not news
                c.close()
                cluster.close()
            raise
        c.close()
        cluster.close()
        return
    yield None


def local_cluster(workers: int) -> LocalCluster:
    """A ``LocalCluster`` of single-threaded worker processes set up for the compiled kernels.

    Two defaults of distributed are changed for these workers (measured on the
    eigenvalue path): the statistical task profiler is off (it samples the
    running task's stack every 10 ms and cost about 35 % here) and
    ``MALLOC_TRIM_THRESHOLD_`` is left unset (with it glibc ``mmap``s every large
    temporary array: about 15 %).  For an existing cluster, set
    ``distributed.worker.profile.enabled: false`` in its Dask configuration.

    The worker processes never see a terminal's Ctrl-C (it goes to the whole
    foreground process group): they start with ``SIGINT`` blocked
    (:func:`_ctrl_c_deferred`), and the calling process, which receives the
    interrupt, shuts them down.  Otherwise every worker printed the traceback
    of its own ``KeyboardInterrupt`` (and one that lost its parent while
    starting, an ``EOFError``).  A Ctrl-C while the workers start takes effect
    once they have started (a few seconds); the cluster is then closed.
    """
    import dask
    from distributed import LocalCluster

    _check_executor(workers, None, None)
    cluster: LocalCluster | None = None
    try:
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                              "distributed.worker.profile.enabled": False}), _ctrl_c_deferred():
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=logging.ERROR, env=_WORKER_ENV)
    except BaseException:  # e.g. the Ctrl-C deferred during the start, raised as it ends: shut the workers down
        if cluster is not None:
            cluster.close()
        raise
    return cluster


@contextlib.contextmanager
def _ctrl_c_deferred() -> Iterator[None]:
    """``SIGINT`` blocked in this thread, and so in every thread and process started inside.

    A blocked signal mask is inherited by new threads and kept across ``fork``
    and ``exec``: the cluster's event loop is started here, its nannies start
    the worker processes from threads of that loop, so the workers start (and
    stay) deaf to Ctrl-C from their first instruction on (no window before a
    handler could be installed).  A Ctrl-C to this thread meanwhile is pending,
    not lost: it is raised as the block ends.  Ending the program while workers
    start instead left a worker reading its start-up data from a closed pipe
    (an ``EOFError`` traceback).
    """
    import signal

    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - Windows: no process groups to shield from
        yield
        return
    # multiprocessing starts its resource tracker on the first spawn and *unblocks* SIGINT in the spawning thread
    # afterwards: start it now, from this thread, so that the loop's threads keep the mask.  The tracker (a
    # process of its own, which outlives us) removes the semaphores of workers whose program was ended before it
    # closed them, as it should, but also warned about them on the terminal after the program had ended: it is
    # started with that one warning ignored (-W options are passed on to it).
    from multiprocessing import resource_tracker

    quiet = "ignore:resource_tracker:UserWarning"
    sys.warnoptions.append(quiet)
    try:
        resource_tracker.ensure_running()
    finally:
        sys.warnoptions.remove(quiet)
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a pending Ctrl-C is raised right after this


def _results(study: Study, spec: ChunkSpec, todo: list[int],
             client: Client | None) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
    """Compute the chunks ``todo``; yields ``(chunk, result)`` as they finish."""
    if not todo:
        return
    if client is None:
        import dask

        for c in todo:
            task = dask.delayed(compute_chunk, pure=False)(spec, _coords(study, c))
            yield c, task.compute(scheduler="synchronous")
        return
    from distributed import as_completed

    limit = 2 * max(1, sum(client.nthreads().values())) + 1
    pending = iter(todo)
    owner: dict[Key, int] = {}

    def submit() -> Future | None:
        c = next(pending, None)
        if c is None:
            return None
        f = client.submit(compute_chunk, spec, _coords(study, c), key=f"brakesqueal-sweep-{spec.key[:16]}-{c}",
                          retries=1)
        owner[f.key] = c
        return f

    first = [f for f in (submit() for _ in range(limit)) if f is not None]
    ac = as_completed(first, loop=client.loop)
    for fut in ac:
        c = owner.pop(fut.key)
        res = fut.result()
        fut.release()
        yield c, res
        nxt = submit()
        if nxt is not None:
            ac.add(nxt)


# ---------------------------------------------------------------- API
@dataclass
class SweepRun:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    dataset : xarray.Dataset
        The results (lazily backed by the store when there is one).
    store : str or None
        The store (None: computed in memory).
    computed, reused : int
        Chunks computed by this run / verified and kept from earlier runs.
    repaired : list of str
        Damage of the store's metadata or coordinates that was found and rewritten.
    """

    dataset: xr.Dataset
    store: str | None
    computed: int
    reused: int
    repaired: list[str] = field(default_factory=list)


def sweep(study: StudySource, *, store: str | Path | None = None, workers: int | None = None,
          scheduler: str | None = None, client: Client | None = None, overwrite: bool = False,
          progress: Progress = False, scheduler_timeout: float = 5.0) -> xr.Dataset:
    """Run a parameter study and return its results as an :class:`xarray.Dataset`.

    Parameters
    ----------
    study : str, Path, dict or Study
        A study file (TOML), its content as a dict, or a loaded :class:`Study`.
    store : str or Path, optional
        Zarr store to write (and resume).  Default: ``[output] store`` of the
        study, else ``STUDY.zarr`` beside the study file; a dict study without
        either is computed in memory (no resume).
    workers : int, optional
        Start a local Dask cluster with this many single-threaded worker processes.
    scheduler : str, optional
        Address of an existing Dask distributed scheduler (``tcp://host:8786``).
    client : distributed.Client, optional
        Use this client (notebooks).
    overwrite : bool
        Replace an existing store (otherwise a store of the same study is
        resumed and one of a different study is an error).
    progress : bool, text stream or callable
        Draw a progress bar with ETA (on stderr for ``True``), or call
        ``progress(fraction)`` after every chunk.
    scheduler_timeout : float
        Seconds to wait for ``scheduler``.

    Returns
    -------
    xarray.Dataset
        One dimension per axis (or ``sample``), variables ``stable``, ``status``
        and the requested quantities; lazily backed by the store when there is one.

    Raises
    ------
    ParameterError
        Bad study or options, unreachable scheduler, or a store of a different study.
    StoreError
        The store is in use by another run, cannot be written (checked before
        anything is computed), runs out of space, or is damaged beyond repair.
    """
    return run_sweep(study, store=store, workers=workers, scheduler=scheduler, client=client, overwrite=overwrite,
                     progress=progress, scheduler_timeout=scheduler_timeout).dataset


def run_sweep(study: StudySource, *, store: str | Path | None = None, workers: int | None = None,
              scheduler: str | None = None, client: Client | None = None, overwrite: bool = False,
              progress: Progress = False, scheduler_timeout: float = 5.0) -> SweepRun:
    """Run a parameter study as :func:`sweep` does, and report what was computed, reused and repaired.

    The order is: the study and the executor options are validated; the store
    location is checked and the store's lock taken (nothing is computed if the
    store cannot be written or another run holds it); the executor is started;
    the store is created atomically, or verified and repaired; the missing
    chunks are computed and written.

    Parameters
    ----------
    study : str, Path, dict or Study
        As for :func:`sweep`.
    store : str or Path, optional
        As for :func:`sweep`.
    workers : int, optional
        As for :func:`sweep`.
    scheduler : str, optional
        As for :func:`sweep`.
    client : distributed.Client, optional
        As for :func:`sweep`.
    overwrite : bool
        As for :func:`sweep`.
    progress : bool, text stream or callable
        As for :func:`sweep`.
    scheduler_timeout : float
        As for :func:`sweep`.

    Returns
    -------
    SweepRun
        The dataset and the counts of computed / reused chunks.
    """
    st = load_study(study)
    _check_executor(workers, scheduler, client)
    path = Path(store) if store is not None else default_store(st)
    spec = ChunkSpec.from_study(st)
    stream = sys.stderr if progress is True else (progress or None)
    if path is None:
        ds = _in_memory(st, spec, workers, scheduler, client, stream, scheduler_timeout)
        return SweepRun(ds, None, st.n_chunks, 0)
    path = path.resolve()
    check_location(path)
    if overwrite:
        check_overwrite(path)  # only a store this package made is ever deleted: refused before any work
    lock = StoreLock(path)
    try:
        lock.acquire()
    except _NotWritable as exc:
        return _read_only(st, path, exc, overwrite)
    with contextlib.ExitStack() as stack:
        stack.callback(lock.release)
        try:
            if path.exists():
                check_writable(path)
        except _NotWritable as exc:
            unwritable: _NotWritable | None = exc
        else:
            unwritable = None
            with _client(workers, scheduler, client, scheduler_timeout) as cl:
                g, repaired = prepare_store(path, st, overwrite=overwrite)
                good, _ = verified_chunks(g, path, st)
                todo = [c for c in range(st.n_chunks) if c not in good]
                bar = _Progress(st, todo, len(good), stream)
                for c, res in _results(st, spec, todo, cl):
                    write_chunk(g, path, st, c, res)
                    bar.update(st.chunk_points(c))
    if unwritable is not None:
        return _read_only(st, path, unwritable, overwrite)
    return SweepRun(open_sweep(path), str(path), len(todo), len(good), repaired)


def _read_only(st: Study, path: Path, exc: StoreError, overwrite: bool) -> SweepRun:
    """The store cannot be written: fine if it is complete (nothing to do), else raise ``exc``."""
    if not overwrite and path.is_dir() and any(path.iterdir()):
        s = sweep_status(st, store=path)
        if s.complete:
            return SweepRun(open_sweep(path), str(path), 0, s.n_chunks)
    raise exc


def _in_memory(st: Study, spec: ChunkSpec, workers: int | None, scheduler: str | None, client: Client | None,
               stream: TextIO | Callable[[float], None] | None, timeout: float) -> xr.Dataset:
    import xarray as xr

    from ..analysis.quantities import quantity

    per_point = sum(np.dtype(quantity(q).dtype).itemsize for q in st.variables())
    if per_point * st.n_points > _MAX_IN_MEMORY:
        raise ParameterError(f"study '{st.source}' has no store, so its results are kept in memory: "
                             f"{st.n_points} points need {per_point * st.n_points / 1e9:.3g} GB, more than the "
                             f"limit of {_MAX_IN_MEMORY / 1e9:g} GB; give a store (store= or [output] store)")
    data: dict[str, np.ndarray] = {q: np.full(st.shape, quantity(q).fill, quantity(q).dtype) for q in st.variables()}
    todo = list(range(st.n_chunks))
    with _client(workers, scheduler, client, timeout) as cl:
        bar = _Progress(st, todo, 0, stream)
        for c, res in _results(st, spec, todo, cl):
            for k, a in data.items():
                a[st.region(c)] = res[k]
            bar.update(st.chunk_points(c))
    va = variable_attrs(st)
    dims = st.dims
    if st.kind == "grid":
        coords: dict[str, Any] = {a.name: xr.Variable((a.name,), a.values, {"units": unit(a.name, st.space()),
                                                                             "scale": a.scale}) for a in st.axes}
    else:
        coords = {"sample": np.arange(st.n_samples)}
        coords.update({n: ("sample", v, {"units": unit(n, st.space())}) for n, v in st.samples().items()})
    ds = xr.Dataset({k: (dims, v, {a: b for a, b in va[k].items() if a != "coordinates"})
                     for k, v in data.items()}, coords=coords, attrs=study_attrs(st))
    return ds


def open_sweep(store: str | Path, *, verify: bool = True) -> xr.Dataset:
    """Open a study's Zarr store as a lazily loaded :class:`xarray.Dataset`.

    Parameters
    ----------
    store : str or Path
        The store directory written by :func:`sweep`.
    verify : bool
        Check the store's metadata and coordinates against its creation
        record first (cheap: data chunks are verified by :func:`sweep_status`).

    Returns
    -------
    xarray.Dataset
        Variables ``stable``, ``status`` and the computed quantities first.

    Raises
    ------
    ParameterError
        ``store`` is not a sweep store.
    StoreError
        Its metadata or coordinates are damaged (running the study again repairs them).
    """
    import xarray as xr

    p = Path(store)
    if not (p / "zarr.json").is_file():
        raise ParameterError(f"'{p}' is not a sweep store (no zarr.json)")
    manifest = read_manifest(p)
    if verify and manifest is not None:
        problems = check_skeleton(p, manifest).problems
        if problems:
            raise StoreError(f"store '{p}' is damaged ({'; '.join(problems)}); run its study again "
                             "(brakesqueal sweep STUDY --out STORE) to repair it")
    try:
        root = json.loads((p / "zarr.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        raise StoreError(f"store '{p}' is damaged (metadata zarr.json unreadable); run its study again "
                         "to repair it") from None
    ds = xr.open_zarr(str(p), consolidated="consolidated_metadata" in root)
    from ..analysis.quantities import QUANTITIES

    order = [q for q in QUANTITIES if q in ds.data_vars]
    return ds[order + [v for v in ds.data_vars if v not in order]]


# ---------------------------------------------------------------- status
@dataclass
class SweepStatus:
    """Completed and missing chunks of a study's store, and any damage found.

    Attributes
    ----------
    store : str
        The store's path.
    exists : bool
        Whether the store has been created.
    study_hash : str
        SHA-256 of the study (see :meth:`Study.hash`).
    dims : dict
        Dimension sizes.
    chunk_shape : list of int
        Shape of one chunk.
    n_chunks : int
        Number of chunks.
    completed, missing, corrupt : list of int
        Verified chunks; chunks still to compute; chunks whose marker exists
        but whose data do not match it (recomputed on resume; also in ``missing``).
    version : str or None
        The brakesqueal version that created the store.
    damaged : list of str
        Damaged or missing metadata, coordinates or creation record (rewritten
        on resume; a damaged store is not complete).
    in_use : str or None
        The live run that holds the store's lock (``PID n (started ...)``), if any.
    """

    store: str
    exists: bool
    study_hash: str
    dims: dict[str, int]
    chunk_shape: list[int]
    n_chunks: int
    completed: list[int] = field(default_factory=list)
    missing: list[int] = field(default_factory=list)
    corrupt: list[int] = field(default_factory=list)
    version: str | None = None
    damaged: list[str] = field(default_factory=list)
    in_use: str | None = None

    @property
    def complete(self) -> bool:
        return not self.missing and not self.damaged

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["complete"] = self.complete
        return d

    def text(self) -> str:
        pts = math.prod(self.dims.values())
        lines = [f"store: {self.store}" + ("" if self.exists else " (not created yet)"),
                 f"study: {self.study_hash[:16]}  dims: " + " x ".join(f"{k}={v}" for k, v in self.dims.items())
                 + f" ({pts} points), chunks of {tuple(self.chunk_shape)}"]
        if self.version:
            lines.append(f"written by brakesqueal {self.version}")
        if self.in_use:
            lines.append(f"in use by {self.in_use}")
        lines.append(f"completed: {len(self.completed)}/{self.n_chunks} chunks "
                     f"({100 * len(self.completed) / max(self.n_chunks, 1):.1f} %)")
        lines.append(f"missing: {len(self.missing)}" + (f" [{_ranges(self.missing)}]" if self.missing else ""))
        if self.corrupt:
            lines.append(f"corrupt (will be recomputed): {len(self.corrupt)} [{_ranges(self.corrupt)}]")
        if self.damaged:
            lines.append(f"damaged (will be repaired on resume): {'; '.join(self.damaged)}")
        return "\n".join(lines) + "\n"


def _ranges(ids: list[int], limit: int = 20) -> str:
    out: list[str] = []
    i = 0
    while i < len(ids):
        j = i
        while j + 1 < len(ids) and ids[j + 1] == ids[j] + 1:
            j += 1
        out.append(str(ids[i]) if i == j else f"{ids[i]}-{ids[j]}")
        i = j + 1
    return ", ".join(out[:limit]) + (", ..." if len(out) > limit else "")


def sweep_status(study: StudySource, *, store: str | Path | None = None) -> SweepStatus:
    """Completed (verified by checksum), corrupt and missing chunks of a study's store (read-only).

    Parameters
    ----------
    study : str, Path, dict or Study
        The study.
    store : str or Path, optional
        The store (default as for :func:`sweep`).

    Returns
    -------
    SweepStatus
        ``.text()`` / ``.to_dict()`` render it.

    Raises
    ------
    ParameterError
        The path is not a sweep store, or holds a different study.
    StoreError
        The store is damaged beyond repair.
    """
    st = load_study(study)
    path = Path(store) if store is not None else default_store(st)
    if path is None:
        raise ParameterError("the study has no store: give store= or [output] store")
    path = path.resolve()
    dims = dict(zip(st.dims, st.shape))
    holder = lock_holder(path)
    status = partial(SweepStatus, store=str(path), study_hash=st.hash(), dims=dims, chunk_shape=list(st.chunks),
                     n_chunks=st.n_chunks, in_use=holder.describe() if holder else None)
    if not path.exists() or (path.is_dir() and not any(path.iterdir())):
        return status(exists=False, missing=list(range(st.n_chunks)))
    check = inspect_store(path, st)
    g = open_group(path, check.manifest, read_only=True)
    good, bad = verified_chunks(g, path, st)
    return status(exists=True, completed=sorted(good), corrupt=sorted(bad),
                  missing=[c for c in range(st.n_chunks) if c not in good],
                  version=check.manifest.get("brakesqueal_version"), damaged=check.problems)
