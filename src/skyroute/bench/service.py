"""``skyroute bench service``: the REST service under load on 127.0.0.1.

The server is ``skyroute serve`` in a process of its own (uvicorn, ``workers``
processes); the load comes from one asyncio process of ``clients`` concurrent httpx
clients, each sending its next request as soon as the last one is answered (a closed
loop; ``client_processes`` splits them over that many processes when one process of
httpx cannot keep the server busy; ``client="raw"`` uses a minimal HTTP/1.1 client on
asyncio streams instead, which costs far less CPU per request). Two loads:

- ``plan``: ``POST /plan`` on a bundled map with queries drawn (seeded) from the map's
  MovingAI scenario file, A* by default;
- ``flightpath``: ``GET /days/{date}/flightpath.geojson`` of a stored day.

Server-side time is the app's own ``Server-Timing: app;dur=`` (from the request reaching
the app to its response headers; for ``/plan`` also ``wait`` for the search slot and
``plan``, the search and its JSON). Client latency adds the network stack, uvicorn's
parsing and the client's own queueing on a shared machine.

A load's size is limited (:func:`check_load`) before the server starts: every request
is drawn and every answer recorded in memory, each client holds a connection (a file
descriptor on both sides) and each process is a Python interpreter. The documented runs
send 2,000-5,000 requests from 50 clients.
"""

from __future__ import annotations

import asyncio
import os
import re
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from skyroute.bench.ready import READY_DIR_ENV, count_ready
from skyroute.errors import OptionError, SkyrouteError

TOKEN = "bench-service-token"
CLIENTS = ("httpx", "raw")
MAX_REQUESTS = 100_000  # 20 times the largest documented load; minutes at 1,000/s
MAX_CLIENTS = 500  # connections: both ends stay well inside a default 1,024 open files
MAX_PROCESSES = 64  # server workers, and client processes
_TIMING = re.compile(r"(\w+);dur=([0-9.]+)")


def check_load(*, clients: int, requests: int, workers: int = 1,
               client_processes: int = 1, flags: bool = False) -> None:
    """An OptionError naming the parameter (``flags``: the CLI's option, whose
    ``--workers`` is not the ``--jobs`` other commands call workers) when a load is below
    1 or past its limit (:data:`MAX_CLIENTS`, :data:`MAX_REQUESTS`,
    :data:`MAX_PROCESSES`)."""
    for name, value, limit, what in (
            ("clients", clients, MAX_CLIENTS, "concurrent clients"),
            ("requests", requests, MAX_REQUESTS, "measured requests a load"),
            ("workers", workers, MAX_PROCESSES, "server processes"),
            ("client_processes", client_processes, MAX_PROCESSES, "client processes")):
        given = f"--{name.replace('_', '-')} {value:,}" if flags else f"{name}={value:,}"
        if value < 1:
            raise OptionError(f"{given} must be at least 1", param=None if flags else name)
        if value > limit:
            raise OptionError(f"{given} is over the limit of {limit:,} {what}",
                              param=None if flags else name)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


START_TIMEOUT = 120.0  # seconds for a server of one process to answer /health
START_PER_WORKER = 60.0  # and for each further process


def default_start_timeout(workers: int) -> float:
    """How long :class:`Server` waits for ``/health`` by default: :data:`START_TIMEOUT`
    and :data:`START_PER_WORKER` for each process past the first. Each process warms the
    planners before it serves (:mod:`skyroute.service.warm`): about a second from
    numba's cache, but with the cache empty each compiles the kernels, all at once on
    the same cores (75 s for several processes on a loaded 2-core machine)."""
    return START_TIMEOUT + START_PER_WORKER * (workers - 1)


