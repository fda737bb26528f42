"""``skyroute serve``: uvicorn in a process of its own on a free port answers /health and
the token works; bad flags are one line and exit 2.

The waits below are upper bounds on conditions (an answer, an exit), never sleeps: a worker's
first /plan loads the map and the compiled kernels, 0.6 s on an idle 2-core machine and over
5 s (httpx's default timeout, which failed the test) under load."""

from __future__ import annotations

import csv
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

import httpx
import pytest

from skyroute.errors import OptionError
from tests.cli.test_cli import run
from tests.conftest import ROOT

TOKEN = "serve-test-token-0001"
WAIT = 60  # seconds: the longest a server may take to start, answer or stop


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start(tmp_path, *args: str, env: dict | None = None,
          log_level: str = "warning") -> tuple[subprocess.Popen, str]:
    port = free_port()
    cmd = [sys.executable, "-m", "skyroute", "serve", "--port", str(port), "--db",
           f"sqlite:///{tmp_path / 's.db'}", "--log-level", log_level, *args]
    environ = {**os.environ, "PYTHONPATH": str(ROOT / "src"), **(env or {})}
    if env is None:
        environ.pop("SKYROUTE_TOKEN", None)
    # a session of its own: stop() can kill the workers too, which hold the pipes open
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=environ, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise AssertionError(f"serve exited {proc.returncode}: {proc.stderr.read()}")
        try:
            if httpx.get(url + "/health", timeout=1).status_code == 200:
                return proc, url
        except httpx.HTTPError:
            pass
        time.sleep(0.2)
    stop(proc)
    raise AssertionError(f"serve did not answer /health within {WAIT} s")


def stop(proc: subprocess.Popen) -> tuple[str, str]:
    proc.terminate()
    try:
        return proc.communicate(timeout=WAIT)
    except subprocess.TimeoutExpired:
        # the workers too, or communicate() waits on their end of the pipes
        os.killpg(proc.pid, signal.SIGKILL)
        return proc.communicate()


@pytest.mark.slow
def test_serve_prints_a_generated_token_once(tmp_path):
    proc, url = start(tmp_path)
    try:
        body = {"map": "den312d", "start": [50, 76], "goal": [60, 13], "geojson": False}
        assert httpx.post(url + "/plan", json=body, timeout=WAIT).status_code == 401
        time.sleep(0.2)
    finally:
        out, err = stop(proc)
    assert proc.returncode in (0, -15), err  # uvicorn re-raises SIGTERM once shut down
    lines = out.splitlines()
    assert "write token" in lines[0] and len(lines) == 2, out
    token = lines[1].strip()
    assert len(token) >= 32 and out.count(token) == 1 and token not in err
    assert "skyroute service on http://127.0.0.1:" in err


@pytest.mark.slow
def test_serve_with_a_token_file_and_two_workers(tmp_path):
    (tmp_path / "token").write_text("s3cret-token-0123456\n")
    proc, url = start(tmp_path, "--token-file", str(tmp_path / "token"), "--workers", "2",
                      "--data", str(ROOT / "examples" / "lunch"))
    try:
        body = {"map": "den312d", "start": [50, 76], "goal": [60, 13], "geojson": False}
        # each on a connection of its own, as either worker may take it; httpx's default
        # timeout (5 s) is shorter than a cold worker's first /plan on a loaded machine
        ok = httpx.post(url + "/plan", json=body, timeout=WAIT,
                        headers={"Authorization": "Bearer s3cret-token-0123456"})
        assert ok.status_code == 200 and ok.json()["status"] == "found"
        bad = httpx.post(url + "/plan", json=body, timeout=WAIT,
                         headers={"Authorization": "Bearer x"})
        assert bad.status_code == 403
        assert httpx.get(url + "/site.geojson", timeout=WAIT).status_code == 200
    finally:
        out, err = stop(proc)
    assert "s3cret" not in out + err and "write token from" in err


