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
:class:`~brakesqueal.errors.OutputError` with one line naming the file.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TypeVar

from .errors import OutputError
from .interrupts import critical, remove_on_exit

__all__ = ["check_output", "check_output_dir", "atomic_write", "write_with", "write_set", "describe_oserror"]

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
        One line: wrong suffix, missing or unwritable directory, or a
        directory in the file's place.
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
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{final.name}.", suffix=".part" + final.suffix, dir=directory)
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
            with critical():
                os.replace(tmp, final)
    except OSError as exc:
        _remove(tmp)
        raise OutputError(f"{what}: cannot write '{path}': {describe_oserror(exc)}") from None
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
    try:
        stage = Path(tempfile.mkdtemp(prefix=".brakesqueal-", suffix=".part", dir=final))
    except OSError as exc:
        raise OutputError(f"{what}: cannot write into '{directory}': {describe_oserror(exc)}") from None
    try:
        with remove_on_exit(stage):
            try:
                yield stage
                files = sorted(p for p in stage.iterdir() if p.is_file())
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
