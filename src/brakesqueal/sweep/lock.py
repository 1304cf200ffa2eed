"""The exclusive lock of a sweep store: one writer per store, stale locks of dead processes taken over.

The lock is the file ``STORE.lock`` beside the store (it must exist before the
store does, so that two runs on a fresh store cannot both create it).  It is
created with ``O_CREAT | O_EXCL``, holds the owner's PID, host, process start
time and the time it was taken (JSON), and is held with ``flock(LOCK_EX)`` as
long as the owner runs.  The kernel drops an ``flock`` when its process dies,
so a lock file left behind by a killed run is recognised as stale and taken
over.  Where ``flock`` is not available the owner's PID is checked instead
(dead, or alive with a different start time: stale).  A lock taken on another
host cannot be checked: it is reported with the host name and the file to
remove.  The owner removes the file on exit (while still holding the
``flock``; a process that opened the old file re-checks the path after
locking and starts over).
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import socket
import time
from dataclasses import dataclass
from pathlib import Path

from ..outputs import process_running, process_start_ticks
from .store import StoreError, _NotWritable

__all__ = ["StoreLock", "LockInfo", "lock_path", "lock_holder"]

_NO_FLOCK = (errno.ENOLCK, errno.EOPNOTSUPP, errno.EINVAL, errno.ENOSYS)


def lock_path(store: Path) -> Path:
    """The lock file of ``store``: ``STORE.lock`` in the same directory."""
    return store.parent / f"{store.name}.lock"


def _alive(pid: int, start: str | None) -> bool:
    """Whether process ``pid`` runs on this host (and, if known, is the one started at ``start``)."""
    if not process_running(pid):
        return False
    now = process_start_ticks(pid)
    return start is None or now is None or now == start


@dataclass(frozen=True)
class LockInfo:
    """Who holds a store's lock.

    Attributes
    ----------
    pid : int
        Process id of the owner (0 if the file is empty or unreadable).
    host : str
        Host name of the owner.
    started : str
        When the lock was taken (ISO 8601).
    path : str
        The lock file.
    """

    pid: int
    host: str
    started: str
    path: str

    def describe(self) -> str:
        """``PID n (started T)``, with the host if it is not this one."""
        if not self.pid:
            return "another process (starting)"
        where = "" if self.host == socket.gethostname() else f" on host {self.host}"
        return f"PID {self.pid}{where} (started {self.started})"


def _parse(text: str, path: Path) -> tuple[LockInfo | None, str | None]:
    try:
        d = json.loads(text)
        return LockInfo(int(d["pid"]), str(d["host"]), str(d["started"]), str(path)), d.get("proc_start")
    except (ValueError, KeyError, TypeError):
        return None, None


def _read_fd(fd: int, path: Path) -> tuple[LockInfo | None, str | None]:
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        return _parse(os.read(fd, 4096).decode("utf-8", "replace"), path)
    except OSError:
        return None, None


def _flock(fd: int) -> bool | None:
    """Try ``flock(LOCK_EX | LOCK_NB)``: True (locked), False (held by another), None (not supported)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
    except OSError as exc:
        if exc.errno in (errno.EAGAIN, errno.EACCES):
            return False
        if exc.errno in _NO_FLOCK:
            return None
        raise


def _same_file(fd: int, path: Path) -> bool:
    try:
        a, b = os.fstat(fd), os.stat(path)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def lock_holder(store: Path) -> LockInfo | None:
    """The live owner of ``store``'s lock, or None (read-only: no lock is taken, stale files are ignored)."""
    p = lock_path(store)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError:
        return None
    info, start = _parse(text, p)
    if info is None:
        return None
    if info.host == socket.gethostname() and not _alive(info.pid, start):
        return None
    return info


