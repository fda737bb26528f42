"""A server behind a reverse proxy that serves it under a path (``skyroute serve
--root-path /sky``, uvicorn's ``root_path``): the URLs the service hands out (the
``Link`` of a page of runs, a job's ``Location``, a run's ``files``, the 404 page's links)
start with that path, and are as before without one; the viewer's pages link relatively.

The clients ask as uvicorn passes a request on: its path with the prefix in front
(``TestClient(root_path=...)`` alone leaves the path as asked)."""

from __future__ import annotations

import re

import pytest

from tests.service.conftest import AUTH, EXAMPLE, TOKEN, TestClient
from tests.service.test_app import assert_problem
from tests.service.test_jobs_fleet import FakeJobs, needs_jobs

PREFIXES = ["", "/sky", "/a/b"]


def client_at(prefix: str, **settings) -> TestClient:
    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    app = create_app(Settings(token=TOKEN, warm=False, **settings))
    return TestClient(app, root_path=prefix)


def _runs(url: str, n: int) -> list[str]:
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    eng = make_engine(url)
    ids = [store.save_fleet_run(eng, scenario="seed-3x3", params={"n": i}, report={},
                                events_jsonl="", tracks_csv=b"", packages_csv="",
                                fleet_geojson="{}") for i in range(n)]
    eng.dispose()
    return ids


@needs_jobs
@pytest.mark.parametrize("prefix", PREFIXES)
def test_the_next_page_of_runs_is_linked_under_the_root_path(tmp_path, prefix):
    """The Link was ``</fleet/runs?...>`` whatever the prefix: behind the proxy, a client
    following it left the server's path (a 404, or another site's page)."""
    url = f"sqlite:///{tmp_path / 'runs.db'}"
    saved = _runs(url, 5)
    with client_at(prefix, db_url=url) as c:
        seen, path = [], f"{prefix}/fleet/runs?limit=2"
        while path:
            r = c.get(path)
            assert r.status_code == 200, r.text
            seen += [x["id"] for x in r.json()]
            link = r.headers.get("link")
            if link is None:
                break
            path = re.fullmatch(r'<([^>]*)>; rel="next"', link)[1]
            assert path == f"{prefix}/fleet/runs?offset={len(seen)}&limit=2", link
        assert sorted(seen) == sorted(saved)
        run = c.get(f"{prefix}/fleet/runs/{saved[0]}").json()
        assert run["files"]["tracks.csv"] == f"{prefix}/fleet/runs/{saved[0]}/tracks.csv"
        assert c.get(run["files"]["tracks.csv"]).status_code == 200


@pytest.mark.parametrize("prefix", PREFIXES)
def test_a_jobs_location_is_under_the_root_path(tmp_path, monkeypatch, prefix):
    FakeJobs().install(monkeypatch)
    with client_at(prefix, db_url=f"sqlite:///{tmp_path / 'j.db'}", data_dir=EXAMPLE) as c:
        r = c.post(f"{prefix}/jobs/deliver", json={"date": "2024-01-03"}, headers=AUTH)
        assert r.status_code == 202, r.text
        assert r.headers["location"] == f"{prefix}/jobs/{r.json()['id']}"
        assert c.get(r.headers["location"]).json()["id"] == r.json()["id"]


@pytest.mark.parametrize("prefix", PREFIXES)
def test_api_and_viewer_paths_are_told_apart_under_the_root_path(tmp_path, prefix):
    """The 404 page, the 405's Allow and which paths are the API's read the path under
    the prefix: under /sky every path was taken for a viewer page (a browser asking for
    an unknown run got the HTML page) and a 405 had no Allow."""
    with client_at(prefix, db_url=f"sqlite:///{tmp_path / 'e.db'}") as c:
        page = c.get(f"{prefix}/no-such-page.html", headers={"Accept": "text/html"})
        assert page.status_code == 404 and page.headers["content-type"].startswith("text/html")
        for link in re.findall(r'(?:href|src)="([^"]*)"', page.text):
            assert link.startswith(f"{prefix}/"), link
            assert c.get(link).status_code == 200, link
        api = c.get(f"{prefix}/fleet/runs/nope/x", headers={"Accept": "text/html"})
        assert_problem(api, 404, words=f"no such resource: {prefix}/fleet/runs/nope/x")
        r = c.put(f"{prefix}/days/2024-01-03", headers=AUTH)
        assert_problem(r, 405)
        assert r.headers["allow"] == "DELETE, GET, HEAD"
        assert c.get(f"{prefix}/health").status_code == 200
        docs = c.get(f"{prefix}/docs").text
        assert f"'{prefix}/openapi.json'" in docs or f'"{prefix}/openapi.json"' in docs


def test_the_viewers_pages_link_relatively():
    """Every page of the viewer is at the top of the mount: its links and scripts are
    relative to it (``viewer.css``, ``js/day.js``, ``day.html``), so the pages load
    under a prefix too (they named ``/viewer.css``)."""
    from skyroute.service.app import STATIC

    pages = sorted(STATIC.glob("*.html"))
    assert len(pages) >= 5
    for page in pages:
        links = re.findall(r'(?:href|src)="([^"]*)"', page.read_text())
        assert links, page
        rooted = [x for x in links if x.startswith("/")]
        assert not rooted, (page.name, rooted)


@pytest.mark.parametrize("given, passed", [
    ("/sky", "/sky"), ("/sky/", "/sky"), ("/a/b", "/a/b"), ("", ""), ("/", "")])
def test_serve_passes_the_root_path_to_uvicorn(monkeypatch, capsys, tmp_path, given,
                                               passed):
    import uvicorn

    from tests.cli.test_cli import run

    served = []
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: served.append(kw))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "root-path-token-0001")
    code, _, err = run(monkeypatch, capsys, "serve", "--db",
                       f"sqlite:///{tmp_path / 's.db'}", "--root-path", given)
    assert code in (0, None) and len(served) == 1, err
    assert served[0]["root_path"] == passed
    assert (f"under {passed}/" in err) == bool(passed), err


@pytest.mark.parametrize("given", ["sky", "/sky?x=1", "/s ky", "/a//b", "/café"])
def test_a_root_path_that_is_no_path_is_one_line(monkeypatch, capsys, tmp_path, given):
    from tests.cli.test_cli import run

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SKYROUTE_TOKEN", "root-path-token-0001")
    code, _, err = run(monkeypatch, capsys, "serve", "--root-path", given)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert f"--root-path {given!r} must be" in err, err
