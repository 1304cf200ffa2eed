"""Output files: checked before any computation, written atomically, failures in one line.

Every command that writes a file checks its path first (:func:`check_output`)
— the directory exists and is writable, the name is not a directory, the
suffix is one the writer supports — so a typo fails in one line *before* a
long computation.  One rule for every output, file, output directory
(:func:`check_output_dir`) or sweep store: the directory that holds it must
exist; missing parents are never created.  Files are written through :func:`atomic_write`: the
content goes to a temporary file in the same directory which is renamed over
the final name only when it is complete, so an interrupted or failed write
(Ctrl-C, a full disk) never leaves a truncated file under the final name and
never destroys an existing file of that name.  Every ``OSError`` becomes an
:class:`~brakesqueal.errors.OutputError` with one line naming the file (also
when a writer turns it into another exception, as the PDF writer's
``zlib.error`` on a full disk does).

What an output never replaces
    * a symbolic link: refused in one line naming the link and its target
      (the link is neither replaced by a file nor written through; give the
      target's path instead);
    * anything but a regular file (a named pipe, a socket, a device such as
      ``/dev/null``): refused in one line, nothing is opened;
    * an input of the same command: while a command runs
      (:func:`guard_inputs`, entered by :func:`brakesqueal.cli.main`) every
      file it reads is recorded, and an output that is the same file (same
      device and inode, so also through another spelling, a link or a hard
      link) as an input, or as another file named on its command line, is
      refused in one line.

Temporary files
    Named ``.<name>.brakesqueal-<host>-<pid>-<random>.part<suffix>`` (files)
    and ``.brakesqueal-<host>-<pid>-<random>.part`` (staging directories of
    :func:`write_set`): ``<host>`` is a short hash of the host name and
    ``<pid>`` the writing process.  They are removed when the write fails or
    is interrupted (Ctrl-C, and SIGTERM/SIGHUP, which a command handles as
    Ctrl-C).  A process killed outright (SIGKILL, a power cut) cannot remove
    them: the next write into the same directory removes those of this host
    whose process has ended (:func:`remove_stale_parts`).  Temporary files of
    running processes, of other hosts, and of versions that did not put the
    process in the name are never removed.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, TypeVar

from .errors import BrakesquealError, OutputError
from .interrupts import critical, remove_on_exit

__all__ = ["check_output", "check_output_dir", "atomic_write", "write_with", "write_set", "describe_oserror",
           "guard_inputs", "remove_stale_parts", "process_running", "process_start_ticks"]

_T = TypeVar("_T")


def describe_oserror(exc: OSError) -> str:
    """A short reason for an ``OSError`` (``"no space left on device"``, ``"permission denied"``)."""
    if exc.errno == errno.ENOSPC:
        return "no space left on device"
    if exc.errno == errno.EDQUOT:
        return "disk quota exceeded"
    return (exc.strerror or str(exc)).lower()


def check_output(path: str | os.PathLike[str], *, what: str = "output file",
                 suffixes: Sequence[str] | None = None) -> Path:
    """Check that ``path`` can be written, before computing anything.

    Parameters
    ----------
    path : str or path-like
        The file to be written.
    what : str, optional
        The option or role of the file, for messages (e.g. ``"--out"``).
    suffixes : sequence of str, optional
        Allowed suffixes (lower case, with the dot), e.g. ``(".nc",)``.

    Returns
    -------
    pathlib.Path
        The path.

    Raises
    ------
    OutputError
        One line: wrong suffix, missing or unwritable directory, a
        directory, symbolic link or non-regular file (pipe, socket, device)
        in the file's place, or the file is an input of the running command.
    """
    p = Path(os.fspath(path))
    if not p.name:
        raise OutputError(f"{what}: '{path}' is not a file name")
    if p.is_dir():
        raise OutputError(f"{what}: cannot write '{path}': it is a directory")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise OutputError(f"{what}: '{path}' must end in {' or '.join(suffixes)}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{what}: cannot write '{path}': the directory '{parent}' does not exist")
    if not parent.is_dir():
        raise OutputError(f"{what}: cannot write '{path}': '{parent}' is not a directory")
    if p.is_dir():
        raise OutputError(f"{what}: cannot write '{path}': it is a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{what}: cannot write '{path}': the directory '{parent}' is not writable")
    if p.exists() and not os.access(p, os.W_OK) and not os.access(parent, os.W_OK):
        raise OutputError(f"{what}: cannot write '{path}': permission denied")
    _check_target(p, what, path)
    return p


def check_output_dir(path: str | os.PathLike[str], *, what: str = "output directory") -> Path:
    """Check that ``path`` is (or can be created as) a writable directory; create it.

    The rule of every output (:func:`check_output` for files, sweep stores):
    the directory that *holds* the output must exist; the output directory
    itself is created if missing, but never its parents (a typo in a path
    fails in one line instead of creating a tree somewhere).

    Raises
    ------
    OutputError
        One line when a regular file is in the way, the parent directory does
        not exist, or the location is not writable.
    """
    p = Path(os.fspath(path))
    if p.exists():
        if not p.is_dir():
            raise OutputError(f"{what}: cannot use '{path}': it is a regular file, not a directory")
        if not os.access(p, os.W_OK | os.X_OK):
            raise OutputError(f"{what}: cannot use '{path}': the directory is not writable")
        return p
    parent = p.parent if str(p.parent) else Path(".")
    for anc in [parent, *parent.parents]:
        if anc.exists() and not anc.is_dir():
            raise OutputError(f"{what}: cannot use '{path}': '{anc}' is a regular file, not a directory")
        if anc.exists():
            break
    if not parent.is_dir():
        raise OutputError(f"{what}: cannot create '{path}': the directory '{parent}' does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{what}: cannot create '{path}': the directory '{parent}' is not writable")
    try:
        p.mkdir(exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{what}: cannot create '{path}': {describe_oserror(exc)}") from None
    return p


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], *, what: str = "output file") -> Iterator[Path]:
    """Context manager yielding a temporary path in the same directory; renamed over ``path`` on success.

    On any exception (including ``KeyboardInterrupt``) the temporary file is
    removed and an existing file at ``path`` is left untouched; an
    ``OSError`` is re-raised as :class:`~brakesqueal.errors.OutputError`.

    Examples
    --------
    >>> with atomic_write("map.nc") as tmp:          # doctest: +SKIP
    ...     dataset.to_netcdf(tmp)
    """
    final = Path(os.fspath(path))
    directory = final.parent if str(final.parent) else Path(".")
    _check_target(final, what, path)
    remove_stale_parts(directory)
    try:
        # (the name shortened, so that the temporary name stays within the file system's limit)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{final.name[:160]}.{_part_tag()}-",
                                        suffix=".part" + final.suffix[:16], dir=directory)
    except OSError as exc:
        raise OutputError(f"{what}: cannot write '{path}': {describe_oserror(exc)}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        with remove_on_exit(tmp):  # removed too if a CLI ends the process after an unanswered Ctrl-C
            os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; the result gets the permissions of open()
            yield tmp
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
            _check_target(final, what, path)  # again: what the computation read, or a link made meanwhile
            with critical():
                os.replace(tmp, final)
    except OSError as exc:
        _remove(tmp)
        raise OutputError(f"{what}: cannot write '{path}': {describe_oserror(exc)}") from None
    except BrakesquealError:
        _remove(tmp)
        raise
    except Exception as exc:  # a writer that turned an OSError into its own error (PDF: zlib.error, ...)
        _remove(tmp)
        cause = _oserror_in(exc)
        if cause is None:
            raise
        raise OutputError(f"{what}: cannot write '{path}': {describe_oserror(cause)}") from None
    except BaseException:
        _remove(tmp)
        raise


def write_with(path: str | os.PathLike[str], writer: Callable[[Path], _T], *, what: str = "output file") -> _T:
    """Call ``writer(temporary_path)`` and move the result to ``path`` atomically (see :func:`atomic_write`).

    Returns
    -------
    object
        What ``writer`` returned.
    """
    with atomic_write(path, what=what) as tmp:
        out = writer(tmp)
    return out


@contextlib.contextmanager
def write_set(directory: str | os.PathLike[str], *, what: str = "output directory") -> Iterator[Path]:
    """Write a set of files that belong together: all of them replace their predecessors, or none does.

    Yields a temporary directory inside ``directory``; the caller writes
    every file of the set into it under its final name.  When the block
    succeeds, each file is synced and the files are renamed into
    ``directory`` (a rename needs no space, so a full disk fails before
    any file is replaced; the renames run in a
    :func:`~brakesqueal.interrupts.critical` section, so a Ctrl-C never
    stops them half-way).  On any failure or interrupt the temporary
    directory is removed and the files already in ``directory`` are left
    as they were.

    Parameters
    ----------
    directory : str or path-like
        An existing, writable directory (see :func:`check_output_dir`).
    what : str, optional
        The option or role, for messages (e.g. ``"--out"``).

    Yields
    ------
    pathlib.Path
        The temporary directory to write the files into.

    Raises
    ------
    OutputError
        One line naming ``directory`` and the reason (``OSError`` of the
        writers or of the renames); the previous files are unchanged.

    Examples
    --------
    >>> with write_set("results") as tmp:                 # doctest: +SKIP
    ...     (tmp / "fig2.json").write_text(text)
    ...     figure.savefig(tmp / "fig2.png")
    """
    final = Path(os.fspath(directory))
    remove_stale_parts(final)
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{_part_tag()}-", suffix=".part", dir=final))
    except OSError as exc:
        raise OutputError(f"{what}: cannot write into '{directory}': {describe_oserror(exc)}") from None
    try:
        with remove_on_exit(stage):
            try:
                try:
                    yield stage
                except (BrakesquealError, OSError):
                    raise
                except Exception as exc:  # a writer that turned an OSError into its own error
                    cause = _oserror_in(exc)
                    if cause is None:
                        raise
                    raise cause from None
                files = sorted(p for p in stage.iterdir() if p.is_file())
                for f in files:  # every file of the set is checked before the first one replaces anything
                    _check_target(final / f.name, what, final / f.name)
                for f in files:
                    with open(f, "rb+") as fh:
                        os.fsync(fh.fileno())
                    os.chmod(f, 0o666 & ~_umask())
                with critical():
                    for i, f in enumerate(files):
                        try:
                            os.replace(f, final / f.name)
                        except OSError as exc:
                            if not i:
                                raise
                            raise OutputError(f"{what}: cannot move '{f.name}' into '{directory}': "
                                              f"{describe_oserror(exc)}; {i} of {len(files)} files were "
                                              "replaced") from None
            except OSError as exc:
                raise OutputError(f"{what}: cannot write the files into '{directory}': {describe_oserror(exc)}; "
                                  "the previous files are unchanged") from None
    finally:
        import shutil

        shutil.rmtree(stage, ignore_errors=True)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _remove(p: Path) -> None:
    with contextlib.suppress(OSError):
        p.unlink()


# ------------------------------------------------------------------ what a write never replaces
_KINDS = {stat.S_IFIFO: "a named pipe (FIFO)", stat.S_IFSOCK: "a socket", stat.S_IFCHR: "a character device",
          stat.S_IFBLK: "a block device"}


def _check_target(p: Path, what: str, path: str | os.PathLike[str]) -> None:
    """Refuse a symbolic link, a non-regular file, or an input of the running command at ``p`` (one line)."""
    try:
        st = os.lstat(p)
    except OSError:
        return  # nothing there (yet): nothing to replace
    if stat.S_ISLNK(st.st_mode):
        target = os.readlink(p)
        raise OutputError(f"{what}: cannot write '{path}': it is a symbolic link (to '{target}'); outputs never "
                          "replace a link or write through it: give the target's path or remove the link")
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{what}: cannot write '{path}': it is a directory")
    if not stat.S_ISREG(st.st_mode):
        kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a regular file")
        raise OutputError(f"{what}: cannot write '{path}': it is {kind}, not a regular file")
    source = _input_named(st)
    if source is not None:
        raise OutputError(f"{what}: cannot write '{path}': it is an input of this command ('{source}'); an "
                          "output never replaces an input: choose another file")


def _oserror_in(exc: BaseException) -> OSError | None:
    """The ``OSError`` that caused ``exc`` (its ``__cause__`` / ``__context__`` chain), if any."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, OSError):
            return e
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return None


