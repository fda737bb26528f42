"""A fleet run's file streamed by a real uvicorn server while the run is saved again or
deleted (a fleet task run twice stores its run twice; a failed job loses its runs).

The same bytes stored again: the client gets the whole file, and the log stays quiet.
Other bytes, or the run deleted: the client never takes the part it got for the whole
file (the connection closes short of Content-Length, which httpx reports as an error);
the server logs one WARNING line naming the file, and no ERROR or traceback. Asking
again gets the run as it is now. On SQLite and PostgreSQL."""

from __future__ import annotations

import logging
import threading
import time

import httpx
import pytest

from tests.service.conftest import TOKEN

PART = 1000  # the store's part size for these runs: a file of several parts, quickly
SIZE = 3 * PART + 17
ARGS = dict(scenario="seed-3x3", params={}, report={}, events_jsonl="", packages_csv="",
            fleet_geojson="{}", run_id="r")


@pytest.fixture(params=["sqlite", "postgresql"])
def store_url(request, tmp_path, monkeypatch):
    from skyroute.jobs import store

    monkeypatch.setattr(store, "PART_BYTES", PART)
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'runs.db'}"
    return request.getfixturevalue("fresh_pg")


@pytest.fixture
def server(store_url):
    """(base URL, engine) of the app on uvicorn in a thread of this process (its log
    records reach caplog), on a free port."""
    import uvicorn

    from skyroute.service.app import create_app
    from skyroute.service.resources import make_engine
    from skyroute.service.settings import Settings

    engine = make_engine(store_url)
    app = create_app(Settings(token=TOKEN, db_url=store_url, warm=False))
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=0, log_config=None,
                                        log_level="info"))
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 60
    while not srv.started:
        assert thread.is_alive() and time.monotonic() < deadline, "uvicorn did not start"
        time.sleep(0.01)
    port = srv.servers[0].sockets[0].getsockname()[1]
    try:
        yield f"http://127.0.0.1:{port}", engine
    finally:
        srv.should_exit = True
        thread.join(60)
        engine.dispose()


def _change_after_part(monkeypatch, k: int, change) -> None:
    """Call ``change()`` once, when the server has sent part ``k`` of a file and comes
    back for the next: the run changes mid-stream, at a known byte."""
    from skyroute.jobs import store

    read = store.StoredFile._read
    pending = [change]

    def reading(self, start, *stop):
        for i, data in enumerate(read(self, start, *stop), start):
            yield data
            if i == k and pending:
                pending.pop()()

    monkeypatch.setattr(store.StoredFile, "_read", reading)


def _get(url: str) -> tuple[bytes, int, Exception | None]:
    """(the body's bytes received, its Content-Length, the error reading it, if any)"""
    got = bytearray()
    with httpx.stream("GET", url, timeout=60) as r:
        assert r.status_code == 200
        try:
            for chunk in r.iter_raw():
                got += chunk
        except httpx.HTTPError as exc:
            return bytes(got), int(r.headers["content-length"]), exc
    return bytes(got), int(r.headers["content-length"]), None


def _records(caplog, level: int) -> list[str]:
    return [f"{r.name}: {r.getMessage()}" for r in caplog.records if r.levelno == level]