@pytest.mark.slow
def test_skyroute_lines_are_logged_as_uvicorn_logs_its_own(monkeypatch, capsys, tmp_path):
    """skyroute's loggers (the warm-up's, the jobs') print as uvicorn's lines do, at
    ``--log-level``: they had no handler, so Python's last resort printed the bare
    message of a warning or error and no INFO line at all (not the warm-up's time, not a
    job that failed on bad input)."""
    # the lunch orders in the store, another town's site: a delivery job fails on input
    monkeypatch.chdir(tmp_path)
    db = f"sqlite:///{tmp_path / 's.db'}"
    assert run(monkeypatch, capsys, "db", "import", str(ROOT / "examples" / "lunch"),
               "--db", db)[0] in (0, None)
    other = tmp_path / "other"  # the lunch site with other menus and no customers
    shutil.copytree(ROOT / "examples" / "lunch", other)
    menus = other / "website" / "menus" / "menus.json"
    menus.write_text(menus.read_text().replace('"item": "', '"item": "Other '))
    with open(other / "database" / "orders.csv") as f:
        for row in csv.DictReader(f):
            shutil.rmtree(other / "website" / "words" / row["deliverTo"].replace(".", "/"),
                          ignore_errors=True)
    env = {"SKYROUTE_TOKEN": TOKEN}
    for level in ("info", "warning"):
        proc, url = start(tmp_path, "--data", str(other), env=env, log_level=level)
        try:
            job = httpx.post(url + "/jobs/deliver", json={"date": "2024-01-03"},
                             headers={"Authorization": f"Bearer {TOKEN}"}, timeout=WAIT)
            assert job.status_code == 202, job.text
            deadline = time.monotonic() + WAIT
            while time.monotonic() < deadline:
                state = httpx.get(f"{url}/jobs/{job.json()['id']}", timeout=WAIT,
                                  headers={"Authorization": f"Bearer {TOKEN}"}).json()
                if state["state"] in ("done", "failed"):
                    break
                time.sleep(0.2)
            assert state["state"] == "failed" and "another site's orders" in state["error"]
        finally:
            _, err = stop(proc)
        lines = err.splitlines()
        warmed = [ln for ln in lines if "warmed the planners" in ln]
        failed = [ln for ln in lines if f"job {job.json()['id']} (deliver) failed" in ln]
        if level == "info":  # as "INFO:     Started server process [...]"
            assert any(ln.startswith("INFO:     Started server process") for ln in lines)
            assert len(warmed) == 1 and re.fullmatch(
                r"INFO:     warmed the planners in \d+\.\d s \(\d+ queries\)", warmed[0]), err
            # the reason on the line; a traceback only for an error not of the input
            assert len(failed) == 1 and failed[0].startswith(
                f"INFO:     job {job.json()['id']} (deliver) failed: ") and \
                "another site's orders" in failed[0] and "Traceback" not in err, err
        else:
            assert not warmed and not failed and "Started server process" not in err, err


def test_a_log_level_not_uvicorns_is_one_line(monkeypatch, capsys, tmp_path):
    """A --log-level uvicorn does not know was its KeyError traceback, after the banner."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "serve-test-token-0001")
    code, out, err = run(monkeypatch, capsys, "serve", "--log-level", "loud", "--db",
                         f"sqlite:///{tmp_path / 's.db'}")
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "--log-level 'loud' is not valid; choose one of critical, error, warning, " \
           "info, debug, trace" in err
    assert "skyroute service on" not in err + out


@pytest.mark.parametrize("args, words", [
    (["--data", "/nonexistent", "--source", "http://x"], "at most one of --data"),
    (["--data", "/nonexistent"], "/nonexistent: no such folder"),
    (["--source", "ftp://x"], "expected an http:// or https:// URL"),
    (["--port", "0"], "--port 0 must be"),
    (["--db", "nonsense"], "not a database URL"),
    (["--token-file", "/nonexistent/token"], "--token-file /nonexistent/token: no such file"),
    (["--job-queue", "0"], "--job-queue: Input should be greater than or equal to 1"),
    (["--max-samples", "1"], "--max-samples: Input should be greater than or equal to 2"),
])
def test_bad_flags_are_one_line(monkeypatch, capsys, tmp_path, args, words):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("SKYROUTE_TOKEN", raising=False)
    code, _, err = run(monkeypatch, capsys, "serve", *args)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err


def _serve_with_token(monkeypatch, capsys, tmp_path, given: str, token: str):
    """``serve`` started with ``token`` from $SKYROUTE_TOKEN (``given`` "env") or from a
    ``--token-file`` ("file"): (exit code, stdout, stderr, how the error names that
    source)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "token").write_text(token + "\n", encoding="utf-8")
    if given == "env":
        monkeypatch.setenv("SKYROUTE_TOKEN", token)
        args, where = [], "SKYROUTE_TOKEN: "
    else:
        monkeypatch.delenv("SKYROUTE_TOKEN", raising=False)
        args, where = ["--token-file", str(tmp_path / "token")], f"--token-file {tmp_path}"
    code, out, err = run(monkeypatch, capsys, "serve", "--db",
                         f"sqlite:///{tmp_path / 's.db'}", *args)
    return code, out, err, where


