"""``GET /fleet/runs/{id}/packages.csv`` (the viewer's package table), against the
stand-in for ``skyroute.jobs`` of test_jobs_fleet: the file under either store layout,
404 for an unknown run and for a run stored without it."""

from __future__ import annotations

from tests.service.test_app import assert_problem
from tests.service.test_jobs_fleet import fake, site_client  # noqa: F401  (fixtures)

CSV = ("id,spawn_s,from_airport,from_gate,to_airport,to_gate,assigned_s,pickup_s,"
       "delivered_s,drone,state\n0,24.803,B,0,A,0,24.803,39.803,231.809,1,delivered\n")


def test_packages_csv_under_either_layout(site_client, fake):  # noqa: F811
    fake.runs["a"] = {"id": "a", "scenario": "seed-3x3", "packages_csv": CSV}
    fake.runs["b"] = {"id": "b", "scenario": "seed-3x3", "packages": CSV.encode()}
    for rid in ("a", "b"):
        r = site_client.get(f"/fleet/runs/{rid}/packages.csv")
        assert r.status_code == 200 and r.text == CSV
        assert r.headers["content-type"].startswith("text/csv")
        assert r.headers["content-disposition"] == 'attachment; filename="packages.csv"'


def test_packages_csv_of_no_run_or_no_file_is_404(site_client, fake):  # noqa: F811
    assert_problem(site_client.get("/fleet/runs/nope/packages.csv"), 404, words="'nope'")
    fake.runs["c"] = {"id": "c", "scenario": "seed-3x3"}
    assert_problem(site_client.get("/fleet/runs/c/packages.csv"), 404,
                   words="has no packages.csv")


def test_a_runs_files_name_packages_csv_where_it_is_stored(site_client, fake):  # noqa: F811
    """A client finds a run's files in its ``files``: packages.csv among them when the
    run has it (it was left out, though served), not when it would be a 404."""
    fake.runs["a"] = {"id": "a", "scenario": "seed-3x3", "packages_csv": CSV}
    fake.runs["c"] = {"id": "c", "scenario": "seed-3x3"}
    files = site_client.get("/fleet/runs/a").json()["files"]
    assert files["packages.csv"] == "/fleet/runs/a/packages.csv"
    assert site_client.get(files["packages.csv"]).text == CSV
    assert "packages.csv" not in site_client.get("/fleet/runs/c").json()["files"]
