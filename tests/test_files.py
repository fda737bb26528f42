"""write_atomic: whole files with the usual permissions, nothing left behind on failure."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyroute.files import write_atomic
from tests.rename_failures import earlier_versions, failing_rename


def test_written_files_get_the_umask_mode_not_mkstemps_private_one(tmp_path):
    mask = os.umask(0o022)
    try:
        import importlib

        import skyroute.files as files

        importlib.reload(files)  # the mode is read from the umask at import
        p = files.write_atomic(tmp_path / "a" / "out.txt", "hello")
    finally:
        os.umask(mask)
    assert p.read_text() == "hello"
    assert stat.S_IMODE(p.stat().st_mode) == 0o644
    assert sorted(x.name for x in p.parent.iterdir()) == ["out.txt"]


def test_a_failed_write_leaves_no_file(tmp_path):
    with pytest.raises(TypeError):
        write_atomic(tmp_path / "x.bin", 123)  # not bytes nor str
    assert list(tmp_path.iterdir()) == []


def test_open_atomic_streams_and_renames(tmp_path):
    from skyroute.files import open_atomic

    target = tmp_path / "deep" / "index.npz"
    with open_atomic(target) as f:
        f.write(b"abc")
        assert not target.exists()  # nothing at the path until the block ends
    assert target.read_bytes() == b"abc"
    assert sorted(x.name for x in target.parent.iterdir()) == ["index.npz"]


def test_an_unwritable_path_is_one_error_naming_it(tmp_path):
    from skyroute.errors import SkyrouteError
    from skyroute.files import open_atomic

    blocker = tmp_path / "file"
    blocker.write_text("x")
    message = r"file/sub/out\.bin: cannot write: .*/file is not a folder"
    with pytest.raises(SkyrouteError, match=message):
        write_atomic(blocker / "sub" / "out.bin", b"data")  # a file where a folder must be
    folder = tmp_path / "folder"
    folder.mkdir()
    # the target itself a folder: the rename fails
    with pytest.raises(SkyrouteError, match=r"folder: cannot write"), open_atomic(folder) as f:
        f.write(b"data")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["file", "folder"]
    assert list(folder.iterdir()) == []


def test_a_dangling_link_in_the_way_is_named(tmp_path):
    from skyroute.errors import SkyrouteError

    link = tmp_path / "link"
    link.symlink_to(tmp_path / "gone")
    with pytest.raises(SkyrouteError, match=r"cannot write: .*/link is not a folder"):
        write_atomic(link / "out.bin", b"data")


def test_check_writable_fails_where_writing_would(tmp_path):
    from skyroute.errors import SkyrouteError
    from skyroute.files import check_writable

    (tmp_path / "afile").write_text("x")
    with pytest.raises(SkyrouteError, match=r"afile/r.json: cannot write: .*afile is not a folder"):
        check_writable(tmp_path / "afile" / "r.json")
    with pytest.raises(SkyrouteError, match="cannot write: it is a folder"):
        check_writable(tmp_path)
    assert check_writable(tmp_path / "new" / "deeper" / "r.json").name == "r.json"
    assert sorted(tmp_path.iterdir()) == [tmp_path / "afile"]  # no folder, no file left
    (tmp_path / "ro").mkdir(mode=0o500)
    if not os.access(tmp_path / "ro", os.W_OK):  # (root may write anywhere)
        with pytest.raises(SkyrouteError, match=r"ro/new/r.json: cannot write: Permission"):
            check_writable(tmp_path / "ro" / "new" / "r.json")


def test_written_together_appear_together_or_not_at_all(tmp_path):
    from skyroute.files import written_together

    out = tmp_path / "run"
    (tmp_path / "keep.txt").write_text("earlier")
    with pytest.raises(KeyboardInterrupt), written_together():
        write_atomic(tmp_path / "keep.txt", "new")
        write_atomic(out / "deep" / "a.txt", "a")
        assert not (out / "deep" / "a.txt").exists()  # nothing in place before the end
        raise KeyboardInterrupt  # Ctrl-C before the set is whole
    # the earlier file kept, no temporary file, no folder made for the set left behind
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]
    assert (tmp_path / "keep.txt").read_text() == "earlier"
    with written_together():
        write_atomic(tmp_path / "keep.txt", "first")
        write_atomic(out / "a.txt", "a")
        write_atomic(tmp_path / "keep.txt", "second")  # written twice: the later wins
    assert (tmp_path / "keep.txt").read_text() == "second"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt", "run"]
    assert [p.name for p in out.iterdir()] == ["a.txt"]


class _StopError(Exception):
    pass


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_while_a_set_is_renamed_into_place_leaves_it_whole(tmp_path, monkeypatch,
                                                                    sig):
    """The renames at the end of a written_together block are one step: Ctrl-C (or
    SIGTERM) after the first of them left that file new and the rest as the earlier run
    had them (the rest removed), a mix of two runs; the rename loop lasts a rename per
    file (thousands for a data set, each a round trip on NFS). The signal now takes
    effect once every file is in place."""
    import signal

    from skyroute import files

    signum = getattr(signal, sig)

    def stop(*_):
        raise _StopError

    names = [f"f{k}.txt" for k in range(5)]
    for name in names:
        (tmp_path / name).write_text("earlier")
    real, renamed = os.replace, []

    def replace(a, b):
        real(a, b)
        renamed.append(Path(b).name)
        if len(renamed) == 1:
            signal.raise_signal(signum)  # arrives right after the first rename

    before = signal.signal(signum, stop)  # SIGTERM's default would end pytest
    try:
        monkeypatch.setattr(files.os, "replace", replace)
        with pytest.raises(_StopError), files.written_together():
            for name in names:
                write_atomic(tmp_path / name, "new")
        monkeypatch.undo()
    finally:
        signal.signal(signum, before)
    assert renamed == names
    assert {p.name: p.read_text() for p in tmp_path.iterdir()} == dict.fromkeys(names, "new")


@pytest.mark.parametrize("fail_at", [1, 2])
def test_a_rename_failing_part_way_leaves_every_file_as_it_was(tmp_path, monkeypatch,
                                                                fail_at):
    """The k-th rename at the end of a written_together block fails (a full disk, a file
    system error): the files renamed before it were left new and the later ones old (or
    missing), a day half written. Now every file is as before the block (an earlier
    version back in place, a new file gone), no temporary or backup file is left, and the
    error is one line naming the file that failed."""
    import skyroute.files as files
    from skyroute.errors import SkyrouteError

    (tmp_path / "b.txt").write_text("old b")  # an earlier run's; a.txt and c.txt are new
    (tmp_path / "c.txt").write_text("old c")
    failing_rename(monkeypatch, fail_at + 1)
    names = ["a.txt", "b.txt", "c.txt", "sub/d.txt"]
    with pytest.raises(SkyrouteError) as err, files.written_together():
        for name in names:
            files.write_atomic(tmp_path / name, f"new {name}")
    failed = names[fail_at]
    assert str(err.value) == f"{tmp_path / failed}: cannot write: No space left on device"
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == \
        ["b.txt", "c.txt"]
    assert (tmp_path / "b.txt").read_text() == "old b"
    assert (tmp_path / "c.txt").read_text() == "old c"


@given(st.lists(st.booleans(), min_size=1, max_size=5), st.integers(0, 6))
@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_written_together_is_all_or_none_whichever_rename_fails(tmp_path_factory, existed,
                                                                 fail_at):
    """Any number of files, some with an earlier version, the rename numbered ``fail_at``
    failing (past the last: none fails): afterwards the folder holds either every new
    version or exactly what it held before, and nothing else."""
    import skyroute.files as files
    from skyroute.errors import SkyrouteError

    here = tmp_path_factory.mktemp("together")
    before = earlier_versions(here, existed)
    with pytest.MonkeyPatch.context() as mp:
        failing_rename(mp, fail_at + 1, errno=5, message="Input/output error")
        try:
            with files.written_together():
                for k in range(len(existed)):
                    files.write_atomic(here / f"f{k}", f"new {k}")
        except SkyrouteError as exc:
            assert fail_at < len(existed) and "\n" not in str(exc)
            assert str(exc).startswith(f"{here / f'f{fail_at}'}: cannot write: ")
            expected = before
        else:
            assert fail_at >= len(existed)
            expected = {f"f{k}": f"new {k}" for k in range(len(existed))}
    assert {p.name: p.read_text() for p in here.iterdir()} == expected


def test_remove_atomic_goes_with_the_renames_or_not_at_all(tmp_path, monkeypatch):
    import skyroute.files as files
    from skyroute.errors import SkyrouteError

    (tmp_path / "old.png").write_text("an earlier run's")
    with monkeypatch.context() as m:  # the second rename fails: nothing changes
        failing_rename(m, 2)
        with pytest.raises(SkyrouteError), files.written_together():
            files.write_atomic(tmp_path / "a.txt", "new a")
            files.remove_atomic(tmp_path / "old.png")
            files.write_atomic(tmp_path / "b.txt", "new b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.png"]
    assert (tmp_path / "old.png").read_text() == "an earlier run's"
    with pytest.raises(KeyboardInterrupt), files.written_together():  # an error in it
        files.remove_atomic(tmp_path / "old.png")
        raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.png"]
    with files.written_together():
        files.write_atomic(tmp_path / "a.txt", "new a")
        files.remove_atomic(tmp_path / "old.png")
        files.remove_atomic(tmp_path / "never.png")  # not there: nothing to do
        files.write_atomic(tmp_path / "c.txt", "written, then removed")
        files.remove_atomic(tmp_path / "c.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    files.write_atomic(tmp_path / "d.txt", "d")
    files.remove_atomic(tmp_path / "d.txt")  # outside a block: now
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
