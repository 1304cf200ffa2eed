"""The limits and checks every input of brakesqueal goes through, in one place.

* Files: :func:`read_input` is the one reader of every model, parameter and study file (and
  :func:`check_input_file` the check of every other input file, such as coefficient matrices): only
  regular files are read (a FIFO, a device or a directory is refused before it is opened for reading, so
  nothing blocks), at most :data:`MAX_FILE_BYTES`, UTF-8.
* Texts: :func:`check_text` bounds, before a TOML or JSON text is parsed, how deeply arrays, tables and
  dotted keys nest (:data:`MAX_NESTING`) and how long one value is (:data:`MAX_TEXT_CHARS`);
  :func:`check_data` bounds the same of data given as Python objects and the length of keys
  (:data:`MAX_NAME_CHARS`); :func:`check_option` bounds a text option (``--preset``, ``--model``, ...).
* Numbers: :func:`number_problem` says why a decimal number *as typed* cannot be read as a double (it
  overflows to infinity or underflows to zero or below the normal range), so that every channel quotes
  the text the user wrote, never the ``inf`` or ``0.0`` it became.

Expression strings have their own limit (:data:`MAX_EXPRESSION_CHARS`, :mod:`brakesqueal.model.expressions`);
the arguments of public functions are checked by :mod:`brakesqueal.validation`.
"""

from __future__ import annotations

import math
import os
import re
import stat
import sys
from collections.abc import Mapping

from .errors import ParameterError

__all__ = ["MAX_FILE_BYTES", "MAX_NESTING", "MAX_TEXT_CHARS", "MAX_NAME_CHARS", "MAX_EXPRESSION_CHARS",
           "DOUBLE_MAX", "DOUBLE_MIN", "read_input", "check_input_file", "check_text", "check_data", "check_option",
           "number_problem", "shown"]

#: Largest model, parameter or study file read [bytes].
MAX_FILE_BYTES = 1 << 20
#: Deepest nesting of arrays, tables, inline tables and dotted keys in a TOML or JSON input (and in data given
#: as Python objects); the files of the project nest 4 deep at most.
MAX_NESTING = 32
#: Longest single value in an input file (a string, a number, a bare word) or a text option such as a path.
MAX_TEXT_CHARS = 4096
#: Longest key or name (a table key, a parameter, preset or model name).
MAX_NAME_CHARS = 128
#: Longest expression string (``"1800/mu"``; :mod:`brakesqueal.model.expressions`).
MAX_EXPRESSION_CHARS = 1000
#: Largest finite double.
DOUBLE_MAX = sys.float_info.max
#: Smallest normal positive double (below it precision is lost, below about 4.9e-324 every number is 0).
DOUBLE_MIN = sys.float_info.min


# ---------------------------------------------------------------------------------------------------- messages

def shown(value: object, limit: int = 60) -> str:
    """A short one-line ``repr`` of ``value`` for messages (long texts and deep containers elided)."""
    import reprlib

    r = reprlib.Repr()
    r.maxstring = r.maxother = limit
    r.maxlevel, r.maxlist, r.maxtuple, r.maxdict, r.maxset = 2, 4, 4, 4, 4
    try:
        text = " ".join(r.repr(value).split())
    except Exception:  # noqa: BLE001 - a repr that fails: its type is enough
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _line(text: str, pos: int) -> int:
    return text.count("\n", 0, pos) + 1


# ---------------------------------------------------------------------------------------------------- numbers

_OVERFLOWS = "overflows a double (max 1.8e308; write inf for an infinite value)"
_FLOAT_TEXT = re.compile(r"[+-]?(?:\d[\d_]*(?:\.[\d_]*)?|\.\d[\d_]*)(?:[eE][+-]?[\d_]+)?")