class StoreLock:
    """Exclusive lock of a sweep store (context manager).

    Parameters
    ----------
    store : Path
        The store directory (need not exist yet); the lock is ``STORE.lock``.

    Raises
    ------
    StoreError
        On entry: one line saying who holds the lock ("store ... is in use by
        PID N (started ...)"), or that the lock cannot be written there.
    """

    def __init__(self, store: Path) -> None:
        self.store = store
        self.path = lock_path(store)
        self._fd: int | None = None

    # ------------------------------------------------------------ acquire / release
    def acquire(self) -> None:
        """Take the lock or raise (see the class docstring)."""
        for _ in range(50):
            created = True
            try:
                fd = self._create()
                if fd is not None:
                    self._fd = fd
                    self._remove_dead_temporaries()
                    return
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                created = False
                try:
                    fd = os.open(self.path, os.O_RDWR)
                except FileNotFoundError:
                    continue  # released meanwhile
                except OSError as exc:
                    raise self._cannot(exc) from None
            except OSError as exc:
                raise self._cannot(exc) from None
            try:
                if self._claim(fd, created):
                    self._fd = fd
                    self._remove_dead_temporaries()
                    return
            except BaseException:
                os.close(fd)
                raise
            os.close(fd)
            time.sleep(0.01)
        raise StoreError(f"cannot lock store '{self.store}': its lock file '{self.path}' keeps changing")

    def _create(self) -> int | None:
        """Make the lock file complete and locked before it appears: fill and flock a temporary file, then
        hard-link it to the lock path (``FileExistsError`` if the lock exists; None where hard links or
        ``flock`` are not available: the caller then uses ``O_EXCL``)."""
        tmp = self.path.parent / f".{self.path.name}.{os.getpid()}.{time.monotonic_ns()}"
        try:
            fd = os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
        except OSError as exc:
            raise self._cannot(exc) from None
        try:
            if _flock(fd) is not True:
                os.close(fd)
                return None
            try:
                os.pwrite(fd, self._content(), 0)
                os.link(tmp, self.path)
            except FileExistsError:
                os.close(fd)
                raise
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
                    return None
                raise self._cannot(exc) from None
            return fd
        finally:
            with contextlib.suppress(OSError):
                os.unlink(tmp)

    def _remove_dead_temporaries(self) -> None:
        """Remove temporary lock files (``.STORE.lock.PID.N``) left by killed processes."""
        prefix = f".{self.path.name}."
        with contextlib.suppress(OSError):
            for p in self.path.parent.iterdir():
                pid = p.name[len(prefix):].split(".")[0] if p.name.startswith(prefix) else ""
                if pid.isdigit() and int(pid) != os.getpid() and not _alive(int(pid), None):
                    with contextlib.suppress(OSError):
                        p.unlink()

    def _content(self) -> bytes:
        me = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
              "proc_start": process_start_ticks(os.getpid()), "store": str(self.store)}
        return json.dumps(me).encode()

    def _claim(self, fd: int, created: bool) -> bool:
        """Lock and fill ``fd``; False to start over (the file was replaced meanwhile)."""
        got = _flock(fd)
        if got is False:
            raise self._in_use(self._owner(fd))
        if not _same_file(fd, self.path):
            return False
        if not created:
            info, start = _read_fd(fd, self.path)
            if info is not None and info.host != socket.gethostname():
                raise self._in_use(info, other_host=True)
            if got is None:  # no flock here: decide by the owner's PID
                if info is not None and _alive(info.pid, start):
                    raise self._in_use(info)
                if info is None and time.time() - os.fstat(fd).st_mtime < 5:
                    raise self._in_use(None)
        data = self._content()
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, data, 0)
        except OSError as exc:
            if created:
                self._unlink_if_mine(fd)
            raise self._cannot(exc) from None
        return True

    def _owner(self, fd: int) -> LockInfo | None:
        """The owner named in a lock file held by another process (re-read briefly while it is being taken over)."""
        for _ in range(20):
            info, start = _read_fd(fd, self.path)
            if info is not None and (info.host != socket.gethostname() or _alive(info.pid, start)):
                return info
            time.sleep(0.01)
        return info

    def release(self) -> None:
        """Remove the lock file and drop the lock."""
        fd, self._fd = self._fd, None
        if fd is None:
            return
        self._unlink_if_mine(fd)
        os.close(fd)

    def _unlink_if_mine(self, fd: int) -> None:
        if _same_file(fd, self.path):
            try:
                os.unlink(self.path)
            except OSError:
                pass

    def __enter__(self) -> StoreLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    # ------------------------------------------------------------ messages
    def _in_use(self, info: LockInfo | None, other_host: bool = False) -> StoreError:
        who = info.describe() if info is not None else "another process (starting)"
        tail = (f"; if no sweep runs there any more, delete '{self.path}'" if other_host
                else "; wait for it to finish or stop it")
        return StoreError(f"store '{self.store}' is in use by {who}{tail}")

    def _cannot(self, exc: OSError) -> StoreError:
        return _NotWritable(f"cannot write the store '{self.store}': cannot create its lock file in "
                          f"'{self.path.parent}' ({(exc.strerror or str(exc)).lower()})")
