"""``skyroute bench service``: the REST service under concurrent load on 127.0.0.1."""

from __future__ import annotations

import os
import platform
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from skyroute.cli.bench_cmd import bench_app
from skyroute.cli.tables import plain_console, print_table, wide_console
from skyroute.errors import SEED_MAX, OptionError, SkyrouteError, check_choice, real
from skyroute.files import check_writable, write_atomic
from skyroute.io.json_text import to_json

LOADS = ("plan", "flightpath")


@bench_app.command("service")
def bench_service(
    load: Annotated[list[str] | None, typer.Option(
        help="plan (POST /plan) or flightpath (GET /days/{date}/flightpath.geojson); "
             "repeatable; default both (flightpath needs --db).")] = None,
    clients: Annotated[int, typer.Option(help="Concurrent clients.")] = 50,
    requests: Annotated[int, typer.Option(help="Measured requests per load.")] = 2000,
    workers: Annotated[int, typer.Option(help="Server processes.")] = 1,
    client_processes: Annotated[int, typer.Option(
        help="Processes the clients are spread over.")] = 1,
    client: Annotated[str, typer.Option(
        help="httpx (AsyncClient) or raw (a minimal HTTP/1.1 client on asyncio streams: "
             "little CPU per request).")] = "httpx",
    map_name: Annotated[str, typer.Option("--map", help="Bundled map for POST /plan.")] =
        "Paris_1_512",
    algorithm: Annotated[str, typer.Option(help="Planner for POST /plan.")] = "astar",
    db: Annotated[str | None, typer.Option(
        help="Store with a flown day, for flightpath (e.g. "
             "postgresql+psycopg://postgres@127.0.0.1:5432/test).")] = None,
    date: Annotated[str | None, typer.Option(help="Day for flightpath (default: the "
                                                  "first stored day with moves).")] = None,
    seed: Annotated[int, typer.Option(
        min=0, max=SEED_MAX, help="Seed of the drawn scenario lines.")] = 0,
    warm: Annotated[bool, typer.Option(
        "--warm/--no-warm", help="The server warms each of its processes before it serves "
        "('serve --warm'): about a second from numba's cache, a minute or more with the "
        "cache empty.")] = True,
    start_timeout: Annotated[float | None, typer.Option(
        help="Seconds to wait for the server to answer /health (default 120, and 60 more "
             "for each server process past the first).")] = None,
    json_out: Annotated[Path | None, typer.Option("--json", help="Write the rows here.")] =
        None,
) -> None:
    """Load the service on 127.0.0.1 (uvicorn in a process of its own) and report
    server-side (Server-Timing) and client latency percentiles, requests/s and errors."""
    from skyroute.bench.machine import machine
    from skyroute.bench.service import (
        CLIENTS,
        bench_flightpath,
        bench_plan,
        check_load,
        check_plan_load,
    )

    loads = load or (["plan", "flightpath"] if db else ["plan"])
    for x in loads:
        check_choice("load", x, LOADS)
    check_choice("client", client, CLIENTS)
    if "flightpath" in loads and db is None:
        raise OptionError("--load flightpath needs --db URL (a store with a flown day)")
    check_load(clients=clients, requests=requests, workers=workers,
               client_processes=client_processes, flags=True)
    if start_timeout is not None:
        real("start_timeout", start_timeout, low=0.0, strict=True)
    if "plan" in loads:
        check_plan_load(map_name, algorithm)
    if json_out:  # a bad path fails now, not after the runs
        check_writable(json_out)
    rows = []
    err = plain_console(stderr=True)
    for x in loads:
        err.print(f"{x}: {requests:,} requests, {clients} {client} clients in {client_processes} "
                  f"process(es), {workers} server process(es) ...")
        server = {"warm": warm, "start_timeout": start_timeout}
        try:
            if x == "plan":
                rows.append(bench_plan(map_name=map_name, clients=clients,
                                       requests=requests, workers=workers, seed=seed,
                                       algorithm=algorithm, client=client,
                                       client_processes=client_processes, **server))
            else:
                rows.append(bench_flightpath(db=db, date=date, clients=clients,
                                             requests=requests, workers=workers,
                                             client_processes=client_processes,
                                             client=client, **server))
        except SkyrouteError as exc:
            if exc.param != "start_timeout":
                raise
            raise SkyrouteError(_start_advice(str(exc), warm)) from None
    t = Table(title=f"service under load on 127.0.0.1 ({os.cpu_count()} cores, "
                    f"{platform.python_implementation()} {platform.python_version()})")
    for col in ("load", "req/s", "errors", "server p50 ms", "server p99 ms",
                "search p50 ms", "search p99 ms", "client p50 ms", "client p99 ms",
                "server CPU ms/req", "req/s per server core", "client CPU ms/req"):
        t.add_column(col, justify="left" if col == "load" else "right")

    def ms(r: dict, key: str) -> str:
        return f"{r[key]:,.2f}" if key in r else "-"

    for r in rows:
        t.add_row(r["load"] if r["load"] != "POST /plan" else f"POST /plan {r['map']}",
                  f"{r['requests_per_second']:,.0f}", f"{r['errors']:,}", ms(r, "app_p50"),
                  ms(r, "app_p99"), ms(r, "plan_p50"), ms(r, "plan_p99"),
                  ms(r, "client_ms_p50"), ms(r, "client_ms_p99"),
                  ms(r, "server_cpu_ms_per_request"),
                  f"{r['per_core_requests_per_second']:,.0f}"
                  if "per_core_requests_per_second" in r else "-",
                  ms(r, "client_cpu_ms_per_request"))
    # the client's view and the CPU costs give way first on a narrow terminal
    print_table(wide_console(), t, optional=("client p50 ms", "client p99 ms",
                                             "server CPU ms/req", "req/s per server core",
                                             "client CPU ms/req"))
    if json_out:
        write_atomic(json_out, to_json(
            {"settings": {"load": loads, "map": map_name if "plan" in loads else None,
                          "algorithm": algorithm if "plan" in loads else None,
                          "db": _shown_url(db), "date": date,
                          "seed": seed, "requests": requests, "clients": clients,
                          "workers": workers, "client_processes": client_processes,
                          "client": client, "warm": warm},
             "machine": machine(("fastapi", "uvicorn", "httpx", "sqlalchemy")), "rows": rows},
            indent=1))


def _start_advice(message: str, warm: bool) -> str:
    """The server's timeout in the flags' words: ``--start-timeout 240 s``, and what to
    do (a longer ``--start-timeout``, or ``--no-warm``)."""
    message = message.replace("start_timeout=", "--start-timeout ")
    lead, _, _ = message.rpartition("; wait longer")
    return lead + "; give a longer --start-timeout" + (
        ", or --no-warm (each server process then loads the kernels on its first "
        "requests)" if warm else "")


def _shown_url(url: str | None) -> str | None:
    """A store's URL for a report, its password masked (SQLAlchemy's rendering)."""
    if url is None:
        return None
    from sqlalchemy.engine import make_url

    return make_url(url).render_as_string(hide_password=True)