@pytest.mark.parametrize("given", ["env", "file"])
def test_a_token_a_header_cannot_carry_is_one_line(monkeypatch, capsys, tmp_path, given):
    """A non-ASCII token was taken, and every write was a 403: curl and httpx send it
    as UTF-8, browsers as Latin-1, the server reads Latin-1. The message names the
    character's place, never the token."""
    from pydantic import ValidationError

    from skyroute.service.settings import Settings

    with pytest.raises(ValidationError, match="character 2 is not printable ASCII"):
        Settings(token="s\u00e9cret")
    assert Settings(token="two words~! and more").token == "two words~! and more"  # as before
    code, out, err, where = _serve_with_token(monkeypatch, capsys, tmp_path, given,
                                              "s\u00e9cret")
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert where in err and "character 2 is not printable ASCII" in err
    assert "\u00e9" not in err + out and "skyroute service on" not in err


@pytest.mark.parametrize("given", ["env", "file"])
def test_a_short_token_is_refused_at_start(monkeypatch, capsys, tmp_path, given):
    """A token of one character was taken: anyone who reached the server could guess
    the writes' token by trying. Fewer than 16 characters is one line naming where the
    token came from (never the token), exit 2, before the banner; a ``Settings`` check,
    so ``create_app`` refuses it too."""
    from pydantic import ValidationError

    from skyroute.service.settings import Settings

    with pytest.raises(ValidationError, match="shorter than 16 characters"):
        Settings(token="x" * 15)
    assert Settings(token="x" * 16).token == "x" * 16
    short = "shorty-7"
    code, out, err, where = _serve_with_token(monkeypatch, capsys, tmp_path, given, short)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"skyroute: error: {where}") and "shorter than 16" in err, err
    assert short not in err + out and "skyroute service on" not in err
    assert not (tmp_path / "s.db").exists()  # refused before the store is made