# ------------------------------------------------------------------ the inputs of a command
_INPUTS: dict[str, Any] = {"depth": 0, "hooked": False, "read": {}, "named": []}


def _audit(event: str, args: tuple[Any, ...]) -> None:
    """Audit hook: record every regular file opened for reading while :func:`guard_inputs` is active."""
    if event != "open" or not _INPUTS["depth"]:
        return
    try:
        path, mode, flags = args
        if path is None or isinstance(path, int):
            return
        if mode is None:  # os.open
            if flags & os.O_ACCMODE != os.O_RDONLY:
                return
        elif any(c in mode for c in "wax+"):
            return
        st = os.stat(path)
        if stat.S_ISREG(st.st_mode):
            _INPUTS["read"].setdefault((st.st_dev, st.st_ino), os.fsdecode(path))
    except Exception:  # noqa: BLE001 - an audit hook must never fail the operation it watches
        return


def _named_files(args: Sequence[str]) -> list[tuple[int, int, str]]:
    """``(device, inode, text)`` of every argument (or ``--option=value`` value) naming an existing regular file."""
    out = []
    for a in args:
        for text in (a, a.partition("=")[2] if a.startswith("-") else ""):
            if not text:
                continue
            try:
                st = os.stat(text)
            except (OSError, ValueError):
                continue
            if stat.S_ISREG(st.st_mode):
                out.append((st.st_dev, st.st_ino, text))
    return out


