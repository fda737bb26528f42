"""The app as a whole: health, OpenAPI, the static page, errors as problem+json, limits,
the timing header, and that making an app connects to nothing."""

from __future__ import annotations

import re
from typing import Annotated

import pytest
from fastapi import Depends, FastAPI, Query  # module level: the test app's annotations

from skyroute.service.auth import require_token
from tests.service.conftest import AUTH, TOKEN, make_client

PROBLEM = "application/problem+json"


def assert_problem(r, status: int, field: str | None = None, words: str = "") -> dict:
    assert r.status_code == status, r.text
    assert r.headers["content-type"] == PROBLEM
    doc = r.json()
    assert doc["status"] == status and doc["type"].startswith("urn:skyroute:problem:")
    assert doc["title"] and doc["detail"]
    assert "Traceback" not in r.text and 'File "' not in r.text
    if field is not None:
        assert doc["field"] == field, doc
        assert doc["errors"][0]["field"] == field
    assert words in doc["detail"], doc
    return doc


def test_health_docs_and_static_page(client):
    r = client.get("/health")
    assert r.status_code == 200 and r.json() == {"status": "ok", "version": "0.1.0"}
    assert r.headers["server-timing"].startswith("app;dur=")
    spec = client.get("/openapi.json").json()
    for path in ("/health", "/maps", "/maps/{name}", "/days", "/days/{date}",
                 "/days/{date}/flightpath.geojson", "/orders", "/site.geojson", "/plan",
                 "/jobs/deliver", "/jobs/fleet", "/jobs/{job_id}", "/fleet/runs",
                 "/fleet/runs/{run_id}", "/fleet/runs/{run_id}/events.jsonl",
                 "/fleet/runs/{run_id}/tracks.csv", "/fleet/runs/{run_id}/fleet.geojson"):
        assert path in spec["paths"], path
    assert spec["components"]["securitySchemes"]["HTTPBearer"]["scheme"] == "bearer"
    assert "swagger" in client.get("/docs").text.lower()
    page = client.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert 'href="docs"' in page.text and "POST /plan" in page.text


VIEWER_FILES = ("/", "/index.html", "/day.html", "/planner.html", "/world.html",
                "/fleet.html", "/js/day.js", "/viewer.css", "/favicon.svg")


@pytest.mark.parametrize("path", VIEWER_FILES)
def test_the_viewer_runs_only_its_own_scripts(client, path):
    """Every viewer file carries a CSP that runs no inline script, no eval and nothing
    from another origin, and lets no other site frame the page (a customer's or an
    airport's name holding ``<script>``, were it ever set as HTML, would not run), and
    nosniff."""
    r = client.get(path)
    assert r.status_code == 200
    policy = dict(d.strip().split(" ", 1) for d in r.headers["content-security-policy"]
                  .split(";"))
    assert policy["script-src"] == "'self'" and policy["default-src"] == "'self'"
    assert policy["frame-ancestors"] == "'none'" and policy["object-src"] == "'none'"
    assert policy["connect-src"] == "'self'"
    assert r.headers["x-content-type-options"] == "nosniff"
    r = client.get(path, headers={"If-None-Match": r.headers["etag"]})
    assert r.status_code == 304 and "content-security-policy" in r.headers


@pytest.mark.parametrize("path", [p for p in VIEWER_FILES if p.endswith(".html")])
def test_the_viewer_pages_need_no_inline_script(client, path):
    """What the policy would block is not in the pages: every script is a file of this
    server, and no element has an ``on...=`` handler."""
    import re

    html = client.get(path).text
    scripts = re.findall(r"<script\b([^>]*)>(.*?)</script>", html, flags=re.S | re.I)
    assert all(re.search(r'src="/?js/[^"]+"', a) and not body.strip()
                           for a, body in scripts), scripts
    assert not re.search(r"<[^>]+\son[a-z]+\s*=", html, flags=re.I)
    assert "javascript:" not in html.lower()


