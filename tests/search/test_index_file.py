"""A prepared index's file: whatever is wrong with it is one InputFormatError naming the
file, before any array reaches a compiled query (which would read out of bounds)."""

import numpy as np
import pytest

import skyroute
from tests.conftest import MOVINGAI


@pytest.fixture(scope="module")
def den312d():
    grid = skyroute.load_map("den312d")
    return grid, {m: skyroute.prepare(grid, method=m) for m in ("subgoal", "jump")}


def _rewrite(src, dst, **changes):
    with np.load(src) as z:
        data = dict(z)
    data.update(changes)
    with open(dst, "wb") as f:
        np.savez(f, **data)
    return dst


@pytest.mark.parametrize("method", ["subgoal", "jump"])
def test_a_written_index_reads_back_and_answers_alike(den312d, tmp_path, method):
    grid, built = den312d
    path = built[method].save(tmp_path / "d.idx")
    loaded = skyroute.load_index(path, grid)
    a, b = built[method].plan((50, 76), (60, 13)), loaded.plan((50, 76), (60, 13))
    assert (loaded.method, loaded.accelerator) == (built[method].method,
                                                   built[method].accelerator)
    assert a.cost == b.cost and np.array_equal(a.path, b.path)


@pytest.mark.parametrize("method, changes, message", [
    ("subgoal", {"version": np.array([3, 3])}, "'version' is not one integer"),
    ("subgoal", {"method": np.array(["subgoal"])}, "'method' is not one string"),
    ("subgoal", {"digest": np.int64(7)}, "'digest' is not one string"),
    ("subgoal", {"shape": np.array([81, 65, 1])}, "'shape' is not two integers"),
    ("subgoal", {"nbr": np.zeros(5, np.int64)}, "'nbr' is a 1-D int64 array, not 1-D int32"),
    ("subgoal", {"dist": np.zeros(5)}, "'dist' is a 1-D float64 array, not 2-D"),
    ("subgoal", {"label": np.zeros(7, np.int32)}, "'label' does not cover the map"),
    ("subgoal", {"offs": np.zeros(3, np.int64)}, "arrays' sizes do not fit together"),
    ("jump", {"piv": np.zeros((10, 24))}, "'piv' does not cover the map"),
    ("jump", {"piv": np.zeros((5561, 24), np.float32)},
     "'piv' is a 2-D float32 array, not 2-D float64"),
])
def test_a_malformed_index_is_refused(den312d, tmp_path, method, changes, message):
    grid, built = den312d
    good = built[method].save(tmp_path / "good.idx")
    bad = _rewrite(good, tmp_path / "bad.idx", **changes)
    with pytest.raises(skyroute.InputFormatError, match=rf"bad.idx: .*{message}"):
        skyroute.load_index(bad, grid)


def test_graph_indices_out_of_range_are_refused(den312d, tmp_path):
    grid, built = den312d
    good = built["subgoal"].save(tmp_path / "good.idx")
    with np.load(good) as z:
        nbr, cells = z["nbr"].copy(), z["cells"].copy()
    nbr[0] = cells.size  # one past the last subgoal
    bad = _rewrite(good, tmp_path / "nbr.idx", nbr=nbr)
    with pytest.raises(skyroute.InputFormatError, match="graph's indices are out of range"):
        skyroute.load_index(bad, grid)
    cells[3] = -1
    bad = _rewrite(good, tmp_path / "cells.idx", cells=cells)
    with pytest.raises(skyroute.InputFormatError, match="graph's indices are out of range"):
        skyroute.load_index(bad, grid)


def test_files_that_are_no_index_at_all(den312d, tmp_path):
    grid, built = den312d
    good = built["jump"].save(tmp_path / "good.idx")
    data = good.read_bytes()
    cases = {"half.idx": data[: len(data) // 2], "empty.idx": b"",
             "text.idx": b"skyroute\n"}
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
    np.save(tmp_path / "plain.npy", np.zeros(3))
    for name in (*cases, "plain.npy"):
        with pytest.raises(skyroute.InputFormatError, match=rf"{name}: not a skyroute index"):
            skyroute.load_index(tmp_path / name, grid)
    with pytest.raises(skyroute.InputFormatError, match="a folder, not an index file"):
        skyroute.load_index(tmp_path, grid)
    with pytest.raises(skyroute.InputFormatError, match="no such index file"):
        skyroute.load_index(tmp_path / "none.idx", grid)


def test_another_programs_npz_says_what_it_holds(den312d, tmp_path):
    # it read "not a skyroute index: method ''", naming an entry the file never had
    grid, _ = den312d
    np.savez(tmp_path / "weights.npz", w=np.zeros(3), b=np.zeros(2))
    with pytest.raises(skyroute.InputFormatError) as err:
        skyroute.load_index(tmp_path / "weights.npz", grid)
    assert str(err.value) == (f"{tmp_path / 'weights.npz'}: not a skyroute index: it has "
                              "no 'method' entry (its arrays: b, w)")


def _with(path, key, change):
    with np.load(path) as z:
        a = z[key].copy()
    change(a)
    return a


@pytest.mark.parametrize("key, change, message", [
    ("pred", lambda a: a.__setitem__((0, 1), 32000), "graph's indices are out of range"),
    ("pred", lambda a: a.__setitem__((0, 1), -5), "graph's indices are out of range"),
    ("offs", lambda a: a.__setitem__(1, a[2] + 1), "graph's indices are out of range"),
    ("label", lambda a: a.__setitem__(np.flatnonzero(a >= 0)[:50], 7),
     "region labels or clearances do not fit"),
    ("clr", lambda a: a.__setitem__((300, 0), 1000), "region labels or clearances do not fit"),
])
def test_index_values_that_do_not_fit_are_refused(den312d, tmp_path, key, change, message):
    grid, built = den312d
    good = built["subgoal"].save(tmp_path / "good.idx")
    bad = _rewrite(good, tmp_path / "bad.idx", **{key: _with(good, key, change)})
    with pytest.raises(skyroute.InputFormatError, match=rf"bad.idx: .*{message}"):
        skyroute.load_index(bad, grid)


@pytest.mark.shared_data
def test_a_hierarchy_index_with_indices_out_of_range_is_refused(tmp_path):
    """Boston_0_256's subgoal graph contracts into a hierarchy with a core table."""
    grid = skyroute.load_map(MOVINGAI / "Boston_0_256.map")
    index = skyroute.prepare(grid, method="subgoal")
    assert index.accelerator == "hierarchy"
    good = index.save(tmp_path / "good.idx")
    assert skyroute.load_index(good, grid).accelerator == "hierarchy"
    for key, value in (("ch_mid", 10**6), ("ch_nbr", -1), ("ch_core", 5000),
                       ("ch_pred", 5000)):
        arr = _with(good, key, lambda a, v=value: a.__setitem__(np.unravel_index(
            int(np.argmax(a)), a.shape), v))
        bad = _rewrite(good, tmp_path / f"{key}.idx", **{key: arr})
        with pytest.raises(skyroute.InputFormatError, match="graph's indices are out of range"):
            skyroute.load_index(bad, grid)


def test_a_path_that_is_no_path_is_an_option_error(den312d):
    grid, built = den312d
    with pytest.raises(skyroute.OptionError, match="path must be a file path, got NoneType"):
        built["jump"].save(None)
    with pytest.raises(skyroute.OptionError, match="path must be a file path, got int"):
        skyroute.load_index(123, grid)
