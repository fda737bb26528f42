"""``skyroute bench service``: a small load of each kind against a real server process,
and its flags."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.cli.test_cli import run


@pytest.mark.slow
@pytest.mark.parametrize("client", ["httpx", "raw"])
def test_plan_load(client):
    from skyroute.bench.service import bench_plan

    r = bench_plan(map_name="den312d", clients=4, requests=40, warmup=4, client=client)
    assert r["requests"] == 40 and r["errors"] == 0 and r["statuses"] == {200: 40}
    assert 0 < r["plan_p50"] <= r["app_p50"] and r["requests_per_second"] > 0


@pytest.mark.slow
def test_flightpath_load_from_the_cli(monkeypatch, capsys, tmp_path, lunch):
    out = tmp_path / "rows.json"
    code, text, err = run(monkeypatch, capsys, "bench", "service", "--load", "flightpath",
                          "--db", lunch[0], "--requests", "30", "--clients", "3",
                          "--client", "raw", "--json", str(out))
    assert code == 0, err
    doc = json.loads(out.read_text())
    (row,) = doc["rows"]
    assert doc["settings"]["requests"] == 30 and doc["machine"]["skyroute"]
    assert row["load"] == "GET /days/2024-01-03/flightpath.geojson"
    assert row["errors"] == 0 and row["requests"] == 30 and "req/s" in text


@pytest.mark.parametrize("args, words", [
    (["--load", "flightpath"], "--load flightpath needs --db URL"),
    (["--load", "upload"], "--load 'upload' is not valid"),
    (["--client", "curl"], "--client 'curl' is not valid"),
    (["--clients", "0"], "must be at least 1"),
])
def test_bad_flags(monkeypatch, capsys, args, words):
    code, _, err = run(monkeypatch, capsys, "bench", "service", *args)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err


def test_the_json_path_is_checked_before_the_load(monkeypatch, capsys, tmp_path):
    def no_load(*_args, **_kwargs):
        raise AssertionError("the service was loaded before the --json path was checked")

    monkeypatch.setattr("skyroute.bench.service.bench_plan", no_load)
    (tmp_path / "file").write_text("keep me")
    code, _, err = run(monkeypatch, capsys, "bench", "service", "--requests", "10",
                       "--json", str(tmp_path / "file" / "rows.json"))
    assert code == 2 and "rows.json: cannot write: " in err and "file is not a folder" in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("args, words", [
    (["--requests", "100001"], "--requests 100,001 is over the limit of 100,000 measured "
                               "requests a load"),
    (["--clients", "501"], "--clients 501 is over the limit of 500 concurrent clients"),
    (["--workers", "65"], "--workers 65 is over the limit of 64 server processes"),
    (["--client-processes", "1000000"], "--client-processes 1,000,000 is over the limit of "
                                        "64 client processes"),
    (["--client-processes", "0"], "--client-processes 0 must be at least 1"),
    # a bad planner was a whole load of 422s and exit 0; a bad map was found after the
    # loads before it had run
    (["--algorithm", "astr"], "--algorithm 'astr' is not valid; choose one of 'bfs', "
                              "'dijkstra', 'astar', 'jps', 'theta', 'lazy_theta'"),
    (["--map", "nope"], "--map 'nope' is not a bundled map; choose one of 'Berlin_1_256', "
                        "'Paris_1_512', 'den312d'"),
])
def test_a_load_past_its_limits_is_refused_before_the_server_starts(monkeypatch, capsys,
                                                                    args, words):
    def no_load(*_args, **_kwargs):
        raise AssertionError("the service was loaded")

    monkeypatch.setattr("skyroute.bench.service.bench_plan", no_load)
    monkeypatch.setattr("skyroute.bench.service.Server", no_load)
    code, out, err = run(monkeypatch, capsys, "bench", "service", *args)
    assert code == 2 and out == "" and err == f"skyroute: error: {words}\n"


def test_the_library_load_names_its_parameters(monkeypatch):
    from skyroute.bench import service
    from skyroute.errors import OptionError

    def no_server(*_args, **_kwargs):
        raise AssertionError("the server was started")

    monkeypatch.setattr(service, "Server", no_server)
    monkeypatch.setattr(service, "plan_queries", no_server)  # 10**9 bodies filled memory
    with pytest.raises(OptionError, match=r"^requests=1,000,000,000 is over the limit of "
                                          r"100,000 ") as err:
        service.bench_plan(map_name="den312d", requests=10**9)
    assert err.value.param == "requests"
    with pytest.raises(OptionError, match=r"^workers=100 is over the limit of 64 server"):
        service.bench_flightpath(db="sqlite://", workers=100)


def test_the_json_report_keeps_every_option(monkeypatch, capsys, tmp_path):
    """Loads, map, planner, store and day (its password masked) beside the seed: the
    report kept only the seed, the sizes and the client, not what was loaded."""
    def fake(load):
        def bench(**kw):
            return {"load": load, "map": kw.get("map_name"), "requests_per_second": 100.0,
                    "errors": 0}
        return bench

    monkeypatch.setattr("skyroute.bench.service.bench_plan", fake("POST /plan"))
    monkeypatch.setattr("skyroute.bench.service.bench_flightpath", fake("GET /days"))
    out = tmp_path / "rows.json"
    code, _, err = run(monkeypatch, capsys, "bench", "service", "--load", "plan", "--load",
                       "flightpath", "--map", "den312d", "--algorithm", "jps", "--db",
                       "postgresql+psycopg://me:secret@db:5432/lunch", "--date",
                       "2024-01-03", "--requests", "10", "--json", str(out))
    assert code == 0, err
    settings = json.loads(out.read_text())["settings"]
    assert settings == {"load": ["plan", "flightpath"], "map": "den312d", "algorithm": "jps",
                        "db": "postgresql+psycopg://me:***@db:5432/lunch",
                        "date": "2024-01-03", "seed": 0, "requests": 10, "clients": 50,
                        "workers": 1, "client_processes": 1, "client": "httpx",
                        "warm": True}


def _never_answers(monkeypatch) -> list:
    """Servers that start a process which never answers /health (nor exits); the list
    gets each :class:`Server` made."""
    import sys

    from skyroute.bench.service import Server

    made = []

    def command(self, **_kw):
        made.append(self)
        return [sys.executable, "-c", "import time; time.sleep(600)"]

    monkeypatch.setattr(Server, "_command", command)
    return made


def test_a_server_that_never_answers_is_one_line_naming_what_to_do(monkeypatch, capsys):
    # serve warms every process before it answers: with numba's cache empty, several
    # processes took 75 s on a loaded machine, and the fixed 120 s wait ended in "the
    # server did not answer /health within 120 s", naming no way on
    made = _never_answers(monkeypatch)
    code, _, err = run(monkeypatch, capsys, "bench", "service", "--requests", "10",
                         "--workers", "2", "--start-timeout", "0.3")
    assert code == 2 and "Traceback" not in err, err
    assert err.strip().splitlines()[-1] == (
        "skyroute: error: the server did not answer /health within --start-timeout 0.3 s: "
        "it warms each of its 2 processes before it serves, which compiles the planners' "
        "kernels when numba's cache is empty (a minute or more on a busy machine); give a "
        "longer --start-timeout, or --no-warm (each server process then loads the kernels "
        "on its first requests)")
    assert len(made) == 1 and made[0].proc.poll() is not None  # stopped, not left running


def test_the_wait_for_a_server_grows_with_its_processes(monkeypatch):
    from skyroute.bench.service import Server, default_start_timeout

    _never_answers(monkeypatch)
    waited = []
    monkeypatch.setattr(Server, "_wait", lambda self, timeout: waited.append(timeout))
    for workers in (1, 3):
        Server(db="sqlite://", workers=workers).stop()
    Server(db="sqlite://", workers=3, start_timeout=7.5).stop()
    assert waited == [default_start_timeout(1), default_start_timeout(3), 7.5]
    assert default_start_timeout(3) > default_start_timeout(1) >= 120


def test_a_server_without_warming(monkeypatch):
    from skyroute.bench.service import Server
    from skyroute.errors import SkyrouteError

    made = _never_answers(monkeypatch)
    with pytest.raises(SkyrouteError) as err:
        Server(db="sqlite://", warm=False, start_timeout=0.2)
    assert str(err.value) == "the server did not answer /health within start_timeout=0.2 s; " \
        "wait longer"
    assert err.value.param == "start_timeout" and made[0].proc.poll() is not None
    monkeypatch.undo()  # the real command: serve --no-warm
    srv = object.__new__(Server)
    srv.port, srv.workers, srv.warm = 8000, 2, False
    assert srv._command(db="sqlite://", data=None, max_expansions=None)[-3:] == [
        "--log-level", "warning", "--no-warm"]


@pytest.mark.parametrize("command", [
    ["-c", "import sys; sys.exit('no store here')"],  # a server that dies at start
    None,  # a server that cannot be started at all (no such program)
])
def test_a_server_that_dies_at_start_leaves_no_ready_folder(monkeypatch, tmp_path,
                                                            command):
    """The ready folder (``$SKYROUTE_READY_DIR``) was removed only by ``stop()``: a
    server that exited at once, or could not be started, left a ``skyroute-ready-*``
    folder in the temp dir for every such start."""
    import sys
    import tempfile

    from skyroute.bench.service import Server
    from skyroute.errors import SkyrouteError

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    program = [sys.executable, *command] if command else [str(tmp_path / "no-python")]
    monkeypatch.setattr(Server, "_command", lambda self, **_kw: program)
    with pytest.raises(SkyrouteError if command else FileNotFoundError) as err:
        Server(db="sqlite://", warm=False, start_timeout=60)
    if command:
        assert str(err.value) == "the server did not start: no store here"
    assert not list(tmp_path.glob("skyroute-ready-*"))  # while the error is still held


# a server whose /health answers at once (its first process is warm) while its second
# process warms for a while longer: it writes the file ``late`` when that one is warm,
# then marks both ready as skyroute.bench.ready does (pid files), if it was asked to
_SLOW_SECOND_PROCESS = """
import http.server, os, sys, threading, time
from pathlib import Path

