"""What a cold ``skyroute plan`` on a grid imports: its own path, not the other commands'.

The start-up of a one-query command is mostly imports (docs/benchmarks.md, section 3).
These tests pin the module names a grid plan loads, never its time.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import skyroute
from skyroute import lazy

SRC = Path(skyroute.__file__).resolve().parents[1]

# Libraries a grid plan does not use. Not listed, as others import them on this path:
# scipy's top package (numba's import), yaml (numba's config). scipy.linalg is listed:
# numba's BLAS probe would import it whole, and skyroute.blas_probe defers that probe;
# pydantic too: Typer 0.29 converts every option with it (pyproject pins Typer < 0.29).
HEAVY = ("shapely", "scipy.linalg", "sqlalchemy", "alembic", "matplotlib", "pyproj",
         "fastapi", "starlette", "uvicorn", "httpx", "dask", "distributed", "PIL", "networkx",
         "pandas", "ompl", "pydantic",
         "scipy.ndimage", "scipy.sparse", "scipy.spatial", "scipy.optimize")
# skyroute's packages and modules that other commands (or World plans) need.
OTHERS = ("skyroute.roadmap", "skyroute.motion", "skyroute.delivery", "skyroute.fleet",
          "skyroute.jobs", "skyroute.bench", "skyroute.service", "skyroute.io.plot",
          "skyroute.world.world", "skyroute.world.segments", "skyroute.world.image",
          "skyroute.geo", "skyroute.cli.bench_cmd", "skyroute.cli.fleet_cmd",
          "skyroute.cli.deliver_cmd", "skyroute.cli.db_cmd", "skyroute.cli.world_cmd",
          "skyroute.cli.fly_cmd", "skyroute.cli.serve_cmd", "skyroute.cli.data_cmd")


def imported_by(*args: str) -> tuple[set[str], str]:
    """The modules a fresh ``python -X importtime -m skyroute ARGS`` imports, and stdout,
    on a warm compile cache: a first run compiles its kernels for seconds, and its delayed
    status (skyroute.cli.status) then loads Rich to ask whether stderr is a terminal."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
    subprocess.run([sys.executable, "-m", "skyroute", *args], capture_output=True, env=env,
                   check=False)
    proc = subprocess.run([sys.executable, "-X", "importtime", "-m", "skyroute", *args],
                          capture_output=True, text=True, env=env, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    names = {line.rsplit("|", 1)[1].strip() for line in proc.stderr.splitlines()
             if line.startswith("import time:") and "|" in line}
    assert "skyroute.search.astar" in names  # the parse saw the imports
    return names, proc.stdout


def loaded(names: set[str], prefixes: tuple[str, ...]) -> list[str]:
    return sorted(n for n in names if any(n == p or n.startswith(p + ".") for p in prefixes))


def test_grid_plan_imports_neither_heavy_libraries_nor_other_commands():
    names, out = imported_by("plan", "den312d", "--start", "50,76", "--goal", "60,13",
                             "--json")
    assert json.loads(out)["cost"] == pytest.approx(112.55634918, abs=1e-8)
    assert loaded(names, HEAVY) == []
    assert loaded(names, OTHERS) == []
    assert loaded(names, ("rich",)) == []  # JSON output needs no Rich


def test_grid_plan_table_output_loads_rich_but_not_its_progress_bars():
    names, out = imported_by("plan", "den312d", "--start", "50,76", "--goal", "60,13")
    assert "112.556349" in out and "found" in out
    assert "rich.table" in names and loaded(names, ("rich.progress",)) == []


def test_public_names_resolve_lazily_and_completely():
    assert sorted(skyroute.__all__) == sorted(skyroute._HOME)
    for name in skyroute.__all__:
        value = getattr(skyroute, name)
        assert getattr(value, "__name__", name) == name
    assert set(skyroute.__all__) <= set(dir(skyroute))
    with pytest.raises(AttributeError, match="nope"):
        skyroute.nope  # noqa: B018
    import skyroute.world as world

    assert sorted(world.__all__) == sorted(world._HOME)
    assert world.World is skyroute.World and world.load_map is skyroute.load_map


def test_lazy_exports_import_on_first_use(monkeypatch):
    import types

    pkg = types.ModuleType("fake_pkg")
    monkeypatch.setitem(sys.modules, "fake_pkg", pkg)
    getattr_, dir_ = lazy.exports("fake_pkg", {"dumps": "json"})
    assert getattr_("dumps") is json.dumps and pkg.dumps is json.dumps  # cached
    assert "dumps" in dir_()
    with pytest.raises(AttributeError, match="loads"):
        getattr_("loads")


def run_program(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``python -m skyroute ARGS`` (the program's own entry, quick exit included)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
    return subprocess.run([sys.executable, "-m", "skyroute", *args], capture_output=True,
                          text=True, env=env, cwd=cwd, check=False)


def test_quick_exit_keeps_output_files_and_exit_codes(tmp_path):
    # a QUICK_EXIT command ends without Python's teardown: what it printed and wrote
    # must all be there, and its exit code must be the command's
    proc = run_program("plan", "den312d", "--start", "50,76", "--goal", "60,13", "--json",
                       "--geojson", str(tmp_path / "p.geojson"), "--plot",
                       str(tmp_path / "p.png"))
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["cost"] == pytest.approx(112.55634918, abs=1e-8)
    assert json.loads((tmp_path / "p.geojson").read_text())["type"] == "FeatureCollection"
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = run_program("plan", "den312d", "--start", "0,0", "--goal", "60,13")
    assert bad.returncode == 2
    assert bad.stderr.startswith("skyroute: error:") and len(bad.stderr.splitlines()) == 1
    usage = run_program("plan", "den312d", "--start", "50,76")  # --goal missing
    assert usage.returncode == 2 and "goal" in usage.stderr


def test_only_quick_exit_commands_skip_the_teardown():
    # an atexit handler runs in Python's teardown: after 'db --help' it must, after
    # 'plan' (a QUICK_EXIT command) it must not
    def teardown_ran(*args: str) -> bool:
        script = ("import atexit, sys; atexit.register(lambda: print('teardown', "
                  f"file=sys.stderr)); sys.argv = ['skyroute', *{list(args)!r}]; "
                  "from skyroute.cli.app import console; console()")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, env=env, check=False)
        assert proc.returncode == 0, proc.stderr
        return "teardown" in proc.stderr

    assert teardown_ran("db", "--help")
    assert not teardown_ran("plan", "den312d", "--start", "50,76", "--goal", "60,13")


def test_only_quick_exit_commands_run_without_the_cyclic_collector():
    # a one-shot command skips ~0.1 s of collections over numba's start-up objects; a
    # command that may run long ('db', 'serve', ...) keeps the collector
    def collector_on_at_exit(*args: str) -> bool:
        script = ("import gc, os, sys; real = os._exit; "
                  "os._exit = lambda c: (print('gc', gc.isenabled(), file=sys.stderr), "
                  "real(c)); import atexit; atexit.register(lambda: print('gc', "
                  "gc.isenabled(), file=sys.stderr)); "
                  f"sys.argv = ['skyroute', *{list(args)!r}]; "
                  "from skyroute.cli.app import console; console()")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])]))
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, env=env, check=False)
        assert proc.returncode == 0, proc.stderr
        states = [line for line in proc.stderr.splitlines() if line.startswith("gc ")]
        assert len(states) == 1, proc.stderr
        return states[0] == "gc True"

    assert collector_on_at_exit("db", "--help")
    assert not collector_on_at_exit("plan", "den312d", "--start", "50,76", "--goal", "60,13",
                                    "--json")