class Server:
    """``skyroute serve`` on a free port of 127.0.0.1, until ``stop()``.

    ``warm``: the server warms its processes before it serves (``serve --no-warm`` when
    False); ``start_timeout``: seconds to wait for ``/health`` (default
    :func:`default_start_timeout`), after which the server is stopped and a
    SkyrouteError with ``param="start_timeout"`` says what to do.

    ``/health`` answers once one process is warm; the others may still be warming on the
    same cores. So the wait also lasts until every process has written its pid to a
    folder the server is given in ``$SKYROUTE_READY_DIR`` (:mod:`skyroute.bench.ready`):
    no measured request competes with a warm-up, whichever process the kernel hands the
    connections to."""

    def __init__(self, *, db: str, workers: int = 1, data: Path | None = None,
                 max_expansions: int | None = None, warm: bool = True,
                 start_timeout: float | None = None) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.workers, self.warm = workers, warm
        cmd = self._command(db=db, data=data, max_expansions=max_expansions)
        # each server process writes its pid here once warm (skyroute.bench.ready)
        self._ready = tempfile.TemporaryDirectory(prefix="skyroute-ready-")
        self.proc: subprocess.Popen | None = None
        env = {**os.environ, "SKYROUTE_TOKEN": TOKEN, READY_DIR_ENV: self._ready.name}
        try:
            self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL,
                                         stderr=subprocess.PIPE, text=True)
            self._wait(default_start_timeout(workers) if start_timeout is None
                       else start_timeout)
        except BaseException:  # a server that died at start, or a Ctrl-C in the wait:
            self.stop()  # no process left running, no ready folder left in the temp dir
            raise

    def _command(self, *, db: str, data: Path | None, max_expansions: int | None) -> list:
        cmd = [sys.executable, "-m", "skyroute", "serve", "--port", str(self.port), "--db",
               db, "--workers", str(self.workers), "--log-level", "warning"]
        if data is not None:
            cmd += ["--data", str(data)]
        if max_expansions is not None:
            cmd += ["--max-expansions", str(max_expansions)]
        if not self.warm:
            cmd.append("--no-warm")
        return cmd

    def _wait(self, timeout: float) -> None:
        import httpx

        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise SkyrouteError("the server did not start: "
                                    + (self.proc.stderr.read().strip().splitlines() or
                                       ["(no message)"])[-1])
            try:
                if (httpx.get(self.url + "/health", timeout=1).status_code == 200
                        and self.ready() >= self.workers):
                    return
            except httpx.HTTPError:
                pass
            time.sleep(0.2)
        self.stop()
        n = self.workers
        why = ("" if not self.warm else
               f": it warms {'its process' if n == 1 else f'each of its {n} processes'} "
               "before it serves, which compiles the planners' kernels when numba's cache "
               "is empty (a minute or more on a busy machine)")
        raise SkyrouteError(f"the server did not answer /health within start_timeout="
                            f"{timeout:g} s{why}; wait longer"
                            + (", or start it without warming (warm=False)" if self.warm
                               else ""), param="start_timeout")

    def ready(self) -> int:
        """How many of the server's processes are warm (have marked themselves ready)."""
        return count_ready(Path(self._ready.name))

    def stop(self) -> None:
        """Stop the server (if it runs) and remove its ready folder; again is harmless."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self.proc is not None and self.proc.stderr is not None:
            self.proc.stderr.close()  # (a ResourceWarning when left to the collector)
        self._ready.cleanup()

    def __enter__(self) -> Server:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def cpu_seconds(pid: int) -> float | None:
    """CPU seconds (user + system) used so far by process ``pid`` and its descendants,
    from /proc (None where there is no /proc): what the server spent, whatever else
    the machine was doing meanwhile."""
    proc = Path("/proc")
    if not (proc / str(pid) / "stat").exists():
        return None
    tick = os.sysconf("SC_CLK_TCK")
    parent, used = {}, {}
    for d in proc.iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parent[int(d.name)] = int(fields[1])
            used[int(d.name)] = (int(fields[11]) + int(fields[12])) / tick
    tree, todo = {pid}, [pid]
    while todo:
        p = todo.pop()
        kids = [c for c, pp in parent.items() if pp == p and c not in tree]
        tree.update(kids)
        todo.extend(kids)
    return sum(used.get(p, 0.0) for p in tree)


def _timings(header: str | None) -> dict[str, float]:
    return {k: float(v) for k, v in _TIMING.findall(header or "")}


async def _load(url: str, requests: list[tuple[str, str, dict | None]], clients: int,
                headers: dict) -> tuple[list[dict], float]:
    """Send every request, ``clients`` at a time (closed loop); (one record per request,
    wall seconds)."""
    import httpx

    records: list[dict] = []
    queue = iter(requests)
    limits = httpx.Limits(max_connections=clients, max_keepalive_connections=clients)

    async def client(http: httpx.AsyncClient) -> None:
        for method, path, body in queue:
            t0 = time.perf_counter()
            try:
                r = await http.request(method, path, json=body)
                await r.aread()
                rec = {"status": r.status_code, "client_ms": (time.perf_counter() - t0) * 1e3,
                       **_timings(r.headers.get("server-timing")), "bytes": len(r.content)}
            except httpx.HTTPError as exc:
                rec = {"status": 0, "error": type(exc).__name__,
                       "client_ms": (time.perf_counter() - t0) * 1e3}
            records.append(rec)

    async with httpx.AsyncClient(base_url=url, headers=headers, limits=limits,
                                 timeout=60.0) as http:
        t0, c0 = time.perf_counter(), time.process_time()
        await asyncio.gather(*(client(http) for _ in range(clients)))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    for r in records:  # the load generator's own CPU, shared out (it competes for cores)
        r["client_cpu_ms"] = cpu * 1e3 / len(records)
    return records, wall


async def _load_raw(url: str, requests: list[tuple[str, str, dict | None]], clients: int,
                    headers: dict) -> tuple[list[dict], float]:
    """:func:`_load` with a minimal HTTP/1.1 keep-alive client on asyncio streams instead
    of httpx: what the server answers when the load generator costs little CPU."""
    import json

    host, port = url.removeprefix("http://").split(":")
    extra = "".join(f"{k}: {v}\r\n" for k, v in headers.items())
    records: list[dict] = []
    queue = iter(requests)

    async def client() -> None:
        reader, writer = await asyncio.open_connection(host, int(port))
        try:
            for method, path, body in queue:
                data = b"" if body is None else json.dumps(body).encode()
                head = (f"{method} {path} HTTP/1.1\r\nHost: {host}\r\n{extra}"
                        + (f"Content-Type: application/json\r\nContent-Length: {len(data)}"
                           "\r\n" if body is not None else "") + "\r\n")
                t0 = time.perf_counter()
                writer.write(head.encode() + data)
                lines = (await reader.readuntil(b"\r\n\r\n")).decode("latin-1").split("\r\n")
                fields = {k.lower(): v.strip() for k, _, v in
                          (x.partition(":") for x in lines[1:] if x)}
                content = await reader.readexactly(int(fields.get("content-length", 0)))
                records.append({"status": int(lines[0].split()[1]),
                                "client_ms": (time.perf_counter() - t0) * 1e3,
                                **_timings(fields.get("server-timing")),
                                "bytes": len(content)})
        finally:
            writer.close()

    t0, c0 = time.perf_counter(), time.process_time()
    await asyncio.gather(*(client() for _ in range(clients)))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    for r in records:
        r["client_cpu_ms"] = cpu * 1e3 / len(records)
    return records, wall


def _load_share(args) -> tuple[list[dict], float, float]:
    """One client process's share: (records, start, end) in wall-clock seconds."""
    url, requests, clients, headers, barrier, raw = args
    barrier.wait()
    t0 = time.time()
    records, _ = asyncio.run((_load_raw if raw else _load)(url, requests, clients, headers))
    return records, t0, time.time()


