"""Read a text file (UTF-8, a byte-order mark read past); write a file whole or not at all,
and a set of files (a run's folder, a day's files) all or none (:func:`written_together`)."""

from __future__ import annotations

import os
import secrets
import shutil
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import AbstractContextManager, ExitStack, contextmanager, suppress
from contextvars import ContextVar
from pathlib import Path
from typing import BinaryIO, TextIO, TypeVar

from skyroute.errors import InputFormatError, OptionError, SkyrouteError

T = TypeVar("T")
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
        raise cannot_read(path, exc) from None
    except UnicodeDecodeError as exc:
        raise InputFormatError(path, f"cannot read: not UTF-8 text ({exc.reason} at "
                               f"byte {exc.start})") from None


def cannot_read(path: str | Path, exc: OSError) -> InputFormatError:
    """The error for a file that could not be opened, in the words every reader uses:
    ``PATH: no such file``, ``PATH: a folder, not a file``, else ``PATH: cannot read:
    <the system's reason>`` (its strerror: the path is named once, not twice). One
    wording for every command: ``fleet simulate`` said "cannot read: No such file or
    directory" where ``plan`` said "no such file"."""
    if isinstance(exc, FileNotFoundError):
        return InputFormatError(path, "no such file")
    if isinstance(exc, IsADirectoryError):
        return InputFormatError(path, "a folder, not a file")
    return InputFormatError(path, f"cannot read: {exc.strerror or exc}")


def need_folder(path: str | Path, what: str = "") -> Path:
    """``path`` as a Path when it is a folder, else ``PATH: no such folder`` (or ``PATH:
    not a folder``, ``what`` after it: ``not a folder of .map and .scen files``) as an
    :class:`InputFormatError`. Checked before any file inside is looked for, so a
    mistyped folder is named as the user typed it, not as ``DIR/database/orders.csv``."""
    path = Path(path)
    if not path.exists():
        raise InputFormatError(path, "no such folder")
    if not path.is_dir():
        raise InputFormatError(path, "not a folder" + (f" {what}" if what else ""))
    return path


def open_text(path: str | Path) -> TextIO:
    """``path`` open for reading as :mod:`csv` wants it (``newline=""``), UTF-8 with a
    byte-order mark read past, for a file read row by row; the caller turns OSError
    and UnicodeDecodeError into an error naming the file."""
    return Path(path).open(encoding="utf-8-sig", newline="")


