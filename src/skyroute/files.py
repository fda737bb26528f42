"""Read a text file (UTF-8, a byte-order mark read past); write a file whole or not at all."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO, TextIO

from skyroute.errors import InputFormatError, OptionError, SkyrouteError

BOM = "\ufeff"  # a UTF-8 byte-order mark: Excel's "CSV UTF-8" and Notepad start with one


def read_text(path: str | Path, *, max_bytes: int | None = None,
              kind: str = "a file") -> str:
    """``path``'s text, read as UTF-8 with a byte-order mark read past (every input
    reader comes through here, so a first field never reads as ``'\\ufefforderNo'``)
    and CRLF read as LF; a file that cannot be read or is not UTF-8, or (before it is
    read) one past ``max_bytes``, is an :class:`InputFormatError` naming it (``kind``:
    what the limit is for, in that message)."""
    try:
        if max_bytes is not None and (size := Path(path).stat().st_size) > max_bytes:
            raise InputFormatError(path, f"{size:,} bytes, over the limit of {max_bytes:,} "
                                   f"for {kind}")
        return Path(path).read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputFormatError(path, f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise InputFormatError(path, f"cannot read: not UTF-8 text ({exc.reason} at "
                               f"byte {exc.start})") from None


def open_text(path: str | Path) -> TextIO:
    """``path`` open for reading as :mod:`csv` wants it (``newline=""``), UTF-8 with a
    byte-order mark read past, for a file read row by row; the caller turns OSError
    and UnicodeDecodeError into an error naming the file."""
    return Path(path).open(encoding="utf-8-sig", newline="")


def strip_bom(data: str | bytes) -> str | bytes:
    """``data`` without a leading byte-order mark: text already in hand (an upload, an
    HTTP answer) or bytes."""
    if isinstance(data, bytes):
        return data.removeprefix(BOM.encode())
    return data.removeprefix(BOM)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# mkstemp makes files only the owner can read; outputs get the usual mode instead
_MODE = 0o666 & ~_umask()


@contextmanager
def open_atomic(path: str | Path) -> Iterator[BinaryIO]:
    """A binary file to write ``path`` through: a temporary file beside it, renamed into
    place when the block ends, removed if it raises. Parent folders are created. A
    folder that cannot be made or a file that cannot be written (no permission, a full
    disk, ``path`` a folder) is a SkyrouteError naming ``path``; nothing is left behind.
    The block should only write the file: an OSError raised in it is reported as such.
    """
    path = Path(path)
    fd, tmp = _temp_beside(path)
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
        os.chmod(tmp, _MODE)
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` whole or not at all (:func:`open_atomic`)."""
    with open_atomic(path) as f:
        f.write(data.encode() if isinstance(data, str) else data)
    return Path(path)


def as_path(value: object, param: str) -> Path:
    """``value`` as a Path when it is a str or path-like; an OptionError naming ``param``
    otherwise (``Path(None)`` is a bare TypeError)."""
    if not isinstance(value, str | os.PathLike):
        raise OptionError(f"{param} must be a file path, got {type(value).__name__}",
                          param=param)
    return Path(value)


def check_writable(path: str | Path) -> Path:
    """Fail now where :func:`open_atomic` would fail at the end of a long run: ``path``
    a folder, a file where a folder must be, no permission. Leaves nothing behind, no
    file and no folder: missing parent folders are made by the write, and their nearest
    existing one is tried instead (a command that failed after the check left an empty
    ``--out`` folder it had made)."""
    path = Path(path)
    if path.is_dir():
        raise SkyrouteError(f"{path}: cannot write: it is a folder")
    here = next(p for p in path.parents if os.path.lexists(p))
    if not here.is_dir():  # a file, or a link to nothing, where a folder must be
        raise SkyrouteError(f"{path}: cannot write: {here} is not a folder")
    fd, tmp = _temp_in(here, path)
    os.close(fd)
    os.unlink(tmp)
    return path


def _temp_beside(path: Path) -> tuple[int, str]:
    """A new temporary file in ``path``'s folder (made if missing): (fd, its path)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):  # a file where a folder must be
        blocker = next(p for p in path.parents if os.path.lexists(p))
        raise SkyrouteError(f"{path}: cannot write: {blocker} is not a folder") from None
    except OSError as exc:
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    return _temp_in(path.parent, path)


def _temp_in(folder: Path, path: Path) -> tuple[int, str]:
    """A new temporary file for ``path`` in ``folder`` (which exists): (fd, its path); a
    failure is a SkyrouteError naming ``path``."""
    try:
        return tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as exc:
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