def _input_named(st: os.stat_result) -> str | None:
    """The input of the running command that is the file ``st`` describes, if any."""
    if not _INPUTS["depth"]:
        return None
    key = (st.st_dev, st.st_ino)
    read = _INPUTS["read"].get(key)
    if read is not None:
        return str(read)
    same = [t for d, i, t in _INPUTS["named"] if (d, i) == key]
    # the output itself is named once on the command line (--out FILE); a second mention is an input
    return same[0] if len(same) > 1 else None


@contextlib.contextmanager
def guard_inputs(args: Sequence[str] = ()) -> Iterator[None]:
    """While a command runs: refuse every output that would replace one of its inputs.

    Every regular file the process opens for reading inside the block (a
    model, parameter, study or matrix file, read by any code through
    Python's ``open``/``os.open``, found by an audit hook) is an input; so
    is a file named twice in ``args`` (once as the output, once as
    something else).  :func:`check_output`, :func:`atomic_write` and
    :func:`write_set` then refuse, in one line, an output that is the same
    file (device and inode) as an input.  Nested blocks share the record.

    Parameters
    ----------
    args : sequence of str, optional
        The command line (lets a clash be refused before the inputs are read).

    Notes
    -----
    The audit hook (:func:`sys.addaudithook`) is added on first use and
    stays for the life of the process, inactive outside the block.  Library
    callers outside a block are not affected (a notebook may read a file and
    write it back).
    """
    if not _INPUTS["hooked"]:
        sys.addaudithook(_audit)
        _INPUTS["hooked"] = True
    outer = _INPUTS["depth"] == 0
    if outer:
        _INPUTS["read"] = {}
        _INPUTS["named"] = _named_files(args)
    _INPUTS["depth"] += 1
    try:
        yield
    finally:
        _INPUTS["depth"] -= 1
        if outer:
            _INPUTS["read"] = {}
            _INPUTS["named"] = []