def lone_surrogate(text: str) -> int | None:
    """The index of the first lone surrogate in ``text`` (U+D800..U+DFFF: half of a
    UTF-16 pair, no character; JSON's ``"\\ud800"`` and YAML's read as one), or None.
    Such text cannot be written as UTF-8: not to a file, a terminal or a store."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        return exc.start
    return None


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


class Together:
    """What a :func:`written_together` block holds: its staged files (temporary file, its
    place, the folders made for it) and the transactions it ends (:meth:`enter`)."""

    def __init__(self) -> None:
        # tmp "" a write that failed, None a file to remove (remove_atomic)
        self.staged: list[tuple[str | None, Path, list[Path]]] = []
        self.ends = ExitStack()

    def enter(self, transaction: AbstractContextManager[T]) -> T:
        """Enter ``transaction`` (e.g. :func:`skyroute.delivery.store.writing`) now and
        leave it when the block ends: without an error (committed) once every file is
        renamed into place, before their earlier versions are dropped, so a commit that
        fails puts the files back; with the error (rolled back) when the block raises
        or a rename fails. What it returns (the connection)."""
        return self.ends.enter_context(transaction)


# the innermost written_together block of this thread
_TOGETHER: ContextVar[Together | None] = ContextVar("skyroute_together", default=None)


@contextmanager
def open_atomic(path: str | Path) -> Iterator[BinaryIO]:
    """A binary file to write ``path`` through: a temporary file beside it, renamed into
    place when the block ends (inside :func:`written_together`, when that block ends),
    removed if it raises. Parent folders are created. A
    folder that cannot be made or a file that cannot be written (no permission, a full
    disk, ``path`` a folder) is a SkyrouteError naming ``path``; nothing is left behind.
    The block should only write the file: an OSError raised in it is reported as such.
    """
    path = Path(path)
    together = _TOGETHER.get()
    staged = None if together is None else together.staged
    made = _folders_for(path)
    # the temporary file's name is known before it exists: a Ctrl-C the moment it is
    # made (mkstemp's name not yet returned) left it behind
    tmp = str(path.parent / f".{path.name}.{secrets.token_hex(8)}.tmp")
    try:
        fd = _create(tmp, path)
        with os.fdopen(fd, "wb") as f:
            yield f
        os.chmod(tmp, _MODE)
        if staged is None:
            os.replace(tmp, path)
        else:
            _stage(staged, tmp, path, made)
    except OSError as exc:
        _failed(staged, tmp, path, made)
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    except BaseException:
        _failed(staged, tmp, path, made)
        raise


@contextmanager
def written_together() -> Iterator[Together]:
    """Every file :func:`open_atomic` or :func:`write_atomic` writes in this block (in
    this thread) appears when the block ends, or none does if it raises (nor a folder
    made for one): a Ctrl-C or an error while a fleet run's folder or a delivery day's
    files were written left some of them new and the others missing, or an earlier
    run's. Each is written to a temporary file beside its place as the block goes, and
    they are renamed into place one after another when it ends (a rename each,
    microseconds). A rename that fails there (a full disk, a file system error) puts
    back the files renamed before it: each file's earlier version is kept as a hard link
    beside it until every rename has succeeded, so a failure leaves every file as it was
    (a new one gone), and the error names the file whose rename failed. A reader sees
    each file whole, old or new; one that reads several in the instant of the renames
    may see some new and the others old. A block inside another joins it.

    The block's :class:`Together` takes a database transaction that must change with
    the files (:meth:`Together.enter`: a delivery day's rows): it is committed after
    every rename, before the earlier versions are dropped, and a commit that fails puts
    every file back; an error in the block or a failed rename rolls it back. The
    renames and the commit are one step for SIGINT and SIGTERM (held until both are
    done, or both undone). Only a crash of the process (SIGKILL, power) between the
    last rename and the commit can leave the files new and the rows old.
    """
    outer = _TOGETHER.get()
    if outer is not None:
        yield outer
        return
    together = Together()
    token = _TOGETHER.set(together)
    try:
        yield together
    except BaseException:
        _TOGETHER.reset(token)
        _discard(together.staged)
        if not together.ends.__exit__(*sys.exc_info()):  # the transactions rolled back
            raise
        return
    _TOGETHER.reset(token)
    _rename_all(together)


def _rename_all(together: Together) -> None:
    """Rename every staged file into place and commit the block's transactions, or (an
    OSError, a failed commit, a Ctrl-C before the signals are held) neither: the files
    renamed before a failure are put back as they were, the transactions rolled back."""
    staged = together.staged
    backups: dict[Path, str] = {}  # place -> its earlier version, a hard link beside it
    done = 0  # the files renamed into place
    failed = None  # the file being backed up or renamed when it failed
    committed = False
    try:
        # one step: a signal in the renames (a rename each, a round trip each on NFS)
        # left the first files new and the others removed, a mix of two runs; nor may
        # one come between the renames and the commit
        with _signals_held():
            for tmp, path, _ in staged:
                failed = path
                if (tmp or tmp is None) and os.path.lexists(path):
                    backups[path] = _backup(path)
            for tmp, path, _ in staged:
                failed = path
                if tmp:
                    os.replace(tmp, path)
                elif tmp is None and path in backups:  # removed (its backup kept)
                    os.unlink(path)
                done += 1
            failed = None
            together.ends.close()  # commit (a failure rolls back what is left, and raises)
            committed = True
    except BaseException as exc:
        if committed:  # a signal held through the renames and the commit, taken after them
            raise
        _put_back(staged[:done], backups)
        _discard(staged)
        # roll back (a commit that failed has ended its transactions already)
        together.ends.__exit__(type(exc), exc, exc.__traceback__)
        if isinstance(exc, OSError) and failed is not None:
            raise SkyrouteError(f"{failed}: cannot write: {exc.strerror or exc}") from None
        raise
    finally:
        for backup in backups.values():  # (those put back are no longer listed)
            with suppress(OSError):
                os.unlink(backup)


def _backup(path: Path) -> str:
    """A hard link to ``path`` beside it (a copy where the file system has no hard
    links): its version before a written_together block's renames; the link's name."""
    backup = str(path.parent / f".{path.name}.{secrets.token_hex(8)}.bak")
    try:
        os.link(path, backup, follow_symlinks=False)
    except OSError:
        try:
            shutil.copy2(path, backup, follow_symlinks=False)
        except BaseException:
            with suppress(OSError):
                os.unlink(backup)
            raise
    return backup


def _put_back(renamed: list[tuple[str, Path, list[Path]]], backups: dict[Path, str]) -> None:
    """Undo the renames of ``renamed``: each earlier version back in place (its backup
    taken off ``backups``), a file that was new removed. A backup that cannot be put
    back is left beside its file (the earlier version is not lost)."""
    for tmp, path, _ in renamed:
        if not tmp and not (tmp is None and path in backups):
            continue  # a failed write, or a removal of a file that was not there
        with suppress(OSError):
            if path in backups:
                os.replace(backups.pop(path), path)
            else:
                os.unlink(path)


@contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held while the block runs (in the main thread, where Python
    runs signal handlers): one that comes is handled, by the handler it would have met,
    when the block ends."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came: list[int] = []
    before: dict[int, object] = {}
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is None:  # set outside Python: cannot be put back
                continue
            before[sig] = signal.signal(sig, lambda signum, _frame: came.append(signum))
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(came):
            signal.raise_signal(sig)


def _stage(staged: list, tmp: str | None, path: Path, made: list[Path]) -> None:
    """Add ``tmp`` to be renamed to ``path``; a file staged for ``path`` before (written
    twice in one block) is dropped: the later one wins, as it would have."""
    for k, (old, place, _) in enumerate(staged):
        if place == path:
            if old:
                Path(old).unlink(missing_ok=True)
            staged[k] = (tmp, path, staged[k][2] + made)
            return
    staged.append((tmp, path, made))


def _failed(staged: list | None, tmp: str, path: Path, made: list[Path]) -> None:
    """A write that failed: its temporary file removed; in a written_together block, the
    folders made for it are the block's to remove with the others'."""
    Path(tmp).unlink(missing_ok=True)
    if staged is not None:
        staged.append(("", path, made))


def _discard(staged: list) -> None:
    """Remove the temporary files, then the folders made for them that are empty
    (deepest first)."""
    for tmp, _, _ in staged:
        if tmp:
            Path(tmp).unlink(missing_ok=True)
    for folder in sorted({f for _, _, made in staged for f in made},
                         key=lambda f: len(f.parts), reverse=True):
        with suppress(OSError):  # not empty (another writer's file), or gone
            folder.rmdir()


def remove_atomic(path: str | Path) -> None:
    """Remove the file ``path`` when the :func:`written_together` block ends, with its
    renames, or not at all (kept when the block fails); outside a block, now. A file
    an earlier run left beside the ones a block writes (a fleet run's maps, not drawn
    this time) would otherwise be read as this run's."""
    path = Path(path)
    together = _TOGETHER.get()
    if together is None:
        path.unlink(missing_ok=True)
        return
    _stage(together.staged, None, path, [])


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
    # named before it is made, as in open_atomic, so a Ctrl-C cannot leave it behind
    tmp = str(here / f".{path.name}.{secrets.token_hex(8)}.tmp")
    try:
        os.close(_create(tmp, path))
    finally:
        with suppress(FileNotFoundError):
            os.unlink(tmp)
    return path


def _folders_for(path: Path) -> list[Path]:
    """Make ``path``'s folder if missing; the folders made, outermost first."""
    made = [p for p in reversed(path.parents) if not os.path.lexists(p)]
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):  # a file where a folder must be
        blocker = next(p for p in path.parents if os.path.lexists(p))
        raise SkyrouteError(f"{path}: cannot write: {blocker} is not a folder") from None
    except OSError as exc:
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    return made


def _create(tmp: str, path: Path) -> int:
    """Create ``tmp`` (new, owner-only, as mkstemp does) for writing ``path``; its fd. A
    failure is a SkyrouteError naming ``path``."""
    try:
        return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0),
                       0o600)
    except OSError as exc:
        raise SkyrouteError(f"{path}: cannot write: {exc.strerror or exc}") from None