def test_a_run_stored_again_with_the_same_bytes_streams_whole(server, monkeypatch, caplog):
    from skyroute.jobs import store

    base, engine = server
    tracks = bytes(range(256)) * (SIZE // 256) + b"x" * (SIZE % 256)
    store.save_fleet_run(engine, tracks_csv=tracks, **ARGS)
    _change_after_part(monkeypatch, 1, lambda: store.save_fleet_run(
        engine, tracks_csv=tracks, **ARGS))
    with caplog.at_level(logging.INFO):
        body, length, error = _get(f"{base}/fleet/runs/r/tracks.csv")
    assert (error, length, body == tracks) == (None, SIZE, True)
    assert _records(caplog, logging.WARNING) == _records(caplog, logging.ERROR) == []


@pytest.mark.parametrize("change", ["other bytes", "deleted"])
def test_a_run_changed_while_streamed_is_cut_short_with_one_warning(server, monkeypatch,
                                                                    caplog, change):
    from skyroute.jobs import store

    base, engine = server
    old, new = b"a" * SIZE, b"b" * SIZE
    job = store.create_job(engine, "fleet", {})
    store.save_fleet_run(engine, tracks_csv=old, job_id=job, **ARGS)
    _change_after_part(monkeypatch, 1, (
        (lambda: store.save_fleet_run(engine, tracks_csv=new, job_id=job, **ARGS))
        if change == "other bytes" else (lambda: store.fail_job(engine, job, "gone"))))
    with caplog.at_level(logging.INFO):
        body, length, error = _get(f"{base}/fleet/runs/r/tracks.csv")
        time.sleep(0.2)  # uvicorn's own line about the closed response comes after
    # the client: two parts, then the connection closed short of the length it was told
    assert isinstance(error, httpx.RemoteProtocolError), error
    assert "incomplete" in str(error) or "complete message body" in str(error), error
    assert (body, length) == (old[:2 * PART], SIZE)
    warned = _records(caplog, logging.WARNING)
    assert len(warned) == 1, warned
    assert warned[0] == ("skyroute.service: GET /fleet/runs/r/tracks.csv cut short after "
                         f"2,000 of its {SIZE:,} bytes: fleet run 'r' was replaced or "
                         "deleted while its tracks_csv was read (the client sees the "
                         "connection closed before the end of the body)")
    assert _records(caplog, logging.ERROR) == _records(caplog, logging.CRITICAL) == []
    assert not any(r.exc_info for r in caplog.records)
    again = httpx.get(f"{base}/fleet/runs/r/tracks.csv", timeout=60)
    if change == "deleted":
        assert again.status_code == 404
    else:
        assert (again.status_code, again.content) == (200, new)


def test_a_stored_file_follows_only_a_replacement_by_the_same_bytes(store_url):
    """The store's side, without a server: iterating a file follows its run saved again
    with the same bytes (even more than once), and stops at one with other bytes of
    the same size (the parts already read differ) or of another size."""
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    engine = make_engine(store_url)
    data = bytes(range(256)) * 14  # 3584 bytes: 4 parts
    store.save_fleet_run(engine, tracks_csv=data, **ARGS)
    f = store.open_fleet_file(engine, "r", "tracks_csv")
    got = []
    for i, part in enumerate(f):
        got.append(part)
        if i < 2:
            store.save_fleet_run(engine, tracks_csv=data, **ARGS)
    assert b"".join(got) == data
    for other in (data[:-1] + b"!", b"!" + data[1:], data + b"!"):
        f = store.open_fleet_file(engine, "r", "tracks_csv")
        parts = iter(f)
        first = next(parts)
        store.save_fleet_run(engine, tracks_csv=other, **ARGS)
        if other[0:1] == b"!" or len(other) != len(data):
            with pytest.raises(store.RunChangedError):
                next(parts)
        else:  # only the last part differs: the file read is the new one, whole
            assert first + b"".join(parts) == other
        store.save_fleet_run(engine, tracks_csv=data, **ARGS)
    engine.dispose()


def test_a_stored_file_follows_a_run_saved_again_while_it_is_compared(store_url,
                                                                       monkeypatch):
    """The run saved with the same bytes twice in quick succession, the second save
    landing while the first replacement's parts were compared with those already sent:
    the comparison met the second replacement, and the stream was cut (RunChangedError)
    although each version was the same bytes. It follows the version now instead; a run
    that changes at every comparison still ends, in the error."""
    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    engine = make_engine(store_url)
    data = bytes(range(256)) * 14  # 4 parts
    store.save_fleet_run(engine, tracks_csv=data, **ARGS)
    opened = store.open_fleet_file
    saves = []

    def save_again_once_opened(*args):
        now = opened(*args)  # the version to compare, replaced before it is read
        if saves:
            saves.pop()()
        return now

    monkeypatch.setattr(store, "open_fleet_file", save_again_once_opened)
    for again, whole in ((1, True), (store.StoredFile.FOLLOW + 1, False)):
        parts = iter(store.open_fleet_file(engine, "r", "tracks_csv"))
        first = next(parts)
        store.save_fleet_run(engine, tracks_csv=data, **ARGS)
        saves[:] = [lambda: store.save_fleet_run(engine, tracks_csv=data, **ARGS)] * again
        if whole:
            assert first + b"".join(parts) == data
        else:
            with pytest.raises(store.RunChangedError):
                list(parts)
    engine.dispose()



def test_a_run_saved_again_in_the_same_microsecond_is_another_version(store_url,
                                                                       monkeypatch):
    """A stored file's version was its run's ``created`` alone, the saving process's
    clock: a run saved again with other bytes at the same reading of the clock (a coarse
    clock's tick, a clock stepped back, another host's clock) kept the version, and a
    file being read went on in the new bytes: one file of two versions, no error. Each
    save of a run now has a later ``created`` than the one it replaces."""
    import datetime as dt

    from skyroute.jobs import store
    from skyroute.service.resources import make_engine

    engine = make_engine(store_url)
    stuck = dt.datetime(2024, 5, 1, 12, 0, 0, 123456)
    monkeypatch.setattr(store, "_now", lambda: stuck)  # the clock does not move
    old, new = b"a" * SIZE, b"b" * SIZE
    store.save_fleet_run(engine, tracks_csv=old, **ARGS)
    first = store.get_fleet_run(engine, "r", files=False)["created"]
    parts = iter(store.open_fleet_file(engine, "r", "tracks_csv"))
    assert next(parts) == old[:PART]
    store.save_fleet_run(engine, tracks_csv=new, **ARGS)
    with pytest.raises(store.RunChangedError):
        rest = b"".join(parts)
        raise AssertionError(f"read on into the new version: {rest[:8]!r}...")
    second = store.get_fleet_run(engine, "r", files=False)["created"]
    assert second > first  # one microsecond on: the clock said the same time
    monkeypatch.setattr(store, "_now", lambda: stuck - dt.timedelta(hours=1))  # stepped back
    store.save_fleet_run(engine, tracks_csv=old, **ARGS)
    assert store.get_fleet_run(engine, "r", files=False)["created"] > second
    assert b"".join(store.open_fleet_file(engine, "r", "tracks_csv")) == old
    engine.dispose()