class Health(http.server.BaseHTTPRequestHandler):
    def do_GET(self):
        self.send_response(200); self.send_header("Content-Length", "0"); self.end_headers()
    def log_message(self, *args):
        pass

port, late = int(sys.argv[1]), Path(sys.argv[2])
server = http.server.HTTPServer(("127.0.0.1", port), Health)
threading.Thread(target=server.serve_forever, daemon=True).start()
ready = os.environ.get("SKYROUTE_READY_DIR")
if ready:
    Path(ready, "1").write_text("1")
time.sleep(1.5)  # the second process warms
late.write_text("warm")
if ready:
    Path(ready, "2").write_text("2")
time.sleep(600)
"""


def test_the_bench_waits_until_every_server_process_is_warm(monkeypatch, tmp_path):
    # /health answers once one process of 'serve --workers N' is warm: the bench started
    # its load while the others still warmed (a second each from numba's cache, over a
    # minute each without it) on the same cores
    import sys

    from skyroute.bench.service import Server

    late = tmp_path / "late"

    def command(self, **_kw):
        return [sys.executable, "-c", _SLOW_SECOND_PROCESS, str(self.port), str(late)]

    monkeypatch.setattr(Server, "_command", command)
    with Server(db="sqlite://", workers=2, start_timeout=60):
        assert late.exists(), "the bench began while a server process was still warming"


@pytest.mark.slow
def test_each_process_of_a_real_server_marks_itself_ready(tmp_path):
    import os

    from skyroute.bench.service import Server

    with Server(db=f"sqlite:///{tmp_path / 'bench.db'}", workers=2, warm=False) as srv:
        pids = sorted(int(p.read_text()) for p in Path(srv._ready.name).iterdir())
        assert [p.name for p in Path(srv._ready.name).iterdir() if not p.name.isdigit()] == []
        assert len(pids) == 2 and pids[0] != pids[1] and srv.proc.pid not in pids
        for pid in pids:  # the server's worker processes, alive
            os.kill(pid, 0)
    assert not Path(srv._ready.name).exists()  # the folder goes with the server
    assert srv.proc.stderr.closed  # its pipe too (left to the collector: a ResourceWarning)


def test_a_process_marks_itself_ready_only_when_asked(monkeypatch, tmp_path):
    import os

    from skyroute.bench.ready import READY_DIR_ENV, count_ready, mark_ready

    monkeypatch.delenv(READY_DIR_ENV, raising=False)
    assert mark_ready() is None
    monkeypatch.setenv(READY_DIR_ENV, str(tmp_path))
    path = mark_ready()
    assert path == tmp_path / str(os.getpid()) and path.read_text() == f"{os.getpid()}\n"
    assert [p.name for p in tmp_path.iterdir()] == [str(os.getpid())]  # no part left
    assert count_ready(tmp_path) == 1 and count_ready(tmp_path / "gone") == 0
    monkeypatch.setenv(READY_DIR_ENV, str(tmp_path / "gone"))
    assert mark_ready() is None  # logged, never raised: a server does not stop for it
