"""written_together with a database transaction (Together.enter): the files and the rows
change together or not at all, whichever of a rename, the commit or the block fails."""

from __future__ import annotations

import signal
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import skyroute.files as files
from skyroute.errors import SkyrouteError
from tests.rename_failures import earlier_versions, failing_rename


class CommitError(Exception):
    pass


class Transaction:
    """Stands in for the store's transaction: what happened to it, and the folder as
    it was at the commit (files by name, with their text)."""

    def __init__(self, here: Path, *, fails: bool = False) -> None:
        self.here, self.fails = here, fails
        self.events: list[str] = []
        self.at_commit: dict[str, str] | None = None

    @contextmanager
    def begin(self):
        self.events.append("begin")
        try:
            yield self
        except BaseException:
            self.events.append("rollback")
            raise
        self.at_commit = folder(self.here)
        if self.fails:
            self.events.append("commit failed")
            raise CommitError("the disk went away")
        self.events.append("commit")


def folder(here: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted(here.iterdir()) if p.is_file()}


def test_the_commit_comes_after_every_rename_and_before_the_backups_go(tmp_path):
    (tmp_path / "a.txt").write_text("old a")
    tx = Transaction(tmp_path)
    with files.written_together() as together:
        files.write_atomic(tmp_path / "a.txt", "new a")
        assert together.enter(tx.begin()) is tx
        files.write_atomic(tmp_path / "b.txt", "new b")
        assert tx.events == ["begin"]  # not committed before the block ends
    assert tx.events == ["begin", "commit"]
    seen = tx.at_commit
    # both new files in place at the commit, the earlier a.txt still kept beside them
    assert {k: v for k, v in seen.items() if not k.startswith(".")} == {
        "a.txt": "new a", "b.txt": "new b"}
    assert [v for k, v in seen.items() if k.endswith(".bak")] == ["old a"]
    assert folder(tmp_path) == {"a.txt": "new a", "b.txt": "new b"}  # backup dropped


@pytest.mark.parametrize("at", [1, 2])
def test_a_failed_rename_rolls_the_transaction_back(tmp_path, monkeypatch, at):
    # the rows were committed before the renames: a rename that failed left the new
    # rows beside the earlier files
    (tmp_path / "a.txt").write_text("old a")
    failing_rename(monkeypatch, at)
    tx = Transaction(tmp_path)
    with pytest.raises(SkyrouteError, match="cannot write: No space left"), \
            files.written_together() as together:
        together.enter(tx.begin())
        files.write_atomic(tmp_path / "a.txt", "new a")
        files.write_atomic(tmp_path / "b.txt", "new b")
    assert tx.events == ["begin", "rollback"]
    assert folder(tmp_path) == {"a.txt": "old a"}


def test_a_failed_commit_puts_every_file_back(tmp_path):
    (tmp_path / "a.txt").write_text("old a")
    tx = Transaction(tmp_path, fails=True)
    with pytest.raises(CommitError), files.written_together() as together:
        files.write_atomic(tmp_path / "a.txt", "new a")
        files.write_atomic(tmp_path / "sub" / "b.txt", "new b")
        together.enter(tx.begin())
    assert tx.events == ["begin", "commit failed"]
    assert tx.at_commit is not None and tx.at_commit["a.txt"] == "new a"
    # the earlier a.txt back, b.txt and the folder made for it gone, nothing left over
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    assert folder(tmp_path) == {"a.txt": "old a"}


def test_an_error_in_the_block_rolls_back_and_writes_nothing(tmp_path):
    tx = Transaction(tmp_path)
    with pytest.raises(KeyboardInterrupt), files.written_together() as together:
        together.enter(tx.begin())
        files.write_atomic(tmp_path / "a.txt", "new a")
        raise KeyboardInterrupt
    assert tx.events == ["begin", "rollback"]
    assert list(tmp_path.iterdir()) == []


def test_a_block_inside_another_commits_with_the_outer_ones_files(tmp_path):
    tx = Transaction(tmp_path)
    with files.written_together():
        files.write_atomic(tmp_path / "a.txt", "new a")
        with files.written_together() as inner:
            inner.enter(tx.begin())
        assert tx.events == ["begin"]
        files.write_atomic(tmp_path / "b.txt", "new b")
    assert tx.events == ["begin", "commit"]
    assert tx.at_commit == {"a.txt": "new a", "b.txt": "new b"}


class _StopError(Exception):
    pass


def test_a_signal_during_the_commit_waits_until_it_is_done(tmp_path):
    """SIGINT in the commit (a round trip to the server): taken once the files are in
    place and the rows committed, so both are new."""
    tx = Transaction(tmp_path)

    @contextmanager
    def interrupted_commit():
        with tx.begin():
            yield
            signal.raise_signal(signal.SIGINT)  # arrives while the commit is under way

    def stop(*_):
        raise _StopError

    before = signal.signal(signal.SIGINT, stop)
    try:
        with pytest.raises(_StopError), files.written_together() as together:
            files.write_atomic(tmp_path / "a.txt", "new a")
            together.enter(interrupted_commit())
    finally:
        signal.signal(signal.SIGINT, before)
    assert tx.events == ["begin", "commit"]
    assert folder(tmp_path) == {"a.txt": "new a"}


@given(st.lists(st.booleans(), min_size=0, max_size=4), st.integers(0, 5), st.booleans())
@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_files_and_transaction_change_together_or_not_at_all(tmp_path_factory, existed,
                                                             fail_at, commit_fails):
    """Any number of files, some with an earlier version, the rename numbered
    ``fail_at`` failing (past the last: none fails) and the commit failing or not:
    afterwards either every file is new and the transaction committed, or the folder
    holds exactly what it held before and the transaction was rolled back."""
    here = tmp_path_factory.mktemp("together")
    before = earlier_versions(here, existed)
    tx = Transaction(here, fails=commit_fails)
    with pytest.MonkeyPatch.context() as mp:
        failing_rename(mp, fail_at + 1)
        try:
            with files.written_together() as together:
                together.enter(tx.begin())
                for k in range(len(existed)):
                    files.write_atomic(here / f"f{k}", f"new {k}")
        except (SkyrouteError, CommitError):
            assert fail_at < len(existed) or commit_fails
            assert tx.events[-1] in ("rollback", "commit failed")
            expected = before
        else:
            assert fail_at >= len(existed) and not commit_fails
            assert tx.events == ["begin", "commit"]
            expected = {f"f{k}": f"new {k}" for k in range(len(existed))}
    assert {p.name: p.read_text() for p in here.iterdir()} == expected