def _run_load(url: str, requests: list, clients: int, headers: dict,
              processes: int = 1, client: str = "httpx") -> tuple[list[dict], float]:
    """:func:`_load` in ``processes`` client processes (each ``clients / processes``
    clients and every ``processes``-th request), started together; (records, wall)."""
    if client not in CLIENTS:
        raise SkyrouteError(f"client={client!r} is not valid; choose one of "
                            + ", ".join(repr(c) for c in CLIENTS), param="client")
    raw = client == "raw"
    if processes == 1:
        return asyncio.run((_load_raw if raw else _load)(url, requests, clients, headers))
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    with ctx.Manager() as manager:
        barrier = manager.Barrier(processes)
        shares = [(url, requests[k::processes], max(1, clients // processes), headers,
                   barrier, raw) for k in range(processes)]
        with ctx.Pool(processes) as pool:
            out = pool.map(_load_share, shares)
    records = [r for rec, _, _ in out for r in rec]
    return records, max(e for _, _, e in out) - min(b for _, b, _ in out)


def _summary(records: list[dict], wall: float) -> dict:
    ok = [r for r in records if r["status"] == 200]

    def pct(key: str) -> dict:
        v = np.array([r[key] for r in ok if key in r])
        if not len(v):
            return {}
        return {f"{key}_p50": float(np.percentile(v, 50)),
                f"{key}_p99": float(np.percentile(v, 99)),
                f"{key}_max": float(v.max())}

    out = {"requests": len(records), "errors": len(records) - len(ok), "wall_seconds": wall,
           "requests_per_second": len(records) / wall if wall else 0.0,
           "client_cpu_ms_per_request": float(np.mean([r.get("client_cpu_ms", 0.0)
                                                       for r in records]))}
    for key in ("app", "wait", "plan", "client_ms"):
        out.update(pct(key))
    statuses: dict[int, int] = {}
    for r in records:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
    out["statuses"] = statuses
    return out


def check_plan_load(map_name: str, algorithm: str) -> Path:
    """The bundled map ``map_name``'s path when it is one and ``algorithm`` is a grid
    algorithm, else an OptionError naming the option: before any server starts, not a
    load of answers that are all 422."""
    from skyroute.errors import check_choice
    from skyroute.search.grid_plan import GRID_ALGORITHMS
    from skyroute.world.load import bundled_maps

    maps = bundled_maps()
    if map_name not in maps:
        raise OptionError(f"map={map_name!r} is not a bundled map; choose one of "
                          + ", ".join(repr(m) for m in maps), param="map")
    check_choice("algorithm", algorithm, GRID_ALGORITHMS)
    return maps[map_name]


def plan_queries(map_name: str, n: int, *, seed: int = 0,
                 algorithm: str = "astar") -> list[dict]:
    """``n`` POST /plan bodies: scenario lines of ``map_name`` drawn uniformly (seeded)."""
    from skyroute.world.movingai import read_scen

    scen = read_scen(str(check_plan_load(map_name, algorithm)) + ".scen")
    rows = np.random.default_rng(seed).integers(0, len(scen), n)
    return [{"map": map_name, "start": scen.starts[i].tolist(),
             "goal": scen.goals[i].tolist(), "algorithm": algorithm, "geojson": False}
            for i in rows]


def bench_plan(*, map_name: str = "Paris_1_512", clients: int = 50, requests: int = 2000,
               warmup: int = 100, workers: int = 1, seed: int = 0, algorithm: str = "astar",
               db: str | None = None, client_processes: int = 1,
               client: str = "httpx", warm: bool = True,
               start_timeout: float | None = None) -> dict:
    """POST /plan under load: the summary (server-side ``app``, ``wait``, ``plan`` and
    client latency percentiles in ms, requests/s, errors). ``warm``, ``start_timeout``:
    the :class:`Server`'s."""
    check_load(clients=clients, requests=requests, workers=workers,
               client_processes=client_processes)
    queries = plan_queries(map_name, warmup + requests, seed=seed, algorithm=algorithm)
    auth = {"Authorization": f"Bearer {TOKEN}"}
    with tempfile.TemporaryDirectory() as tmp, \
            Server(db=db or f"sqlite:///{Path(tmp) / 'bench.db'}", workers=workers,
                   warm=warm, start_timeout=start_timeout) as srv:
        asyncio.run(_load(srv.url, [("POST", "/plan", q) for q in queries[:warmup]],
                          min(clients, 8), auth))
        cpu0 = cpu_seconds(srv.proc.pid)
        records, wall = _run_load(srv.url, [("POST", "/plan", q) for q in queries[warmup:]],
                                  clients, auth, client_processes, client)
        cpu1 = cpu_seconds(srv.proc.pid)
    return {"load": "POST /plan", "map": map_name, "algorithm": algorithm,
            "clients": clients, "client": client, "workers": workers,
            "client_processes": client_processes, **_summary(records, wall),
            **_cpu(cpu0, cpu1, len(records))}


def bench_flightpath(*, db: str, date: str | None = None, clients: int = 50,
                     requests: int = 5000, warmup: int = 200, workers: int = 1,
                     client_processes: int = 1, client: str = "httpx", warm: bool = True,
                     start_timeout: float | None = None) -> dict:
    """GET /days/{date}/flightpath.geojson under load (the first stored day unless
    ``date``): the summary, as :func:`bench_plan`'s."""
    import httpx

    check_load(clients=clients, requests=requests, workers=workers,
               client_processes=client_processes)
    with Server(db=db, workers=workers, warm=warm, start_timeout=start_timeout) as srv:
        days = httpx.get(srv.url + "/days", timeout=30).json()
        if date is None:
            flown = [d["date"] for d in days if d["moves"]]
            if not flown:
                raise SkyrouteError(f"db={db}: no day with moves stored; fly one first, "
                                    "e.g. 'skyroute deliver 2024-01-03 --data "
                                    "examples/lunch --db URL'", param="db")
            date = flown[0]
        path = f"/days/{date}/flightpath.geojson"
        asyncio.run(_load(srv.url, [("GET", path, None)] * warmup, min(clients, 8), {}))
        cpu0 = cpu_seconds(srv.proc.pid)
        records, wall = _run_load(srv.url, [("GET", path, None)] * requests, clients, {},
                                  client_processes, client)
        cpu1 = cpu_seconds(srv.proc.pid)
    return {"load": f"GET {path}", "clients": clients, "client": client, "workers": workers,
            "client_processes": client_processes, **_summary(records, wall),
            **_cpu(cpu0, cpu1, len(records))}


def _cpu(before: float | None, after: float | None, n: int) -> dict:
    """The server's CPU per request, and the requests per second one core of it could
    answer at that cost (the load generator and other work left out)."""
    if before is None or after is None or not n or after <= before:
        return {}
    ms = (after - before) * 1e3 / n
    return {"server_cpu_ms_per_request": ms, "per_core_requests_per_second": 1e3 / ms}
