"""write_atomic: whole files with the usual permissions, nothing left behind on failure."""

from __future__ import annotations

import os
import stat

import pytest

from skyroute.files import write_atomic


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