def number_problem(text: str) -> str | None:
    """Why a decimal number, as typed, cannot be read as a double; ``None`` if it can (or is no number).

    Parameters
    ----------
    text : str
        The number as typed (``"1e400"``, ``"-2.5e-330"``, ``"1_000"``); ``inf`` and ``infinity`` are
        infinite on purpose, and a mantissa of zeros is zero on purpose.

    Returns
    -------
    str or None
        ``"overflows a double (max 1.8e308; ...)"``, ``"underflows to 0 (...)"`` or ``"underflows (...)"``
        (below the smallest normal double, where digits are lost), to follow the number in a message.
    """
    t = text.strip()
    if not _FLOAT_TEXT.fullmatch(t):
        return None
    try:
        v = float(t.replace("_", ""))
    except (ValueError, OverflowError):
        return None
    if math.isinf(v):
        return _OVERFLOWS
    if abs(v) >= DOUBLE_MIN:
        return None
    mantissa = re.split("[eE]", t)[0]
    if not any(c in "123456789" for c in mantissa):
        return None  # a zero, typed as one
    if v == 0:
        return "underflows to 0 (the smallest normal double is 2.2e-308; write 0 for zero)"
    return "underflows (below 2.2e-308, the smallest normal double, digits are lost; write 0 for zero)"


# ---------------------------------------------------------------------------------------------------- files

def _describe_mode(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "a special file"


def _as_path(path: object, what: str) -> str:
    if isinstance(path, bool) or not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"{what} must be a file path (str or os.PathLike); got {shown(path)} "
                             f"({type(path).__name__})")
    p = os.fspath(path)
    if isinstance(p, bytes):
        p = os.fsdecode(p)
    if not p:
        raise ParameterError(f"{what} is an empty path")
    if len(p) > MAX_TEXT_CHARS:
        raise ParameterError(f"{what} path is {len(p)} characters long (at most {MAX_TEXT_CHARS})")
    return p