@pytest.mark.parametrize("host, words", [
    ("127.0.0.1", "the port is in use"),
    ("nosuch.invalid", "--host 'nosuch.invalid': not an address"),
])
def test_an_address_it_cannot_listen_on_is_one_line(monkeypatch, capsys, tmp_path, host,
                                                    words):
    """A port another server holds (a second 'serve' on 8000) or a host that is no address
    is one line naming the option, exit 2, before the banner and the store: uvicorn logged
    it after "skyroute service on ..." and exited 3."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "serve-test-token-0001")
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        code, out, err = run(monkeypatch, capsys, "serve", "--host", host, "--port",
                             str(port), "--db", f"sqlite:///{tmp_path / 's.db'}")
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert "skyroute service on" not in err + out
    assert not (tmp_path / "s.db").exists()


def test_a_port_held_on_any_address_of_the_host_is_one_line(monkeypatch):
    """A name that resolves to ::1 and 127.0.0.1 (``localhost`` on most machines), with
    another server on 127.0.0.1 only: uvicorn binds both and fails on the second, so the
    check binds both too (it bound the first alone, passed, and uvicorn exited 3)."""
    from skyroute.cli import serve_cmd

    real = socket.getaddrinfo

    def dual_stack(host, port, *args, **kwargs):
        if host != "dual.test":
            return real(host, port, *args, **kwargs)
        return [(socket.AF_INET6, socket.SOCK_STREAM, 6, "", ("::1", port, 0, 0)),
                (socket.AF_INET, socket.SOCK_STREAM, 6, "", ("127.0.0.1", port))]

    monkeypatch.setattr(socket, "getaddrinfo", dual_stack)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        try:
            socket.create_server(("::1", port), family=socket.AF_INET6).close()
        except OSError:
            pytest.skip("no IPv6 loopback here, or its port is taken")
        with pytest.raises(OptionError, match=f"--port {port}: cannot listen on "
                                              f"dual.test:{port}: the port is in use"):
            serve_cmd.check_listen("dual.test", port)
    serve_cmd.check_listen("dual.test", port)  # both free now: no error


def test_serve_fails_the_jobs_a_stopped_server_left(monkeypatch, capsys, tmp_path):
    """A job runs only in the process that took it: one left queued or running by a
    server that stopped is failed when the next server starts, a finished one is kept,
    and so is the job of another server still alive on the same store."""
    import uvicorn
    from fastapi.testclient import TestClient

    from skyroute.jobs import store
    from skyroute.jobs.runner import ORPHANED
    from skyroute.service.resources import make_engine

    db = f"sqlite:///{tmp_path / 's.db'}"
    eng = make_engine(db)
    queued = store.create_job(eng, "fleet", {"preset": "seed-3x3"})
    running = store.create_job(eng, "fleet", {"preset": "seed-3x3"})
    store.set_progress(eng, running, 0.5)
    done = store.create_job(eng, "fleet", {"preset": "seed-3x3"})
    store.finish_job(eng, done, {"fleet_run": "r"})
    store.beat(eng, "other-server:1:a")
    live = store.create_job(eng, "fleet", {"preset": "seed-3x3"}, owner="other-server:1:a")
    eng.dispose()

    served = []
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: served.append(app))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "serve-test-token-0001")
    code, _, err = run(monkeypatch, capsys, "serve", "--db", db)
    assert code in (0, None) and len(served) == 1, err
    assert "2 job(s) left queued or running by a stopped server marked failed" in err
    with TestClient(served[0], base_url="http://127.0.0.1:8000",  # one of its names
                    headers={"Authorization": f"Bearer {TOKEN}"}) as c:  # errors in full
        for job_id in (queued, running):
            job = c.get(f"/jobs/{job_id}").json()
            assert job["state"] == "failed" and job["error"] == ORPHANED, job
        job = c.get(f"/jobs/{done}").json()
        assert job["state"] == "done" and job["result"] == {"fleet_run": "r"}
        assert c.get(f"/jobs/{live}").json()["state"] == "queued"
    code, _, err = run(monkeypatch, capsys, "serve", "--db", db)  # nothing left to fail
    assert len(served) == 2 and "job(s) left" not in err


def test_a_token_file_saved_with_a_byte_order_mark_gives_the_token(tmp_path, monkeypatch):
    """Notepad saves 'UTF-8' with a byte-order mark: it is no part of the token (else
    every request with the token the user typed would be a 401)."""
    from skyroute.cli.serve_cmd import TOKEN_ENV, read_token
    from skyroute.errors import OptionError

    monkeypatch.delenv(TOKEN_ENV, raising=False)
    f = tmp_path / "token.txt"
    f.write_bytes(b"\xef\xbb\xbfs3cret\r\n")
    assert read_token(f) == ("s3cret", str(f))
    f.write_bytes(b"\xff\xfes\x00")  # UTF-16: one line naming the option and the file
    with pytest.raises(OptionError, match=r"^--token-file .*token\.txt: cannot read: not UTF-8"):
        read_token(f)


def _served(monkeypatch, capsys, tmp_path, *args) -> tuple[object, str]:
    """(the app ``skyroute serve *args`` would run, its stderr), uvicorn not started."""
    import uvicorn

    served = []
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: served.append(app))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", TOKEN)
    code, _, err = run(monkeypatch, capsys, "serve", "--db",
                       f"sqlite:///{tmp_path / 's.db'}", "--no-warm", "--port",
                       str(free_port()), *args)
    assert code in (0, None) and len(served) == 1, err
    return served[0], err


def _status(app, host: str) -> int:
    from fastapi.testclient import TestClient

    with TestClient(app, base_url=f"http://{host}") as c:
        return c.get("/health").status_code


def test_a_loopback_server_answers_only_to_its_names(monkeypatch, capsys, tmp_path):
    """DNS rebinding: a page of another site points a DNS name of its own at 127.0.0.1,
    and the browser lets it read what the server there answers, as it sends that name
    as the Host; no Host was refused. ``serve`` on a loopback address now answers to
    localhost, 127.0.0.1, [::1] and its --host alone: another Host is a 400 problem."""
    app, err = _served(monkeypatch, capsys, tmp_path)
    for host in ("127.0.0.1:8000", "localhost:8000", "[::1]:8000", "LOCALHOST"):
        assert _status(app, host) == 200, host
    for host in ("rebind.attacker.example:8000", "testserver", "127.0.0.2:8000"):
        assert _status(app, host) == 400, host
    assert "warning" not in err, err
    app, _ = _served(monkeypatch, capsys, tmp_path, "--host", "127.0.0.2")  # its --host
    assert _status(app, "127.0.0.2:8000") == 200
    assert _status(app, "rebind.attacker.example") == 400


def test_allowed_hosts_names_the_servers_names(monkeypatch, capsys, tmp_path):
    app, err = _served(monkeypatch, capsys, tmp_path, "--allowed-hosts",
                       "sky.example, *.fleet.example,::1")
    for host in ("sky.example", "a.fleet.example:443", "[::1]:8000"):
        assert _status(app, host) == 200, host
    for host in ("127.0.0.1:8000", "localhost", "fleet.example", "other.example"):
        assert _status(app, host) == 400, host
    app, err = _served(monkeypatch, capsys, tmp_path, "--allowed-hosts", "*")
    assert _status(app, "any.example") == 200 and "warning" not in err


def test_a_server_on_all_addresses_takes_any_host_and_says_so(monkeypatch, capsys,
                                                              tmp_path):
    """Bound to 0.0.0.0 the names other machines reach it by are not known: any Host is
    taken by default, with one warning naming --allowed-hosts."""
    app, err = _served(monkeypatch, capsys, tmp_path, "--host", "0.0.0.0")
    assert _status(app, "any.example") == 200
    warned = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    assert len(warned) == 1 and "any Host header is taken" in warned[0] and \
        "--allowed-hosts" in warned[0], err
    app, err = _served(monkeypatch, capsys, tmp_path, "--host", "0.0.0.0",
                       "--allowed-hosts", "sky.example")
    assert _status(app, "sky.example") == 200 and _status(app, "any.example") == 400
    assert "warning" not in err


@pytest.mark.parametrize("given, words", [
    ("sky.example:8000", "--allowed-hosts: host 'sky.example:8000': give the name or "
                         "address alone (no port, scheme or path)"),
    ("http://sky.example", "no port, scheme or path"),
    ("sky.*.example", "--allowed-hosts: host 'sky.*.example': give a name, an address, "
                      "*.domain or *"),
    (",", "--allowed-hosts: give at least one host (or * for any)"),
])
def test_bad_allowed_hosts_are_one_line(monkeypatch, capsys, tmp_path, given, words):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", TOKEN)
    code, out, err = run(monkeypatch, capsys, "serve", "--db",
                         f"sqlite:///{tmp_path / 's.db'}", "--allowed-hosts", given)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert "skyroute service on" not in err + out and not (tmp_path / "s.db").exists()



def test_max_samples_is_the_limit_the_schema_declares(monkeypatch, capsys, tmp_path):
    """``--max-samples``: the server's limit on a PRM request's samples, which
    ``/openapi.json`` declares (the flag did not exist: every server held 20,000)."""
    from fastapi.testclient import TestClient

    app, _ = _served(monkeypatch, capsys, tmp_path, "--max-samples", "500")
    with TestClient(app, base_url="http://127.0.0.1:8000") as c:
        spec = c.get("/openapi.json").json()
        assert spec["components"]["schemas"]["PlanRequest"]["properties"]["samples"][
            "maximum"] == 500
    assert app.state.settings.max_samples == 500  # what POST /plan holds samples to