# ------------------------------------------------------------------ temporary files of killed runs
_PART = re.compile(r"\.(?:.+\.)?brakesqueal-([0-9a-f]{8})-([0-9]+)-[a-z0-9_]{8}\.part(?:\.[^.]*)?")


def _host_tag() -> str:
    import hashlib
    import socket

    return hashlib.sha256(socket.gethostname().encode("utf-8", "replace")).hexdigest()[:8]


def _part_tag() -> str:
    """``brakesqueal-<host>-<pid>``: the writer of a temporary file, so a later run can tell a stale one."""
    return f"brakesqueal-{_host_tag()}-{os.getpid()}"


def process_start_ticks(pid: int) -> str | None:
    """Start time of process ``pid`` in clock ticks since boot (Linux ``/proc``), to detect PID reuse; ``None``
    when unknown (no such process, or no ``/proc``)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
        return stat.rsplit(b")", 1)[1].split()[19].decode()
    except (OSError, ValueError, IndexError):
        return None


def process_running(pid: int) -> bool:
    """Whether a process ``pid`` runs on this host (another user's counts: it cannot be signalled, but exists)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


def _process_start(pid: int) -> float | None:
    """Start time (seconds since the epoch) of process ``pid`` (Linux ``/proc``), or ``None``."""
    ticks = process_start_ticks(pid)
    if ticks is None:
        return None
    try:
        with open("/proc/stat", "rb") as f:
            btime = next(int(ln.split()[1]) for ln in f if ln.startswith(b"btime "))
        return btime + int(ticks) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, StopIteration):
        return None


def _writer_alive(pid: int, mtime: float) -> bool:
    """Whether process ``pid`` of this host may still be writing a file last modified at ``mtime``."""
    if pid == os.getpid():
        return True
    if not process_running(pid):
        return False
    start = _process_start(pid)
    # a process started after the file was last written cannot be its writer (the PID was reused)
    return start is None or start <= mtime + 2.0


def remove_stale_parts(directory: str | os.PathLike[str]) -> list[Path]:
    """Remove the temporary files and staging directories of writers that no longer run.

    Only names this module makes (``.<name>.brakesqueal-<host>-<pid>-<random>.part<suffix>``
    and ``.brakesqueal-<host>-<pid>-<random>.part``) of this host are
    considered, and only those whose process has ended (or whose PID now
    belongs to a process started after the file was last written).  Symbolic
    links are never followed or removed.  Errors are ignored (another run
    may remove the same file).

    Parameters
    ----------
    directory : str or path-like
        The directory about to be written into.

    Returns
    -------
    list of Path
        What was removed.
    """
    host = _host_tag()
    removed: list[Path] = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    for e in entries:
        m = _PART.fullmatch(e.name)
        if m is None or m[1] != host:
            continue
        try:
            st = e.stat(follow_symlinks=False)
            if _writer_alive(int(m[2]), st.st_mtime):
                continue
            if stat.S_ISDIR(st.st_mode):
                import shutil

                shutil.rmtree(e.path)
            elif stat.S_ISREG(st.st_mode):
                os.unlink(e.path)
            else:
                continue
        except OSError:
            continue
        removed.append(Path(e.path))
    return removed