def _contrast(a: str, b: str) -> float:
    """WCAG 2 contrast ratio of two ``#rrggbb`` colours."""
    def lum(c: str) -> float:
        rgb = [int(c[i:i + 2], 16) / 255 for i in (1, 3, 5)]
        r, g, b = (x / 12.92 if x <= 0.03928 else ((x + 0.055) / 1.055) ** 2.4 for x in rgb)
        return 0.2126 * r + 0.7152 * g + 0.0722 * b

    hi, lo = sorted((lum(a), lum(b)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def test_the_viewer_colours_can_be_told_apart(client):
    """The focus ring (amber #f0a000) was 2.2:1 on the white panels and 2.0:1 on the
    page, under the 3:1 WCAG asks of a focus indicator: a keyboard user lost where the
    focus was. It is 3:1 or more on every background it is drawn on (the panels, the
    page, the header), and the text colours keep 4.5:1 on theirs."""
    css = client.get("/viewer.css").text
    colour = dict(re.findall(r"--([a-z-]+):\s*(#[0-9a-f]{6})\b", css))
    for back in ("paper", "wash", "ink"):
        assert _contrast(colour["focus"], colour[back]) >= 3, back
    for text, back in (("ink", "paper"), ("ink", "wash"), ("muted", "paper"), ("muted", "wash"),
                       ("accent", "paper"), ("accent", "wash"), ("accent-ink", "accent"),
                       ("ok", "paper"), ("bad", "paper"), ("warn", "paper")):
        assert _contrast(colour[text], colour[back]) >= 4.5, (text, back)


@pytest.mark.parametrize("page", ["/docs", "/redoc"])
def test_api_reference_needs_no_internet(client, page):
    """Swagger UI and ReDoc load their scripts and styles from this server (FastAPI's
    default pages fetch them from a CDN, and show a blank page offline)."""
    import re

    html = client.get(page).text
    assert not re.findall(r"https?://", html), html
    assets = re.findall(r'(?:src|href)="([^"]+)"', html)
    assert any(a.endswith(".js") for a in assets), assets
    for asset in assets:
        r = client.get(asset)
        assert r.status_code == 200 and len(r.content) > 0, asset


def test_unknown_path_and_method_are_problems(client):
    assert_problem(client.get("/no/such/thing"), 404, words="/no/such/thing")
    assert_problem(client.delete("/health"), 405, words="DELETE")


BROWSER = ("text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,"
           "image/webp,*/*;q=0.8")  # Chromium's Accept when it navigates


@pytest.mark.parametrize("path", ["/planer.html", "/no/such/thing", "/js/<b>x</b>"])
def test_a_browser_on_a_missing_page_gets_a_page_linking_home(client, path):
    """A browser that mistypes a page got the problem+json document as raw text."""
    r = client.get(path, headers={"Accept": BROWSER})
    assert r.status_code == 404 and r.headers["content-type"].startswith("text/html")
    assert "does not exist" in r.text and '<a href="/">' in r.text
    assert "<b>" not in r.text and "Accept" in r.headers["vary"]  # the path is escaped


def test_the_missing_page_page_has_the_viewers_policy(client):
    """The 'Page not found' page is a viewer page that shows the path asked for: it
    carries the viewer's Content-Security-Policy and nosniff as the others do (it had
    neither, the one viewer page a crafted link writes into)."""
    from skyroute.service.viewer import HEADERS

    r = client.get("/planer.html", headers={"Accept": BROWSER})
    assert r.status_code == 404 and r.headers["content-type"].startswith("text/html")
    for name, value in HEADERS.items():
        assert r.headers[name] == value, name


@pytest.mark.parametrize("accept", [None, "*/*", "application/json",
                                    "application/problem+json",
                                    "text/html;q=0.5, application/json",
                                    "image/avif,image/webp,*/*;q=0.8"])
def test_an_api_client_on_a_missing_page_still_gets_a_problem(client, accept):
    headers = {} if accept is None else {"Accept": accept}
    assert_problem(client.get("/planer.html", headers=headers), 404, words="/planer.html")


@pytest.mark.parametrize("path", ["/fleet/nope", "/days/2024-01-03/nope", "/jobs/x/y",
                                  "/docs/nope", "/plan/x"])
def test_a_browser_under_the_api_gets_a_problem(client, path):
    r = client.get(path, headers={"Accept": BROWSER})
    assert r.status_code in (404, 405) and r.headers["content-type"] == PROBLEM, r.text


@pytest.mark.parametrize("path", ["/plan", "/jobs/deliver", "/jobs/fleet"])
@pytest.mark.parametrize("method", ["GET", "HEAD", "PUT", "PATCH", "DELETE", "OPTIONS"])
def test_post_only_paths_allow_post(client, path, method):
    r = client.request(method, path, headers=AUTH)
    assert r.status_code == 405 and r.headers["allow"] == "POST"
    if method != "HEAD":
        assert_problem(r, 405, words=f"{method} is not allowed on {path}; use POST")


@pytest.mark.parametrize("method, path, allow", [
    # DELETE /days/{date} is served: the 405 (from the viewer's mount at /, which
    # matches every path) said "GET, HEAD" for every API path
    ("PUT", "/days/2024-01-03", "DELETE, GET, HEAD"),
    ("PATCH", "/days/2024-01-03", "DELETE, GET, HEAD"),
    ("DELETE", "/days", "GET, HEAD"),
    ("DELETE", "/fleet/runs/x", "GET, HEAD"),
    ("PUT", "/days/2024-01-03/flightpath.geojson", "GET, HEAD"),
    ("TRACE", "/plan", "POST"),
])
def test_a_405_allows_the_methods_the_path_serves(client, method, path, allow):
    r = client.request(method, path, headers=AUTH)
    assert r.status_code == 405 and r.headers["allow"] == allow
    assert_problem(r, 405, words=f"{method} is not allowed on {path}")


def test_making_an_app_connects_to_nothing(tmp_path, caplog):
    """A store that cannot be opened fails the requests that need it (503), not the
    app: create_app and /health never touch it."""
    with make_client(db_url="postgresql+psycopg://nobody:pw@127.0.0.1:1/none") as c:
        assert c.get("/health").status_code == 200
        assert c.get("/maps").status_code == 200
        doc = assert_problem(c.get("/days"), 503, words="the store cannot be opened")
        assert doc["type"] == "urn:skyroute:problem:store-unavailable"
        assert "127.0.0.1" not in doc["detail"] and "nobody" not in doc["detail"]
    logged = [r.getMessage() for r in caplog.records if r.name == "skyroute.service"]
    assert any("nobody:***@127.0.0.1:1/none: cannot connect" in m for m in logged), logged
    assert not any(":pw@" in m for m in logged)


def test_a_store_lost_after_it_was_opened_is_a_503(fresh_pg, caplog):
    """The store's database gone under the running server (its server down or
    restarting, the database dropped) was a 500 'internal error' and a traceback in the
    log at every request; it is the 503 the docs promise ("the store ... cannot be
    reached"), with Retry-After, and one line in the log."""
    import sqlalchemy as sa

    from tests.conftest import PG

    with make_client(db_url=fresh_pg) as c:
        assert c.get("/days").status_code == 200  # the store opened, a connection pooled
        admin = sa.create_engine(PG, isolation_level="AUTOCOMMIT")
        name = sa.engine.make_url(fresh_pg).database
        with admin.connect() as a:
            a.execute(sa.text(f"drop database {name} with (force)"))
        admin.dispose()
        caplog.clear()
        for _ in range(2):  # the pooled connection, then a new one: both refused
            r = c.get("/days")
            doc = assert_problem(r, 503, words="the store cannot be reached")
            assert doc["type"] == "urn:skyroute:problem:store-unavailable"
            assert r.headers["retry-after"] == "10" and name not in r.text
    logged = [r for r in caplog.records if r.name == "skyroute.service"]
    assert logged and all(r.exc_info is None for r in logged), logged
    assert f'database "{name}" does not exist' in logged[-1].getMessage()


def test_a_503_names_no_path_of_the_server(tmp_path, caplog):
    """A store or delivery site that cannot be opened was a 503 whose detail named the
    store's file (``url=sqlite:////srv/...``) or the site's folder: where the server
    keeps its data, to anyone. The detail now says which is unavailable; the reason,
    with the path, is in the server's log."""
    (tmp_path / "taken").write_text("a file, not a folder\n")
    store = tmp_path / "taken" / "sub" / "x.db"
    with make_client(db_url=f"sqlite:///{store}") as c:
        doc = assert_problem(c.get("/days"), 503, words="the store cannot be opened; the "
                             "server's log says why")
        assert str(tmp_path) not in c.get("/days").text, doc
    nosite = tmp_path / "not-a-site"
    nosite.mkdir()
    with make_client(db_url=f"sqlite:///{tmp_path / 's.db'}", data_dir=nosite) as c:
        r = c.get("/site.geojson")
        doc = assert_problem(r, 503, words="the delivery site cannot be read; the server's "
                             "log says why")
        assert doc["type"] == "urn:skyroute:problem:site-unavailable"
        assert str(tmp_path) not in r.text
    logged = [r.getMessage() for r in caplog.records if r.name == "skyroute.service"]
    assert any(f"cannot make the store's folder {store.parent}" in m for m in logged), logged
    assert any(str(nosite) in m for m in logged), logged


def test_a_host_not_allowed_is_a_400_problem_before_the_body_is_read(tmp_path):
    """``Settings.allowed_hosts`` (``serve --allowed-hosts``): Starlette's Host check,
    its refusal a problem document like every other error (Starlette says "Invalid host
    header" as text), before the body limit reads a byte; HEAD as GET, without a body.
    The app factory's default takes any Host (``*``), as TestClient's ``testserver``."""
    from skyroute.service.settings import Settings

    assert Settings().allowed_hosts == ("*",)
    with make_client(db_url=f"sqlite:///{tmp_path / 'h.db'}",
                     allowed_hosts=("localhost", "::1")) as c:
        doc = assert_problem(c.get("/health"), 400, words="the Host 'testserver' is not "
                             "one of this server's names (skyroute serve --allowed-hosts)")
        assert doc["type"] == "urn:skyroute:problem:untrusted-host"
        for host in ("localhost:8000", "[::1]:8000", "LocalHost"):
            assert c.get("/health", headers={"Host": host}).status_code == 200, host
        big = c.post("/plan", content=b"x" * (11 * 1024 * 1024), headers=AUTH)
        assert_problem(big, 400, words="not one of this server's names")  # not a 413
        head = c.head("/health")
        assert head.status_code == 400 and head.content == b""
        assert c.get("/health", headers={"Host": "localhost.attacker.example"}
                     ).status_code == 400


def test_settings_refuse_two_sites_and_bad_limits(tmp_path):
    from pydantic import ValidationError

    from skyroute.service.settings import Settings

    with pytest.raises(ValidationError, match="at most one of data_dir and source_url"):
        Settings(data_dir=tmp_path, source_url="http://x")
    with pytest.raises(ValidationError):
        Settings(max_body_bytes=0)
    a, b = Settings(), Settings()
    assert a.token != b.token and len(a.token) >= 32  # a fresh random token each time


def test_body_over_the_limit_is_413(tmp_path):
    with make_client(db_url=f"sqlite:///{tmp_path / 'x.db'}", max_body_bytes=1000) as c:
        big = {"map_text": "x" * 2000, "start": [0, 0], "goal": [1, 1]}
        assert_problem(c.post("/plan", json=big, headers=AUTH), 413, words="limit is 1,000")

        def chunks():  # no Content-Length: counted as it streams in
            for _ in range(5):
                yield b"x" * 300

        assert_problem(c.post("/plan", content=chunks(), headers=AUTH), 413,
                       words="limit is 1,000")
        small = {"map": "den312d", "start": [50, 76], "goal": [60, 13], "geojson": False}
        assert c.post("/plan", json=small, headers=AUTH).status_code == 200


def test_a_chunked_body_under_the_limit_arrives_whole(client):
    body = b'{"map": "den312d", "start": [50, 76], "goal": [60, 13], "geojson": false}'

    def chunks():
        for k in range(0, len(body), 7):
            yield body[k:k + 7]

    r = client.post("/plan", content=chunks(), headers={**AUTH,
                                                         "Content-Type": "application/json"})
    assert r.status_code == 200 and r.json()["status"] == "found"


def test_an_unexpected_error_is_a_500_that_hides_its_cause(tmp_path):
    from fastapi.testclient import TestClient

    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    app = create_app(Settings(token=TOKEN))

    @app.get("/boom")
    def boom():
        raise RuntimeError("secret internals at /etc/shadow")

    app.router.routes.insert(0, app.router.routes.pop())  # before the static mount
    with TestClient(app, raise_server_exceptions=False) as c:
        doc = assert_problem(c.get("/boom"), 500)
        assert "secret" not in c.get("/boom").text and "RuntimeError" not in doc["detail"]


@pytest.mark.parametrize("headers, status", [
    ({}, 401),
    ({"Authorization": "Basic dXNlcjpwYXNz"}, 401),
    ({"Authorization": "Bearer"}, 401),
    ({"Authorization": "Bearer wrong-token"}, 403),
    ({"Authorization": f"Bearer {TOKEN}x"}, 403),
    ({"Authorization": f"Bearer {TOKEN[:-1]}"}, 403),
])
@pytest.mark.parametrize("path, body", [
    ("/plan", {"map": "den312d", "start": [50, 76], "goal": [60, 13]}),
    ("/plan", {"bad": "body"}),  # the token is checked before the body
    ("/jobs/deliver", {"date": "2024-01-03"}),
    ("/jobs/fleet", {"preset": "seed-3x3"}),
])
def test_writes_need_the_token(client, headers, status, path, body):
    r = client.post(path, json=body, headers=headers)
    assert_problem(r, status)
    if status == 401:
        assert r.headers["www-authenticate"] == "Bearer"


def test_reads_need_no_token(client):
    for path in ("/health", "/maps", "/maps/den312d", "/days", "/orders?date=2024-01-01"):
        assert client.get(path).status_code == 200, path


@pytest.mark.parametrize("path", ["/health", "/maps", "/maps/den312d", "/days",
                                  "/orders?date=2024-01-01", "/openapi.json", "/"])
def test_head_answers_as_get_without_a_body(client, path):
    """HEAD on a readable resource is its GET's status and headers (RFC 9110), not the
    404 the viewer's static mount gave for every API path."""
    get, head = client.get(path), client.head(path)
    assert get.status_code == 200
    assert head.status_code == 200 and head.content == b""
    assert head.headers["content-type"] == get.headers["content-type"]


def test_head_on_an_unknown_resource_is_its_get_status(client):
    r = client.head("/maps/atlantis")
    assert r.status_code == 404 and r.content == b""
    assert r.headers["content-type"] == PROBLEM


@pytest.mark.parametrize("path, body", [
    ("/plan", '{"map": "den312d", "start": [50, 76], "goal": [60, 13]}'),
    ("/jobs/deliver", '{"date": "2024-01-03"}'),
    ("/jobs/fleet", '{"preset": "seed-3x3"}'),
])
@pytest.mark.parametrize("ctype, words", [
    ("text/plain", "Content-Type text/plain is not JSON"),
    ("application/x-www-form-urlencoded",  # what `curl -d` sends
     "Content-Type application/x-www-form-urlencoded is not JSON"),
    ("application/xml; charset=utf-8", "Content-Type application/xml is not JSON"),
    (None, "no Content-Type"),
])
def test_a_body_that_is_not_declared_json_is_415(client, path, body, ctype, words):
    """A JSON body sent as another media type (or none) is never read: a 415 naming the
    media type, not a 422 saying the body is not an object."""
    headers = {**AUTH, **({"Content-Type": ctype} if ctype else {})}
    doc = assert_problem(client.post(path, content=body, headers=headers), 415, words=words)
    assert "application/json" in doc["detail"] and "field" not in doc


@pytest.mark.parametrize("ctype", ["application/json", "application/json; charset=utf-8",
                                   "application/merge-patch+json"])
def test_json_media_types_are_read(client, ctype):
    body = b'{"map": "den312d", "start": [50, 76], "goal": [60, 13], "geojson": false}'
    r = client.post("/plan", content=body, headers={**AUTH, "Content-Type": ctype})
    assert r.status_code == 200, r.text


def test_documented_errors_include_415_and_503(client):
    """Every body takes a 415; every operation that opens the store may answer 503."""
    spec = client.get("/openapi.json").json()
    for path, ops in spec["paths"].items():
        for method, op in ops.items():
            if "requestBody" in op:
                assert "415" in op["responses"], (method, path)
    for path in ("/days", "/days/{date}", "/days/{date}/flightpath.geojson", "/orders",
                 "/site.geojson", "/jobs/{job_id}", "/fleet/runs"):
        assert "503" in spec["paths"][path]["get"]["responses"], path


@pytest.mark.parametrize("path, body, field", [
    ("/plan", {"map": "den312d", "start": [50, 76]}, "goal"),  # pydantic's check
    ("/plan", {"map_text": "garbage", "start": [0, 0], "goal": [1, 1]}, "map_text"),
    ("/jobs/fleet", {"scenario": {"name": "x"}}, "scenario.airports"),
    ("/jobs/fleet", {"preset": "seed-3x3", "rate": 100000, "hours": 24}, "rate"),
])
def test_an_errors_message_is_the_detail_without_its_field(client, path, body, field):
    """``errors[].message`` reads the same whoever found the fault (the model or a
    router): the detail is ``field: message``, the message does not repeat the field."""
    doc = assert_problem(client.post(path, json=body, headers=AUTH), 422, field)
    message = doc["errors"][0]["message"]
    assert doc["detail"] == f"{field}: {message}" and not message.startswith(field)


def test_shutdown_ends_the_jobs_worker_processes(tmp_path):
    """At shutdown the jobs' workers end with their tasks (a running job stays running
    in the store and is failed as an orphan). They ran on: 'skyroute serve' stopped by
    SIGTERM left them behind, holding its stdout and stderr, each task to its end."""
    import multiprocessing
    import threading
    import time

    from skyroute.service.resources import Resources
    from skyroute.service.settings import Settings

    res = Resources(Settings(db_url=f"sqlite:///{tmp_path / 'x.db'}", job_workers=2))
    ex = res.executor()
    from skyroute.jobs.executor import ExecutorClosedError

    raised: list[BaseException] = []

    def run() -> None:
        try:
            ex.map(time.sleep, [30.0, 30.0, 30.0])
        except BaseException as exc:  # what a job's lane sees when the server stops
            raised.append(exc)

    others = set(multiprocessing.active_children())  # other tests' pools, ending

    def ours():
        return [p for p in multiprocessing.active_children()
                if p not in others and p.is_alive()]

    lane = threading.Thread(target=run)
    lane.start()
    while len(ours()) < 2:  # the workers have started, with the tasks submitted
        time.sleep(0.01)
    res.close()
    lane.join(timeout=10)
    assert not lane.is_alive()  # its map ended: the workers are gone
    assert [type(e) for e in raised] == [ExecutorClosedError]  # the runner's orphan case
    assert ours() == []


def test_a_cancelled_lifespan_still_closes_the_resources(monkeypatch):
    """A second Ctrl-C to 'skyroute serve' is uvicorn's forced exit: no shutdown is
    sent, the lifespan is cancelled as the loop ends. The resources were not closed (the
    jobs' workers ran on, the exit waited for their tasks, and the running job failed
    with "cannot schedule new futures after shutdown", not as an orphan) and starlette
    logged the cancellation as a failed shutdown, a KeyboardInterrupt traceback."""
    import asyncio

    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    app = create_app(Settings(token=TOKEN, warm=False, db_url="sqlite://"))
    closed: list[bool] = []
    monkeypatch.setattr(app.state.resources, "close", lambda: closed.append(True))

    async def serve() -> None:
        running = asyncio.Event()

        async def lifespan() -> None:  # as starlette's router holds it while serving
            async with app.router.lifespan_context(app):
                running.set()
                await asyncio.Event().wait()  # starlette's wait for the shutdown message

        task = asyncio.create_task(lifespan())
        await running.wait()
        task.cancel()  # the loop's end cancels what still runs
        await asyncio.wait({task})
        assert not task.cancelled() and task.exception() is None  # no failed shutdown

    asyncio.run(serve())
    assert closed == [True]


def _query_routes(client) -> list[tuple[str, dict]]:
    """(path, {name: a valid value}) of every GET route of the API with query
    parameters, from its OpenAPI document (a route added later is covered too)."""
    sample = {"date": "2024-01-03", "integer": "1", "string": "x"}
    out = []
    for path, ops in client.get("/openapi.json").json()["paths"].items():
        params = (ops.get("get") or {}).get("parameters", [])
        query = {p["name"]: sample.get(p["schema"].get("format"), sample[p["schema"]["type"]])
                 for p in params if p["in"] == "query"}
        if query:
            out.append((re.sub(r"\{[^}]+\}", "x", path), query))
    return out


def test_a_repeated_query_parameter_is_a_422_naming_it(client):
    """``?date=A&date=B`` (and every other single-valued parameter given twice) used one
    of the values and dropped the other without a word; it is a 422 naming it."""
    routes = _query_routes(client)
    assert {p for p, _ in routes} >= {"/orders", "/fleet/runs", "/fleet/runs/x"}
    for path, query in routes:
        for name, value in query.items():
            pairs = [*query.items(), (name, value)]  # the same value twice, even
            r = client.get(path, params=pairs)
            assert r.status_code == 422, (path, name, r.text)
            assert r.headers["content-type"] == "application/problem+json"
            doc = r.json()
            assert doc["field"] == name and doc["detail"] == \
                f"{name}: given 2 times ({value!r}, {value!r}); give it once", doc
    r = client.get("/orders", params=[("date", "2024-01-03"), ("date", "2024-01-04")])
    assert r.json()["detail"] == "date: given 2 times ('2024-01-03', '2024-01-04'); " \
                                 "give it once"
    assert client.get("/orders", params={"date": "2024-01-03"}).status_code == 200
    assert client.get("/health?x=1&x=2").status_code == 200  # not a parameter of it


def _page(offset: int = 0) -> int:  # a dependency reading a query parameter
    return offset


def test_a_list_query_parameter_still_takes_every_value():
    """The check reads which parameters a route takes as one value: a list takes every
    repeat (also optional, or inside a dependency), a scalar in a dependency does not."""
    from skyroute.service import problems, query
    from tests.service.conftest import TestClient

    app = FastAPI(dependencies=[Depends(query.one_value_each)])
    problems.install(app)

    @app.get("/many")
    def many(tag: Annotated[list[str], Query()],
             more: Annotated[list[int] | None, Query()] = None,
             at: Annotated[int, Depends(_page)] = 0) -> dict:
        return {"tag": tag, "more": more, "at": at}

    c = TestClient(app)
    r = c.get("/many?tag=a&tag=b&more=1&more=2&offset=3")
    assert r.status_code == 200 and r.json() == {"tag": ["a", "b"], "more": [1, 2], "at": 3}
    r = c.get("/many?tag=a&offset=3&offset=4")
    assert r.status_code == 422 and r.json()["field"] == "offset", r.text


def _paged_for_the_token(_: Annotated[None, Depends(require_token)],
                         limit: int = 10) -> int:  # a dependency needing both
    return limit


@pytest.mark.parametrize("headers, status", [
    ({}, 401), ({"Authorization": "Bearer wrong-token"}, 403), (AUTH, 422)])
def test_a_repeated_query_parameter_is_checked_after_the_token(headers, status):
    """The app-wide check ran before the route's token: a caller without it was told
    422 "limit: given 2 times", a detail of the route. (No route of the app takes both
    a token and a single-valued query parameter yet; a test app's routes do.)"""
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings
    from tests.service.conftest import TestClient

    app = create_app(Settings(token=TOKEN, warm=False))

    @app.delete("/things", dependencies=[Depends(require_token)])
    def things(limit: int = 10) -> dict:
        return {"limit": limit}

    @app.delete("/deep")  # the token and the parameter in a dependency of the route
    def deep(limit: Annotated[int, Depends(_paged_for_the_token)]) -> dict:
        return {"limit": limit}

    for _ in range(2):  # before the viewer's mount at /
        app.router.routes.insert(0, app.router.routes.pop())
    c = TestClient(app)
    for path in ("/things", "/deep"):
        r = c.delete(f"{path}?limit=1&limit=2", headers=headers)
        doc = assert_problem(r, status)
        assert ("limit" in doc["detail"]) == (status == 422), doc
        if status == 401:
            assert r.headers["www-authenticate"] == "Bearer"
        assert c.delete(f"{path}?limit=1", headers=headers).status_code == \
            (200 if status == 422 else status)
    # a route without the token: the 422 as before, and none without a repeat
    r = c.get("/orders?date=2024-01-03&date=2024-01-04")
    assert_problem(r, 422, field="date")


def test_responses_write_infinities_and_nans_as_null():
    """Starlette's JSONResponse refused them (a 500); the service's writes null, as
    the routes with a response model do, and is every route's default."""
    from skyroute.service.app import create_app
    from skyroute.service.json_response import FiniteJSONResponse

    body = FiniteJSONResponse({"length": float("inf"), "mean": [float("nan"), 1]}).body
    assert body == b'{"length":null,"mean":[null,1]}'
    assert create_app().router.default_response_class is FiniteJSONResponse