def check_input_file(path: object, what: str) -> str:
    """``path`` as a ``str`` if it names a regular file (symbolic links followed), else one ParameterError line.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages (``"model file"``).

    Returns
    -------
    str
        The path.

    Raises
    ------
    ParameterError
        Not a path (an ``int`` is never taken for a file descriptor), missing, or a directory, FIFO, device
        or socket (reading one could block forever or never end).
    """
    p = _as_path(path, what)
    try:
        st = os.stat(p)
    except OSError as exc:
        raise ParameterError(f"cannot read {what} '{p}': {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ParameterError(f"{what} '{p}' is {_describe_mode(st.st_mode)}, not a regular file; give a file")
    return p


def read_input(path: object, what: str, *, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The text of an input file: the one reader of every model, parameter and study file.

    The file is opened without blocking (a FIFO is refused, never waited for), must be a regular file of at
    most ``max_bytes`` bytes and UTF-8 text.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages (``"model file"``, ``"parameter file"``, ``"study file"``).
    max_bytes : int, optional
        The size limit (default :data:`MAX_FILE_BYTES`).

    Returns
    -------
    str

    Raises
    ------
    ParameterError
        One line naming the file: not a path, unreadable, not a regular file, too large, not UTF-8.
    """
    p = _as_path(path, what)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(p, flags)
    except OSError as exc:
        raise ParameterError(f"cannot read {what} '{p}': {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ParameterError(f"{what} '{p}' is {_describe_mode(st.st_mode)}, not a regular file; give a file")
        if st.st_size > max_bytes:
            raise ParameterError(f"{what} '{p}' is larger than {max_bytes // 1024} KiB; refusing to read it")
        chunks, size = [], 0
        while size <= max_bytes:
            chunk = os.read(fd, max_bytes + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise ParameterError(f"cannot read {what} '{p}': {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    raw = b"".join(chunks)
    if len(raw) > max_bytes:  # grew while read
        raise ParameterError(f"{what} '{p}' is larger than {max_bytes // 1024} KiB; refusing to read it")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{what} '{p}' is not UTF-8 text (byte {exc.start})") from None


# ---------------------------------------------------------------------------------------------------- texts

_SPECIAL = {"toml": re.compile(r"[\"'#\[\]{}]"), "json": re.compile(r"[\"\[\]{}]")}
_LONG_BARE = re.compile(r"[^\s\[\]{}\"',=#]{%d,}" % (MAX_TEXT_CHARS + 1))
# a dot of a dotted key: not the one dot of a number (1.5, 00:00:00.25), i.e. not between digits unless
# another dot follows in the same word (1.2.3 is a key of three parts)
_KEY_DOT = re.compile(r"(?<![0-9_])\.|\.(?![0-9_])|(?<=[0-9_])\.(?=[0-9_]*\.)")
_KEY_BREAK = re.compile(r"[=,\n]")  # a key ends at its '=' (or a line, or an item of an inline table)


def _string_end(text: str, start: int, quote: str) -> int:
    """Index just past the string starting at ``start`` (TOML/JSON rules; an unterminated one ends the line or
    the text)."""
    n = len(text)
    if text.startswith(quote * 3, start):  # multi-line
        pos = start + 3
        while True:
            k = text.find(quote * 3, pos)
            if k < 0:
                return n
            if quote == '"' and _escaped(text, k):
                pos = k + 1
                continue
            end = k + 3
            extra = 0
            while end < n and text[end] == quote and extra < 2:  # """a"""" ends with a quote inside
                end, extra = end + 1, extra + 1
            return end
    nl = text.find("\n", start)
    line_end = n if nl < 0 else nl
    pos = start + 1
    while True:
        k = text.find(quote, pos, line_end)
        if k < 0:
            return line_end
        if quote == '"' and _escaped(text, k):
            pos = k + 1
            continue
        return k + 1


def _escaped(text: str, k: int) -> bool:
    """Whether the character at ``k`` follows an odd number of backslashes."""
    j = k
    while j > 0 and text[j - 1] == "\\":
        j -= 1
    return (k - j) % 2 == 1


def check_text(text: str, where: str, *, syntax: str = "toml") -> None:
    """Refuse a TOML or JSON text that nests too deeply or holds a too long value, before it is parsed.

    One pass over the text, outside strings and comments: brackets and braces (arrays, tables, inline
    tables) and the parts of dotted keys (``a.b.c``) count as nesting, at most :data:`MAX_NESTING`; a string,
    number or bare word is at most :data:`MAX_TEXT_CHARS` characters long.  (A parser recurses per level:
    thousands of levels end in a ``RecursionError``.)

    Parameters
    ----------
    text : str
        The text.
    where : str
        How messages name it (``"model file 'm.toml'"``).
    syntax : {"toml", "json"}, optional
        TOML (also ``'...'`` strings, ``#`` comments and dotted keys) or JSON.

    Raises
    ------
    ParameterError
        One line naming ``where``, the line and the limit.
    """
    special = _SPECIAL[syntax]
    toml = syntax == "toml"
    most = MAX_NESTING + (not toml)  # a JSON document's top-level table has braces, a TOML one has none
    n = len(text)
    depth = chain = 0
    i = 0

    def too_deep(pos: int, what: str) -> ParameterError:
        return ParameterError(f"{where}: {what} nest more than {MAX_NESTING} deep at line {_line(text, pos)} "
                              f"(at most {MAX_NESTING} levels)")

    while i <= n:
        m = special.search(text, i)
        end = m.start() if m else n
        if end > i:
            if end - i > MAX_TEXT_CHARS:
                long = _LONG_BARE.search(text, i, end)
                if long:
                    run = re.match(r"[^\s\[\]{}\"',=#]*", text[long.start():end]).end()  # type: ignore[union-attr]
                    raise ParameterError(f"{where}: a value at line {_line(text, long.start())} is {run} characters "
                                         f"long (at most {MAX_TEXT_CHARS})")
            last = max(text.rfind("=", i, end), text.rfind(",", i, end), text.rfind("\n", i, end))
            if toml and text.find(".", i, end) >= 0:
                if chain + len(_KEY_DOT.findall(text, i, end)) >= MAX_NESTING:  # look closer: key by key
                    pos = i
                    for brk in _KEY_BREAK.finditer(text, i, end):
                        if chain + len(_KEY_DOT.findall(text, pos, brk.start())) >= MAX_NESTING:
                            raise too_deep(pos, "dotted keys")
                        chain, pos = 0, brk.end()
                    if chain + len(_KEY_DOT.findall(text, pos, end)) >= MAX_NESTING:
                        raise too_deep(pos, "dotted keys")
                chain = (len(_KEY_DOT.findall(text, last + 1, end)) if last >= 0 else
                         chain + len(_KEY_DOT.findall(text, i, end)))
            elif last >= 0:
                chain = 0
        if m is None:
            return
        c = m.group()
        i = m.end()
        if c in "[{":
            depth += 1
            chain = 0
            if depth > most:
                raise too_deep(m.start(), "arrays and tables")
        elif c in "]}":
            depth = max(0, depth - 1)
            chain = 0
        elif c == "#":
            k = text.find("\n", i)
            i = n if k < 0 else k
        else:  # a string
            stop = _string_end(text, m.start(), c)
            if stop - m.start() > MAX_TEXT_CHARS + 6:
                raise ParameterError(f"{where}: a string at line {_line(text, m.start())} is "
                                     f"{stop - m.start()} characters long (at most {MAX_TEXT_CHARS})")
            i = stop


def check_data(data: object, where: str) -> None:
    """Refuse data (as parsed, or given as Python objects) that nests too deeply, has a too long key or string,
    or an integer beyond the double range; iteratively (no recursion) and before anything else reads it.

    Parameters
    ----------
    data : object
        Dicts, lists and tuples of scalars.
    where : str
        How messages name the data.

    Raises
    ------
    ParameterError
        Deeper than :data:`MAX_NESTING`, a key longer than :data:`MAX_NAME_CHARS`, a string longer than
        :data:`MAX_TEXT_CHARS`, an integer of magnitude beyond :data:`DOUBLE_MAX`.
    """
    stack: list[tuple[object, int, str]] = [(data, 0, "")]
    seen: set[int] = set()
    while stack:
        obj, depth, key = stack.pop()
        at = f" at '{key if len(key) <= 80 else '...' + key[-77:]}'" if key else ""
        if isinstance(obj, str):
            if len(obj) > MAX_TEXT_CHARS:
                raise ParameterError(f"{where}: the value{at} is {len(obj)} characters long (at most "
                                     f"{MAX_TEXT_CHARS})")
        elif isinstance(obj, int) and not isinstance(obj, bool):
            if abs(obj) > DOUBLE_MAX:
                if obj.bit_length() < 13000:  # str() of larger integers is refused by Python
                    digits = str(abs(obj))
                    typed = digits if len(digits) <= 24 else f"{digits[:12]}... ({len(digits)} digits)"
                else:
                    typed = f"of about {int(obj.bit_length() * math.log10(2)) + 1} digits"
                raise ParameterError(f"{where}: the number {'-' if obj < 0 else ''}{typed}{at} {_OVERFLOWS}")
        elif isinstance(obj, (Mapping, list, tuple)):
            if depth > MAX_NESTING:
                raise ParameterError(f"{where}: tables and arrays nest more than {MAX_NESTING} deep{at} (at most "
                                     f"{MAX_NESTING} levels)")
            if id(obj) in seen:
                raise ParameterError(f"{where}: the data{at} contains itself")
            seen.add(id(obj))
            items = obj.items() if isinstance(obj, Mapping) else enumerate(obj)
            for k, v in items:
                if isinstance(k, str) and len(k) > MAX_NAME_CHARS:
                    raise ParameterError(f"{where}: a key{at} is {len(k)} characters long (at most "
                                         f"{MAX_NAME_CHARS}): {shown(k, 40)}")
                part = (f".{k}" if key else k) if isinstance(k, str) else f"[{k}]"
                stack.append((v, depth + 1, key + part))


def check_option(value: object, option: str, *, name: bool = False) -> str | None:
    """A text option (``--preset``, ``--model``, ``--params``) checked before it is looked up.

    Parameters
    ----------
    value : str or None
        The option's value (``None``: not given).
    option : str
        The option, for messages (``"--preset"``).
    name : bool, optional
        The value is a name (at most :data:`MAX_NAME_CHARS`), not a path or text (:data:`MAX_TEXT_CHARS`).

    Returns
    -------
    str or None
        ``value``.

    Raises
    ------
    ParameterError
        Not a string, empty, or too long (the value is not echoed).
    """
    if value is None:
        return None
    if isinstance(value, os.PathLike) and not name:
        value = os.fspath(value)
    if not isinstance(value, str):
        raise ParameterError(f"{option} must be a string; got {shown(value)} ({type(value).__name__})",
                             parameter=option.lstrip("-"))
    most = MAX_NAME_CHARS if name else MAX_TEXT_CHARS
    if not value.strip():
        raise ParameterError(f"{option} is empty; give a {'name' if name else 'value'} or leave the option out",
                             parameter=option.lstrip("-"))
    if len(value) > most:
        raise ParameterError(f"{option} is {len(value)} characters long (at most {most})",
                             parameter=option.lstrip("-"))
    return value
