"""The web viewer in a browser: Playwright driving Debian's Chromium (headless, no
browser download) against the app served by uvicorn on 127.0.0.1, over the store of
``skyroute deliver`` flying examples/lunch (plus a fleet run when ``skyroute.jobs`` is
there). Each page loads without a console error, its main action works, and it is
photographed at 1280x800 and 360x740 into artefacts/screenshots/ (look at them)."""

from __future__ import annotations

import contextlib
import json
import re
import shutil
import socket
import threading
import time
from pathlib import Path

import httpx
import pytest

from tests.conftest import ROOT
from tests.service.conftest import AUTH, DAY, EXAMPLE, TOKEN

CHROMIUM = Path("/usr/bin/chromium")
if not CHROMIUM.exists():
    pytest.skip(f"browser tests: no Chromium at {CHROMIUM} (apt-get install chromium)",
                allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api",
                               reason="browser tests: playwright is not installed (dev extra)")

# how long a page may take to show what a test waits for: a bound for a loaded machine
# (a first plan compiles its kernels while the other test process runs), not a measurement
WAIT = 120_000
SHOTS = ROOT / "artefacts" / "screenshots"
VIEWPORTS = {"desktop": {"width": 1280, "height": 800}, "phone": {"width": 360, "height": 740}}
SIZES = {**VIEWPORTS, "phone-640": {"width": 360, "height": 640},  # (Page's other sizes)
         "desktop-720": {"width": 1280, "height": 720}}
FLEET_SEED = 1


def _fleet_run(db: str) -> str | None:
    """Store one short seed-3x3 run the way a fleet job does; its id (None without
    skyroute.jobs)."""
    try:
        from skyroute.jobs.fleet import FleetTask, RunSpec, fly_fleet
    except ImportError:
        return None
    from skyroute.fleet.scenario import preset
    from skyroute.service.resources import make_engine

    make_engine(db).dispose()  # the store at the newest migration (fleet_runs)
    spec = RunSpec(preset("seed-3x3").model_dump(), 0.25, FLEET_SEED)
    return fly_fleet(FleetTask(db, "viewer-test-run", None, spec))["id"]


@pytest.fixture(scope="module")
def server(lunch, tmp_path_factory):
    """(base URL, fleet run id or None, store URL): the app on a free port of 127.0.0.1,
    in a thread, over a copy of the lunch store with the examples/lunch site."""
    import uvicorn

    from skyroute.service.app import create_app
    from skyroute.service.settings import Settings

    folder = tmp_path_factory.mktemp("viewer")
    source = Path(lunch[0].removeprefix("sqlite:///"))
    db = f"sqlite:///{shutil.copy(source, folder / 'viewer.db')}"
    run_id = _fleet_run(db)
    app = create_app(Settings(db_url=db, data_dir=EXAMPLE, token=TOKEN))
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    end = time.monotonic() + 120  # a bound for a loaded machine, not a measurement
    while not server.started:
        assert thread.is_alive() and time.monotonic() < end, "uvicorn did not start"
        time.sleep(0.02)
    yield f"http://127.0.0.1:{port}", run_id, db
    server.should_exit = True
    thread.join(10)
    sock.close()


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), headless=True)
        yield b
        b.close()


@pytest.fixture(scope="module")
def api(server):
    with httpx.Client(base_url=server[0], headers=AUTH, timeout=60) as c:
        yield c


class Page:
    """A page in a fresh context at one viewport, with every console error and uncaught
    exception collected."""

    def __init__(self, browser, url: str, size: str, init_script: str | None = None,
                 csp: bool = False):
        self.size = size
        # the pages' policy refuses eval, which Playwright's string waits use: the tests
        # pass it by, except those that check the pages under it (csp=True)
        self.context = browser.new_context(viewport=SIZES[size], accept_downloads=True,
                                           bypass_csp=not csp)
        # a page's waits get 60 s, not Playwright's 30: a job the page follows (a day
        # flown by the server's workers) took longer on a machine loaded by other runs
        self.context.set_default_timeout(WAIT)
        self.page = self.context.new_page()
        if init_script:
            self.page.add_init_script(init_script)
        self.errors: list[str] = []
        self.closed = False
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.goto(url)

    def done(self, name: str) -> None:
        """Check the page: no console error, nothing wider than the viewport; photograph it."""
        p = self.page
        assert not self.errors, self.errors
        wide = p.evaluate("document.documentElement.scrollWidth - window.innerWidth")
        assert wide <= 0, f"{name} at {self.size} is {wide}px wider than the viewport"
        SHOTS.mkdir(parents=True, exist_ok=True)
        p.screenshot(path=str(SHOTS / f"{name}-{self.size}.png"), full_page=True)
        self.close()

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self.context.close()


@pytest.fixture
def open_page(browser, server):
    pages = []

    def make(path: str, size: str, init_script: str | None = None, csp: bool = False
             ) -> Page:
        pages.append(Page(browser, server[0] + path, size, init_script, csp))
        return pages[-1]

    yield make
    for pg in pages:
        pg.close()


def set_slider(page, selector: str, value: float) -> None:
    page.eval_on_selector(
        selector, "(e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }", value)


def click_canvas(page, fx: float, fy: float) -> None:
    """A click at a share (fx, fy) of the map canvas, on whole pixels."""
    canvas = page.locator("#map")
    canvas.scroll_into_view_if_needed()
    box = canvas.bounding_box()
    page.mouse.click(round(box["x"] + fx * box["width"]), round(box["y"] + fy * box["height"]))


def click_cell(page, width: int, x: float, y: float) -> None:
    """A click on the planner's canvas at cell (x, y) of a map ``width`` cells wide (x + 0.5
    is a cell's middle), on whole pixels: the cells are square and fill the canvas's
    width from its top left corner; the key strip under them is no share of the map."""
    canvas = page.locator("#map")
    canvas.scroll_into_view_if_needed()
    box = canvas.bounding_box()
    px = box["width"] / width
    page.mouse.click(round(box["x"] + x * px), round(box["y"] + y * px))


@pytest.mark.parametrize("size", VIEWPORTS)
def test_home_page_links_every_page(open_page, size):
    pg = open_page("/", size)
    links = pg.page.locator("nav a").evaluate_all("a => a.map(x => x.getAttribute('href'))")
    # relative: the same pages under a proxy's path (serve --root-path)
    assert links == ["day.html", "planner.html", "world.html", "fleet.html", "docs"]
    urls = pg.page.locator("nav a").evaluate_all("a => a.map(x => x.href)")
    root = pg.page.url.rstrip("/")
    assert urls == [f"{root}/{x}" for x in links]
    # the endpoints table fits (at 360 px its answers were cut at the edge, to be scrolled to)
    assert pg.page.evaluate("(t => t.scrollWidth - t.clientWidth)"
                            "(document.querySelector('.table-wrap'))") <= 0
    pg.done("home")


@pytest.mark.parametrize("size", VIEWPORTS)
def test_day_animates_to_its_end(open_page, api, size):
    report = api.get(f"/days/{DAY}").json()["report"]
    pg = open_page(f"/day.html#date={DAY}", size)
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0")
    assert p.input_value("#date") == DAY
    assert p.locator("#orders tbody tr").count() == report["orders_placed"]
    p.select_option("#speed", "1000")
    p.click("#play")
    p.wait_for_function("(t => t.value === t.max)(document.querySelector('#time'))"
                        " && document.querySelector('#play').textContent === 'Play'",
                        timeout=WAIT)
    moves = report["moves"]
    assert p.inner_text("#time-text") == f"move {moves} of {moves}"
    assert p.inner_text("#s-pct") == f"{report['money_pct']:.1f} %"
    assert p.inner_text("#s-orders") == f"{report['orders_delivered']} of {report['orders_placed']}"
    assert p.locator("#orders tbody tr.done").count() == report["orders_delivered"]
    assert "is over" in p.inner_text("#status")
    # two places of this day get 10 of their 12 orders: ringed, and said at the end
    # (one dot a place: a served and an unserved order there drew over each other)
    assert "2 customer places partly served" in p.inner_text("#status")
    assert "partly served" in p.inner_text(".legend")
    if size == "phone":  # the picture halfway through
        set_slider(p, "#time", moves // 2)
        assert p.inner_text("#time-text") == f"move {moves // 2} of {moves}"
    pg.done("day")


def _free_cells(rows: list[str], passable: str) -> list[tuple[int, int]]:
    """Cells whose 5x5 neighbourhood is passable (a click a pixel off still lands on one)."""
    h, w = len(rows), len(rows[0])
    ok = [[c in passable for c in row] for row in rows]
    return [(x, y) for y in range(2, h - 2) for x in range(2, w - 2)
            if all(ok[y + j][x + i] for i in range(-2, 3) for j in range(-2, 3))]


@pytest.mark.parametrize("size", VIEWPORTS)
def test_planner_click_pair_matches_post_plan(open_page, api, size):
    doc = api.get("/maps/den312d").json()
    free = _free_cells(doc["rows"], doc["passable"])
    start, goal = min(free, key=lambda c: c[0] + c[1]), max(free, key=lambda c: c[0] + c[1])
    api.post("/plan", json={"map": "den312d", "start": start, "goal": goal})  # compiled, warm
    pg = open_page("/planner.html", size)
    p = pg.page
    p.wait_for_function("document.querySelector('#map-name').options.length > 1")
    p.fill("#token", TOKEN)
    p.select_option("#map-name", "den312d")
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('den312d')")
    blank = p.evaluate("document.querySelector('#map').toDataURL()")
    for x, y in (start, goal):
        click_cell(p, doc["width"], x + 0.5, y + 0.5)
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'"
                        " && document.querySelector('#status').textContent.startsWith('Planned')",
                        timeout=WAIT)
    cells = [int(p.input_value(f"#{k}")) for k in ("sx", "sy", "gx", "gy")]
    assert max(abs(a - b) for a, b in zip(cells, [*start, *goal], strict=True)) <= 1, cells
    rows = p.locator("#results tbody tr")
    algorithms = rows.evaluate_all("r => r.map(x => x.dataset.algorithm)")
    assert algorithms == ["astar", "jps", "theta"]
    for k, name in enumerate(algorithms):
        want = api.post("/plan", json={"map": "den312d", "start": cells[:2], "goal": cells[2:],
                                       "algorithm": name, "corner_cutting": False}).json()
        row = rows.nth(k)
        assert want["status"] == "found"
        assert float(row.get_attribute("data-cost")) == want["cost"], name
        assert int(row.get_attribute("data-expanded")) == want["expanded"], name
    assert p.evaluate("document.querySelector('#map').toDataURL()") != blank  # paths drawn
    pg.done("planner")


def test_planner_without_a_token_says_so(open_page):
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'")
    p.fill("#token", "")
    p.fill("#sx", "1")
    p.fill("#sy", "1")
    p.fill("#gx", "2")
    p.fill("#gy", "2")
    p.click("#run")
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'")
    assert "needs the server's token" in p.inner_text("#status")
    assert p.evaluate("document.activeElement.id") == "token"
    p.fill("#token", "wrong")
    p.click("#run")
    p.wait_for_function("document.querySelector('#status').textContent.includes('403')")
    assert all("401" in e or "403" in e for e in pg.errors), pg.errors  # the refused requests


@pytest.mark.parametrize("size", VIEWPORTS)
def test_world_draws_a_path_and_offers_waypoints(open_page, api, size):
    pg = open_page("/world.html", size)
    p = pg.page
    p.wait_for_function("document.querySelector('#algorithm').options.length > 0")
    p.fill("#token", TOKEN)
    p.set_input_files("#file", str(ROOT / "examples" / "city.csv"))
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('city.csv')")
    blank = p.evaluate("document.querySelector('#map').toDataURL()")
    click_canvas(p, 0.05, 0.05)
    click_canvas(p, 0.95, 0.95)
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('Found')",
                        timeout=WAIT)
    start = [float(p.input_value("#s0")), float(p.input_value("#s1"))]
    goal = [float(p.input_value("#g0")), float(p.input_value("#g1"))]
    want = api.post("/plan", json={"world_text": (ROOT / "examples" / "city.csv").read_text(),
                                   "world_format": "colliders", "frame": "ned", "start": start,
                                   "goal": goal, "algorithm": "visibility", "altitude": 5,
                                   "safety": 5}).json()
    assert p.inner_text("#r-cost") == f"{want['cost']:,.2f} m"
    assert p.locator("#waypoints tbody tr").count() == len(want["waypoints"])
    assert p.evaluate("document.querySelector('#map').toDataURL()") != blank
    with p.expect_download() as download:
        p.click("#dl-waypoints")
    got = json.loads(Path(download.value.path()).read_text())
    assert got == want["waypoints"]
    pg.done("world")


@pytest.mark.parametrize("size", VIEWPORTS)
def test_fleet_replay_moves_drones_with_the_slider(open_page, server, size):
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree (jobs branch not merged): no fleet run")
    pg = open_page(f"/fleet.html#run={server[1]}", size)
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
    assert p.input_value("#run") == server[1]
    assert p.locator("#drones tbody tr").count() == 3

    def drones() -> list[str]:
        return p.locator("#drones tbody tr").evaluate_all("r => r.map(x => x.innerText)")

    set_slider(p, "#time", 100)
    before, picture = drones(), p.evaluate("document.querySelector('#map').toDataURL()")
    set_slider(p, "#time", 400)
    after = drones()
    assert after != before and any("cruise" in d or "climb" in d for d in after), after
    assert p.evaluate("document.querySelector('#map').toDataURL()") != picture
    assert p.locator("#packages tbody tr").count() > 0
    assert "delivered" in p.inner_text("#packages-caption")
    p.click("#play")
    p.wait_for_function("Number(document.querySelector('#time').value) > 400")
    p.click("#play")  # pause for the picture
    pg.done("fleet")


# -- defects found by using the pages (each test failed before its fix) -----------------

def _wait_status(page, kind: str, timeout: int = 30_000) -> str:
    page.wait_for_function(f"document.querySelector('#status').dataset.kind === '{kind}'"
                           " && !document.querySelector('#run').ariaDisabled", timeout=timeout)
    return page.inner_text("#status")


def _open_map(pg, name: str) -> None:
    p = pg.page
    p.wait_for_function("document.querySelector('#map-name').options.length > 1")
    p.fill("#token", TOKEN)
    p.select_option("#map-name", name)
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{name}')")


def _type_cells(p, start, goal) -> None:
    for key, value in zip(("sx", "sy", "gx", "gy"), (*start, *goal), strict=True):
        p.fill(f"#{key}", str(value))


@pytest.mark.parametrize("path, ready", [
    ("/", "nav a"),
    (f"/day.html#date={DAY}", "#orders tbody tr"),
    ("/world.html", "#algorithm option"),
    ("/fleet.html", "#drones tbody tr"),
])
def test_the_pages_load_under_their_csp(open_page, path, ready):
    """The server's Content-Security-Policy enforced (the other tests pass it by): each
    page fills itself from the API without a refusal (Chromium logs each as a console
    error, which ``done`` checks)."""
    pg = open_page(path, "desktop", csp=True)
    pg.page.locator(ready).first.wait_for(state="attached", timeout=WAIT)
    pg.done(f"csp-{path.strip('/').split('.')[0] or 'home'}")


def test_the_planner_plans_under_its_csp(open_page, api):
    """The planner under the policy: fetches the map, posts the query, draws the paths
    and its table's colour swatches (inline styles, which the policy allows)."""
    doc = api.get("/maps/den312d").json()
    free = _free_cells(doc["rows"], doc["passable"])
    pg = open_page("/planner.html", "desktop", csp=True)
    p = pg.page
    p.locator("#map-name option").nth(1).wait_for(state="attached")
    p.fill("#token", TOKEN)
    p.select_option("#map-name", "den312d")
    # the map drawn ("den312d: W x H cells..."), not "Loading den312d...": Plan pressed
    # before the map is in does nothing, and no result row ever came (a loaded CI)
    p.locator("#status", has_text="den312d: ").wait_for(timeout=WAIT)
    _type_cells(p, free[0], free[-1])
    p.click("#run")
    p.locator("#results tbody tr").nth(2).wait_for(timeout=WAIT)
    assert p.locator("#results tbody tr .swatch[style]").count() == 3
    pg.done("csp-planner")


def test_planner_says_a_bad_start_once(open_page, api):
    """A start on a wall is one sentence, not the same 422 once per algorithm."""
    doc = api.get("/maps/den312d").json()
    wall = next((x, y) for y, row in enumerate(doc["rows"]) for x, c in enumerate(row)
                if c not in doc["passable"])
    goal = _free_cells(doc["rows"], doc["passable"])[0]
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "den312d")
    _type_cells(p, wall, goal)
    p.press("#gy", "Enter")
    text = _wait_status(p, "error")
    want = f"Planning failed (422): start ({wall[0]}, {wall[1]}) is on a blocked cell."
    assert text == want, text
    assert p.locator("#results tbody tr").count() == 3  # each row still names its error
    assert all("422" in e for e in pg.errors), pg.errors


def test_planner_says_when_no_algorithm_finds_a_path(open_page, api):
    """An unreachable goal is not a green "Planned ...: 0 found a path"."""
    doc = api.get("/maps/Berlin_1_256").json()
    rows, passable = doc["rows"], doc["passable"]

    def blocked(x, y):
        return not (0 <= y < len(rows) and 0 <= x < len(rows[y])) or rows[y][x] not in passable

    island = next((x, y) for y, row in enumerate(rows) for x, c in enumerate(row)
                  if c in passable and all(blocked(x + i, y + j) for i, j in
                                           ((1, 0), (-1, 0), (0, 1), (0, -1))))
    start = _free_cells(rows, passable)[0]
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "Berlin_1_256")
    for name in ("jps", "theta"):
        p.uncheck(f"#algorithms input[value={name}]")
    _type_cells(p, start, island)
    p.click("#run")
    text = _wait_status(p, "error")
    assert text.endswith("with 1 algorithm: none found a path."), text
    assert p.locator("#results tbody tr").get_attribute("data-cost") == ""
    pg.done("planner-no-path")


def test_planner_typed_cells_drop_the_old_paths(open_page, api):
    """Typing a new cell clears the last query's paths and table (they were drawn from
    the old start, next to the new start's marker)."""
    doc = api.get("/maps/den312d").json()
    free = _free_cells(doc["rows"], doc["passable"])
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "den312d")
    _type_cells(p, free[0], free[-1])
    p.click("#run")
    _wait_status(p, "ok")
    assert p.locator("#results tbody tr").count() == 3
    planned = p.evaluate("document.querySelector('#map').toDataURL()")
    p.fill("#sx", str(free[1][0]))
    p.fill("#sy", str(free[1][1]))
    assert p.locator("#results tbody tr").count() == 0
    assert "Press Plan" in p.inner_text("#status")
    assert p.evaluate("document.querySelector('#map').toDataURL()") != planned
    pg.done("planner-typed")


def _load_city(pg) -> None:
    p = pg.page
    p.wait_for_function("document.querySelector('#algorithm').options.length > 0")
    p.fill("#token", TOKEN)
    p.set_input_files("#file", str(ROOT / "examples" / "city.csv"))
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('city.csv')")


def test_world_hides_the_cell_size_of_exact_planners(open_page):
    """The Cell size field (grid algorithms only) was shown for every algorithm: the
    style sheet's .field display beat the hidden attribute."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#algorithm').options.length > 0")
    assert p.input_value("#algorithm") == "visibility"
    assert not p.is_visible("#resolution")
    p.select_option("#algorithm", "astar")
    assert p.is_visible("#resolution")
    p.select_option("#algorithm", "prm")
    assert not p.is_visible("#resolution")
    pg.done("world-fields")


def test_world_error_leaves_no_old_path(open_page):
    """A new start, then a refused plan: the old path, length and waypoints go (they
    stayed, next to the new start's marker and the error)."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    _load_city(pg)
    click_canvas(p, 0.05, 0.05)
    click_canvas(p, 0.95, 0.95)
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('Found')",
                        timeout=WAIT)
    assert p.inner_text("#r-status") == "found"
    # the centre of the city's first box (north, east), inside it at any altitude
    first = (ROOT / "examples" / "city.csv").read_text().splitlines()[2].split(",")
    p.fill("#s0", first[0])
    p.fill("#s1", first[1])
    assert p.inner_text("#r-status") == "–"
    assert p.is_disabled("#dl-waypoints")
    p.click("#run")
    text = _wait_status(p, "error")
    assert "lies inside obstacle" in text, text
    assert p.inner_text("#r-cost") == "–"
    assert p.locator("#waypoints tbody tr").count() == 0
    assert all("422" in e for e in pg.errors), pg.errors


def test_world_widens_the_view_to_typed_points(open_page):
    """A start typed far outside the city is drawn after planning (the view kept the
    city's box and the start marker was off the canvas)."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    _load_city(pg)
    for key, value in (("s0", 3000), ("s1", 3000), ("g0", -172.5), ("g1", 270.5)):
        p.fill(f"#{key}", str(value))
    p.click("#run")
    assert _wait_status(p, "ok").startswith("Found")
    start_marker = p.evaluate("""() => {
        const c = document.querySelector('#map');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) {
          const near = (k, v) => Math.abs(d[i + k] - v) < 8;
          if (near(0, 27) && near(1, 122) && near(2, 61)) n++;
        }
        return n;
    }""")
    assert start_marker > 20, start_marker
    pg.done("world-far")


def test_day_without_a_flight_says_so(open_page):
    """A stored day without orders says there is nothing to play (it said "Press Play to
    fly it" beside a disabled Play button); the legend names the grey customers."""
    pg = open_page("/day.html#date=2024-02-01", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('2024-02-01')")
    text = p.inner_text("#status")
    assert "did not fly" in text and "Press Play" not in text, text
    assert p.is_disabled("#play")
    assert "customer not served" in p.inner_text(".legend")
    pg.done("day-empty")


@pytest.mark.parametrize("page", ["planner", "world"])
def test_plan_button_on_a_phone_shows_the_answer(open_page, page):
    """At 390 px the form fills the screen and the map and status line are under it:
    Plan (or a missing start) changed nothing in view. Now the status line comes up."""
    pg = open_page(f"/{page}.html", "phone")
    p = pg.page
    if page == "planner":
        _open_map(pg, "den312d")
        cells = (("sx", 50), ("sy", 76), ("gx", 60), ("gy", 13))
    else:
        _load_city(pg)
        cells = (("s0", 172), ("s1", -271), ("g0", -172), ("g1", 270))

    def status_in_view() -> bool:
        box = p.locator("#status").bounding_box()
        return box["y"] >= 0 and box["y"] + box["height"] <= p.viewport_size["height"] + 1

    p.evaluate("window.scrollTo(0, 0)")
    p.click("#run")  # no start yet
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'")
    assert "start and a goal" in p.inner_text("#status")
    assert status_in_view()
    for key, value in cells:
        p.fill(f"#{key}", str(value))
    p.evaluate("window.scrollTo(0, 0)")
    p.click("#run")
    _wait_status(p, "ok")
    assert status_in_view()
    pg.done(f"{page}-phone-plan")


def test_api_reference_renders_offline(browser, server):
    """/docs (the nav's "API") draws the operations with every request to another host
    refused, as on a server without internet."""
    context = browser.new_context(viewport=VIEWPORTS["desktop"])
    outside: list[str] = []

    def route(r):
        if r.request.url.startswith(server[0]):
            r.continue_()
        else:
            outside.append(r.request.url)
            r.abort()

    context.route("**/*", route)
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    try:
        page.goto(server[0] + "/docs")
        page.wait_for_selector(".opblock", timeout=WAIT)
        paths = page.locator(".opblock-summary-path").all_inner_texts()
        assert any("/plan" in p for p in paths), paths
        assert not outside and not errors, (outside, errors)
    finally:
        context.close()


def server_has_no_jobs() -> bool:
    try:
        import skyroute.jobs  # noqa: F401
    except ImportError:
        return True
    return False


def _job_routes(p, job: dict, kind: str = "fleet", posts: list | None = None) -> None:
    """POST /jobs/{kind} answers job "job-1" (each request appended to ``posts``); GET
    /jobs/job-1 answers ``job`` as it is at each poll (state "unreachable": no answer at
    all), so a test sets what the server says while the page follows it."""
    def post(r):
        if posts is not None:
            posts.append(r.request.post_data_json)
        r.fulfill(status=202, json={"id": "job-1"})

    p.route(f"**/jobs/{kind}", post)

    def poll(r):
        if job["state"] == "unreachable":
            r.abort()
            return
        doc = {"id": "job-1", "kind": kind, "result": None, "error": None, **job}
        if doc["error"] and r.request.headers.get("authorization") != f"Bearer {TOKEN}":
            doc["error"] = HIDDEN_ERROR  # as the server: the error in full with the token
        r.fulfill(json=doc)

    p.route("**/jobs/job-1", poll)


HIDDEN_ERROR = ("the job failed; its error is shown with the server's token "
                "(Authorization: Bearer TOKEN)")


def _start_fleet_job(open_page, server, job: dict):
    """The stored run's fleet page with its job requests answered from ``job`` (which
    the test changes as it goes), a run started with the token; the page."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    pg = open_page(f"/fleet.html#run={server[1]}", "desktop")
    p = pg.page
    _job_routes(p, job)
    p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
    p.fill("#token", TOKEN)
    p.click("#start")
    return pg


def test_fleet_job_shows_it_runs_and_survives_a_reload(open_page, server):
    """A fleet run is one task: its job says progress 0 until it ends. The page showed
    "Job running: 0 %" on an empty bar for the whole run, and a reload forgot the job (no
    word of it, Start enabled). Now the bar moves (indeterminate) with the time taken,
    and a reload goes on following the job to its run."""
    job = {"state": "running", "progress": 0.0}
    pg = _start_fleet_job(open_page, server, job)
    p = pg.page
    p.wait_for_function("document.querySelector('#job-status').textContent.includes('so far')")
    assert "0 %" not in p.inner_text("#job-status")
    assert p.evaluate("document.querySelector('#progress').hasAttribute('value')") is False
    assert p.is_disabled("#start")
    p.reload()
    p.wait_for_function("document.querySelector('#job-status').textContent"
                        ".startsWith('Job running')", timeout=WAIT)
    assert p.is_disabled("#start")
    job.update(state="running", progress=0.4)
    p.wait_for_function("document.querySelector('#job-status').textContent"
                        ".startsWith('Job running: 40 %')")
    assert p.evaluate("document.querySelector('#progress').value") == pytest.approx(0.4)
    job.update(state="done", progress=1.0, result={"fleet_run": server[1]})
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'ok'"
                        " && !document.querySelector('#start').ariaDisabled", timeout=WAIT)
    assert p.inner_text("#job-status") == "The run is done and stored."
    p.reload()  # the job is over: nothing to follow after another reload
    p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
    assert p.inner_text("#job-status") == "" and not p.is_disabled("#start")
    pg.done("fleet-job")


def test_a_failed_job_shows_its_error_read_with_the_token(open_page, server):
    """GET /jobs/{id} shows a failed job's error in full only with the token (it may
    name the server's files); the page polls with the token it submitted the job with,
    so it says why the job failed, not only that it did."""
    job = {"state": "running", "progress": 0.0}
    pg = _start_fleet_job(open_page, server, job)
    p = pg.page
    p.wait_for_function("document.querySelector('#job-status').textContent"
                        ".startsWith('Job running')")
    job.update(state="failed", error="scenario.airports: too few (see the docs)")
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'error'",
                        timeout=WAIT)
    assert p.inner_text("#job-status").startswith(
        "The job failed: scenario.airports: too few (see the docs)"), \
        p.inner_text("#job-status")
    assert not pg.errors, pg.errors


def test_fleet_job_outlives_a_server_that_does_not_answer(open_page, server):
    """One unanswered poll (a server restarting, a network blip) ended the following for
    good: the job's run never showed. Now the page says so and asks again."""
    job = {"state": "unreachable", "progress": 0.0}
    pg = _start_fleet_job(open_page, server, job)
    p = pg.page
    p.wait_for_function("document.querySelector('#job-status').textContent"
                        ".includes('Asking again')")
    assert "did not answer" in p.inner_text("#job-status")
    assert p.is_disabled("#start")
    job.update(state="done", progress=1.0, result={"fleet_run": server[1]})
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'ok'"
                        " && !document.querySelector('#start').ariaDisabled", timeout=WAIT)


@contextlib.contextmanager
def _copied_run(server, **changes):
    """A second fleet run in the store, the module's run stored again (same settings,
    but for ``changes``); its id. Deleted at the end."""
    import sqlalchemy as sa

    from skyroute.jobs import store

    eng = sa.create_engine(server[2])
    run = store.get_fleet_run(eng, server[1])
    copy = store.save_fleet_run(eng, **{k: run[k] for k in (
        "scenario", "params", "report", "events_jsonl", "tracks_csv", "packages_csv",
        "fleet_geojson")} | changes)
    try:
        yield copy
    finally:
        with eng.begin() as c:
            c.execute(sa.text("DELETE FROM fleet_runs WHERE id = :id"), {"id": copy})
        eng.dispose()


def test_a_run_stored_without_packages_csv_opens_without_a_console_error(open_page, server):
    """A run stored without packages.csv (its ``files`` do not name it: a run stored
    before it was kept) opened with a 404 for it, which the browser logs as a console
    error; the page now asks for it only where the run has it, and learns the packages'
    routes from the landing events."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    with _copied_run(server, packages_csv="") as copy:
        assert "packages.csv" not in httpx.get(f"{server[0]}/fleet/runs/{copy}").json()["files"]
        pg = open_page(f"/fleet.html#run={copy}", "desktop")
        p = pg.page
        p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
        assert p.input_value("#run") == copy
        set_slider(p, "#time", p.eval_on_selector("#time", "e => e.max"))
        p.wait_for_function("document.querySelector('#packages tbody tr')")
        assert "delivered" in p.inner_text("#packages-caption")
        pg.done("fleet-run-without-packages")


def test_fleet_runs_of_the_same_settings_are_told_apart(open_page, server):
    """Runs of one preset, hours and seed were the same line in the run list (31 of them
    could not be told apart); each line now starts with when the run was stored (to the
    minute, or the second where two share a minute; whole in its tooltip)."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    with _copied_run(server) as copy:
        pg = open_page("/fleet.html", "desktop")
        p = pg.page
        p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
        labels = p.locator("#run option").all_inner_texts()
        assert len(labels) == 2 and labels[0] != labels[1], labels
        assert p.input_value("#run") == copy  # the newest first
        when = r"\d\d? [A-Z][a-z]{2}( \d{4})? \d\d:\d\d(:\d\d)? · seed-3x3"
        assert all(re.match(when, x) for x in labels), labels
        titles = p.eval_on_selector_all("#run option", "os => os.map((o) => o.title)")
        when = r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d · seed-3x3"
        assert all(re.match(when, x) for x in titles), titles
        pg.done("fleet-runs")


@contextlib.contextmanager
def _newer_runs(server, n: int):
    """``n`` runs stored after the module's run, which becomes the oldest, on the second
    page of GET /fleet/runs (pages of 100): ``n - 1`` without files (never opened) and,
    newest, a copy of the module's run (the page opens the newest). Their ids, newest
    first; deleted at the end."""
    import sqlalchemy as sa

    from skyroute.jobs import store

    eng = sa.create_engine(server[2])
    ids = []
    try:
        for i in range(n - 1):
            ids.append(store.save_fleet_run(
                eng, scenario="seed-3x3", params={"hours": 0.25, "seed": 100 + i},
                report={}, events_jsonl="", tracks_csv=b"", packages_csv="",
                fleet_geojson="{}"))
        run = store.get_fleet_run(eng, server[1])
        ids.append(store.save_fleet_run(eng, **{k: run[k] for k in (
            "scenario", "params", "report", "events_jsonl", "tracks_csv", "packages_csv",
            "fleet_geojson")}))
        yield ids[::-1]
    finally:
        with eng.begin() as c:
            for table, key in (("fleet_run_files", "run_id"), ("fleet_runs", "id")):
                c.execute(sa.text(f"DELETE FROM {table} WHERE {key} IN "
                                  f"({', '.join(map(repr, ids))})"))
        eng.dispose()


def _options(p) -> list[str]:
    return p.eval_on_selector_all("#run option", "os => os.map((o) => o.value)")


@pytest.mark.parametrize("size", ["desktop-720", "phone-640"])
def test_the_fleet_page_lists_runs_past_the_first_page(open_page, server, size):
    """GET /fleet/runs answers a page of 100 runs (a Link to the next); the page listed
    the first page alone, so the 101st run could not be chosen. "List older runs" (a
    button, by keyboard too) appends the next page until the last, and a link to a run
    older than the first page opens it."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    oldest = server[1]
    with _newer_runs(server, 100) as newer:
        pg = open_page("/fleet.html", size)
        p = pg.page
        p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
        assert _options(p) == newer and p.input_value("#run") == newer[0]
        assert p.is_visible("#more-runs")
        assert p.inner_text("#run-count") == \
            "The newest 100 runs are listed; older ones follow."
        p.focus("#run")  # the keyboard: Tab from the list to the button, Enter
        p.keyboard.press("Tab")
        assert p.evaluate("document.activeElement.id") == "more-runs"
        SHOTS.mkdir(parents=True, exist_ok=True)  # the button, focused
        p.screenshot(path=str(SHOTS / f"fleet-more-runs-{size}.png"), full_page=True)
        p.keyboard.press("Enter")
        p.wait_for_function("document.querySelectorAll('#run option').length === 101")
        assert _options(p) == [*newer, oldest]
        assert p.is_hidden("#more-runs")  # the last page: the focus moved to the list
        assert p.evaluate("document.activeElement.id") == "run"
        assert p.inner_text("#run-count") == \
            "All 101 stored runs are listed, newest first."
        p.keyboard.press("End")  # the oldest, chosen from the list by keyboard
        p.wait_for_function(f"location.hash === '#run={oldest}'"
                            " && document.querySelector('#status').dataset.kind === 'ok'",
                            timeout=WAIT)
        assert p.input_value("#run") == oldest
        pg.done("fleet-older-runs")

        # a link to the 101st run (the address the page shows for it): opened, listed
        # last until its page is listed, then in its place, once
        pg = open_page(f"/fleet.html#run={oldest}", size)
        p = pg.page
        p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'"
                            " && document.querySelector('#time').max > 0", timeout=WAIT)
        assert p.input_value("#run") == oldest and "not stored" not in p.inner_text("#status")
        assert _options(p) == [*newer, oldest] and p.is_visible("#more-runs")
        p.click("#more-runs")
        p.wait_for_function("document.querySelector('#more-runs').hidden")
        assert _options(p) == [*newer, oldest] and p.input_value("#run") == oldest
        pg.done("fleet-older-runs-link")


@pytest.mark.parametrize("page", ["day", "fleet", "planner"])
def test_the_last_choice_is_shown_when_an_earlier_one_answers_late(open_page, server, page):
    """A day, run or map chosen, then another before the first had arrived (a large run
    takes seconds): the first, arriving last, was shown under the second's name in the
    list. Now only the last choice is drawn."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    with contextlib.ExitStack() as stack:
        if page == "day":
            first, last, held_url = DAY, "2024-02-01", f"**/days/{DAY}/flightpath.geojson"
        elif page == "planner":
            first, last, held_url = "Paris_1_512", "den312d", "**/maps/Paris_1_512"
        else:
            first, last = stack.enter_context(_copied_run(server)), server[1]
            held_url = f"**/fleet/runs/{first}/tracks.csv"
        key = {"day": "date", "fleet": "run", "planner": "map-name"}[page]
        if page == "planner":  # no address of its own: the map is chosen first
            pg = open_page("/planner.html", "desktop")
            _open_map(pg, last)
        else:
            pg = open_page(f"/{page}.html#{key}={last}", "desktop")
        p = pg.page
        p.wait_for_function("document.querySelector('#status').dataset.kind !== 'busy'"
                            " && document.querySelector('#status').textContent", timeout=WAIT)
        held = []
        p.route(held_url, lambda r: held.append(r))  # the first choice's answer waits
        p.select_option(f"#{key}", first)
        for _ in range(200):  # the page asks for it
            if held:
                break
            p.wait_for_timeout(50)
        assert held and p.evaluate("document.querySelector('#status').dataset.kind") == "busy"
        p.select_option(f"#{key}", last)
        p.wait_for_function(f"(location.hash === '#{key}={last}'"
                            f" || document.querySelector('#status').textContent.includes('{last}'))"
                            " && document.querySelector('#status').dataset.kind !== 'busy'")
        shown = p.inner_text("#status"), p.evaluate("location.hash")
        held[0].continue_()  # now the first choice arrives, last
        p.wait_for_timeout(1500)
        assert p.input_value(f"#{key}") == last
        assert (p.inner_text("#status"), p.evaluate("location.hash")) == shown
        assert not pg.errors, pg.errors


@pytest.mark.parametrize(("path", "named"), [("/day.html#date=2099-01-01", "2099-01-01"),
                                             ("/fleet.html#run=no-such-run", "no-such-run")])
def test_a_link_to_what_is_not_stored_says_so(open_page, server, path, named):
    """A link (an old bookmark) to a day or run the store does not hold showed another
    day or run without a word; the status line now says the link's one is not stored."""
    if "fleet" in path and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    pg = open_page(path, "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
    text = p.inner_text("#status")
    assert f"The link names {'run ' if 'fleet' in path else ''}{named}, which is not" in text, text
    assert "Press Play" in text, text
    assert _key_inked(p) > 0  # a map drawn: its scale bar and north arrow
    pg.done("link-not-stored")


def test_a_mistyped_page_says_so_and_links_home(browser, server):
    """A mistyped page showed the 404 problem document as raw JSON text."""
    context = browser.new_context(viewport=VIEWPORTS["phone"])
    try:
        page = context.new_page()
        answer = page.goto(server[0] + "/planer.html")
        assert answer.status == 404
        assert page.inner_text("h1") == "Page not found"
        assert "/planer.html does not exist" in page.inner_text("main")
        wide = page.evaluate("document.documentElement.scrollWidth - window.innerWidth")
        assert wide <= 0
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / "not-found-phone.png"), full_page=True)
        page.click("text=Go to the skyroute start page")
        page.wait_for_url(server[0] + "/")
        assert page.locator("a[href='planner.html']").count() >= 1
    finally:
        context.close()


def test_world_plans_with_the_safety_typed(open_page):
    """A negative safety margin was planned with 0 and answered "Found a path" (the page
    replaced it); it goes to the server as typed, which refuses it naming the field."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    _load_city(pg)
    for key, value in (("s0", 172), ("s1", -271), ("g0", -172), ("g1", 270), ("safety", -3)):
        p.fill(f"#{key}", str(value))
    p.click("#run")
    text = _wait_status(p, "error")
    assert text == "Planning failed (422): safety: Input should be greater than or equal to 0", text
    assert p.inner_text("#r-status") == "–"
    assert p.evaluate("document.activeElement.id") == "safety"  # the field at fault


def test_planner_new_map_drops_the_old_maps_query(open_page, api):
    """A query under way when another map was chosen ended on the new map as "Planned
    (5, 5) -> (60, 70) with 0 algorithm: none found a path." in red, and Plan stayed
    disabled until it did. The new map's answer is the old query's end now."""
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "Berlin_1_256")
    held = []
    p.route("**/plan", lambda r: held.append(r))
    _type_cells(p, (5, 5), (60, 70))
    p.click("#run")
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'busy'")
    p.select_option("#map-name", "den312d")
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('den312d')")
    assert not p.is_disabled("#run")
    assert held
    p.unroute("**/plan")  # (lets the held request go on)
    p.wait_for_timeout(2000)  # the old query's answers arrive
    assert p.inner_text("#status").startswith("den312d: 65 × 81 cells"), p.inner_text("#status")
    assert p.locator("#results tbody tr").count() == 0
    assert not p.is_disabled("#run")


def test_world_new_file_drops_the_old_worlds_plan(open_page):
    """A plan under way when another world was loaded drew its path (and length and
    waypoints) over the new world, whose start and goal were cleared. And a pasted world
    left the file control naming the file chosen before."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    _load_city(pg)
    held = []
    p.route("**/plan", lambda r: held.append(r))
    for key, value in (("s0", 172), ("s1", -271), ("g0", -172), ("g1", 270)):
        p.fill(f"#{key}", str(value))
    p.click("#run")
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'busy'")
    zones = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
             "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [0.001, 0], [0.001, 0.001],
                                                              [0, 0]]]}}]}
    p.fill("#text", json.dumps(zones))
    p.dispatch_event("#text", "change")
    p.wait_for_function("document.querySelector('#status').textContent"
                        ".startsWith('the pasted text')")
    # the file control no longer names city.csv, the world it no longer shows
    assert p.evaluate("document.querySelector('#file').files.length") == 0
    assert not p.is_disabled("#run")
    assert held
    p.unroute("**/plan")  # (lets the held request go on)
    p.wait_for_timeout(2000)  # the old plan's answer arrives
    text = p.inner_text("#status")
    assert text.startswith("the pasted text: 1 obstacles"), text
    assert p.inner_text("#r-cost") == "–"
    assert p.locator("#waypoints tbody tr").count() == 0


def test_day_page_flies_a_day_as_a_job(open_page, api):
    """The day page could only show days flown elsewhere (the CLI, or POST /jobs/deliver
    by hand); it now flies a stored orders' day as a job, follows it and shows it."""
    if server_has_no_jobs():
        pytest.skip("skyroute.jobs is not in this tree: no jobs")
    date = "2024-01-01"  # orders imported with the lunch day, not flown
    pg = open_page(f"/day.html#date={DAY}", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0")
    p.click("#start")
    assert p.inner_text("#job-status") == "Give the date to fly first."
    assert p.evaluate("document.activeElement.id") == "job-date"
    p.fill("#job-date", date)
    p.select_option("#method", "greedy")
    p.fill("#token", TOKEN)
    p.click("#start")
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'ok'"
                        " && !document.querySelector('#start').ariaDisabled", timeout=120_000)
    assert p.inner_text("#job-status") == "The day is flown and stored."
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{date}:')")
    report = api.get(f"/days/{date}").json()["report"]
    assert report["settings"]["method"] == "greedy"
    assert p.input_value("#date") == date and p.evaluate("location.hash") == f"#date={date}"
    assert p.locator("#orders tbody tr").count() == report["orders_placed"]
    assert p.evaluate("document.querySelector('#progress').value") == 1
    pg.done("day-job")


@pytest.mark.parametrize(("field", "value", "said"), [
    ("hours", "-1", "hours: Input should be greater than 0"),
    ("hours", "", "hours: Input should be greater than 0"),
    ("seed", "1.5", "seed: Input should be a valid integer"),
])
def test_fleet_form_focuses_the_field_the_server_refuses(open_page, field, value, said):
    """A refused field was said in the status line while the focus stayed on Start: the
    field is now focused (as the Token field is for a 401), so a keyboard or screen
    reader user is at what to fix."""
    pg = open_page("/fleet.html", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#preset').options.length > 0")
    p.fill("#token", TOKEN)
    p.fill(f"#{field}", value)
    p.click("#start")
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'error'")
    assert said in p.inner_text("#job-status")
    assert p.evaluate("document.activeElement.id") == field


@pytest.mark.parametrize(("field", "value", "said"), [
    ("weight", "0.5", "weight: Input should be greater than or equal to 1"),
    ("sx", "9999", "start (9999, 2) lies outside"),
])
def test_planner_focuses_the_field_the_server_refuses(open_page, field, value, said):
    """As on the fleet form: the refused field gets the focus, not the lost button's."""
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "den312d")
    _type_cells(p, (2, 2), (3, 3))
    p.fill(f"#{field}", value)
    p.click("#run")
    assert said in _wait_status(p, "error")
    assert p.evaluate("document.activeElement.id") == field


@pytest.mark.parametrize("page", ["planner", "world", "day", "fleet"])
def test_a_pressed_button_keeps_the_focus(open_page, server, page):
    """Plan, Fly it and Start run were disabled while their request ran: a disabled
    button loses the focus, which dropped to the page's body, so a keyboard user's next
    Tab started again from the top of the page. The button keeps the focus now (it is
    aria-disabled while busy and refuses a second press), during the request and after
    its answer."""
    if page in ("day", "fleet") and server_has_no_jobs():
        pytest.skip("skyroute.jobs is not in this tree: no jobs")
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    sent, held = [], []
    if page in ("planner", "world"):
        pg = open_page(f"/{page}.html", "desktop")
        p = pg.page
        if page == "planner":
            _open_map(pg, "den312d")
            _type_cells(p, (50, 76), (60, 13))
        else:
            _load_city(pg)
            for key, value in (("s0", 172), ("s1", -271), ("g0", -172), ("g1", 270)):
                p.fill(f"#{key}", str(value))

        def hold_first(r):  # the first plan waits until the test lets it go
            sent.append(r.request.post_data_json)
            if len(sent) == 1:
                held.append(r)
            else:
                r.continue_()

        p.route("**/plan", hold_first)
        button = "run"
    else:
        job = {"state": "running", "progress": 0.0}
        pg = open_page(f"/day.html#date={DAY}" if page == "day" else f"/fleet.html#run={server[1]}",
                       "desktop")
        p = pg.page
        _job_routes(p, job, "deliver" if page == "day" else "fleet", posts=sent)
        p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
        p.fill("#token", TOKEN)
        if page == "day":
            p.fill("#job-date", DAY)
        button = "start"
    p.focus(f"#{button}")
    p.keyboard.press("Enter")
    if page in ("planner", "world"):
        p.wait_for_function("document.querySelector('#status').dataset.kind === 'busy'")
    else:
        p.wait_for_function("document.querySelector('#job-status').textContent"
                            ".startsWith('Job running')")
    assert p.evaluate("document.activeElement.id") == button  # while busy
    assert p.get_attribute(f"#{button}", "aria-disabled") == "true"
    p.keyboard.press("Enter")  # a second press while busy sends nothing
    p.wait_for_timeout(300)
    assert len(sent) == 1, sent
    if page in ("planner", "world"):
        held[0].continue_()
        _wait_status(p, "ok")
    else:
        job.update(state="done", progress=1.0,
                   result={"from": DAY, "to": DAY} if page == "day" else {"fleet_run": server[1]})
        p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'ok'"
                            " && !document.querySelector('#start').ariaDisabled", timeout=WAIT)
    assert p.evaluate("document.activeElement.id") == button  # after the answer
    assert not pg.errors, pg.errors


# Records what the map canvas draws, in CSS pixels: the bounding box of each top-level
# save()..restore() block with its texts (the north arrow is the block saying "N", the
# scale bar the one saying "... m"), each small mark drawn outside such blocks (a
# filled or stroked path, or a filled rectangle, at most 24 px across: customer dots and
# rings, shops, home, the drone; the planner's start and goal) and each image drawn (the
# planner's grid of cells). Each render starts with a clearRect of the whole canvas.
CANVAS_LOG = """
(() => {
  const P = CanvasRenderingContext2D.prototype;
  const log = { blocks: [], marks: [], images: [] };
  window.canvasLog = log;
  let depth = 0, block = null, path = null;
  const mine = (ctx) => ctx.canvas.id === "map";
  const at = (ctx, x, y) => {
    const m = ctx.getTransform(), d = window.devicePixelRatio || 1;
    return [(m.a * x + m.c * y + m.e) / d, (m.b * x + m.d * y + m.f) / d];
  };
  const grow = (box, [x, y]) => {
    box[0] = Math.min(box[0], x); box[1] = Math.min(box[1], y);
    box[2] = Math.max(box[2], x); box[3] = Math.max(box[3], y);
  };
  const empty = () => [Infinity, Infinity, -Infinity, -Infinity];
  const touch = (ctx, pts) => {
    for (const p of pts) {
      const q = at(ctx, p[0], p[1]);
      if (block) grow(block.box, q);
      else if (path) grow(path, q);
    }
  };
  const small = (b) => b[2] - b[0] <= 24 && b[3] - b[1] <= 24 && b[0] <= b[2];
  const wrap = (name, before) => {
    const f = P[name];
    P[name] = function (...a) { if (mine(this)) before(this, ...a); return f.apply(this, a); };
  };
  wrap("clearRect", (ctx, x, y, w, h) => {
    if (x === 0 && y === 0 && w * (window.devicePixelRatio || 1) >= ctx.canvas.width - 1) {
      log.blocks = []; log.marks = []; log.images = [];
    }
  });
  wrap("save", () => { if (depth++ === 0) block = { box: empty(), texts: [] }; });
  wrap("restore", () => { if (--depth === 0 && block) { log.blocks.push(block); block = null; } });
  wrap("beginPath", () => { path = empty(); });
  wrap("moveTo", (ctx, x, y) => touch(ctx, [[x, y]]));
  wrap("lineTo", (ctx, x, y) => touch(ctx, [[x, y]]));
  wrap("rect", (ctx, x, y, w, h) => touch(ctx, [[x, y], [x + w, y + h]]));
  wrap("arc", (ctx, x, y, r) => touch(ctx, [[x - r, y - r], [x + r, y + r]]));
  const done = (ctx) => { if (!block && path && small(path)) log.marks.push(path.slice()); };
  wrap("fill", done);
  wrap("stroke", done);
  wrap("drawImage", (ctx, image, ...a) => {  // (dx, dy[, dw, dh]) or (s..., dx, dy, dw, dh)
    const [x, y, w, h] = a.length === 8 ? a.slice(4)
      : [a[0], a[1], a[2] ?? image.width, a[3] ?? image.height];
    const b = empty();
    grow(b, at(ctx, x, y)); grow(b, at(ctx, x + w, y + h));
    log.images.push(b);
  });
  wrap("fillRect", (ctx, x, y, w, h) => {
    const b = empty();
    grow(b, at(ctx, x, y)); grow(b, at(ctx, x + w, y + h));
    if (block) { grow(block.box, [b[0], b[1]]); grow(block.box, [b[2], b[3]]); }
    else if (small(b)) log.marks.push(b);
  });
  wrap("fillText", (ctx, text, x, y) => {
    if (!block) return;
    const w = ctx.measureText(text).width;
    const x0 = ctx.textAlign === "right" || ctx.textAlign === "end" ? x - w
      : ctx.textAlign === "center" ? x - w / 2 : x;
    grow(block.box, at(ctx, x0, y - 12)); grow(block.box, at(ctx, x0 + w, y + 3));
    block.texts.push(text);
  });
})();
"""

# The key's blocks (north arrow, scale bar) that overlap a mark, over the day's flight
# at every tenth move (the drone moves under the corners as it flies)
OVERLAPS = """(moves) => {
  const hit = (a, b) => a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
  const slider = document.querySelector('#time');
  const out = [];
  let marks = 0;
  for (let k = 0; k <= moves; k += 10) {
    slider.value = k;
    slider.dispatchEvent(new Event('input'));
    const log = window.canvasLog;
    marks = Math.max(marks, log.marks.length);
    const key = log.blocks.filter(b => b.texts.some(t => t === 'N' || / k?m$/.test(t)));
    if (key.length !== 2) return { error: `move ${k}: key blocks ${JSON.stringify(log.blocks)}` };
    for (const b of key) for (const m of log.marks) {
      if (hit(b.box, m)) out.push({ move: k, key: b.texts.join(' '), box: b.box, mark: m });
    }
  }
  return { overlaps: out, marks };
}"""


def test_map_key_covers_no_marker_on_a_phone(open_page, api):
    """At 360 px the north arrow (drawn in the map's top right corner) covered a
    customer of the README's day, and the scale bar (bottom left) the confinement
    area's corner: they sit in a strip under the plotted area now, so no customer, shop,
    home or drone is ever under them."""
    detail = api.get(f"/days/{DAY}").json()
    site = api.get("/site.geojson").json()["features"]
    places = {tuple(o["lonlat"]) for o in detail["orders"] if o["lonlat"]}
    shops = [f for f in site if f["properties"].get("kind") == "shop"]
    moves = detail["report"]["moves"]
    pg = open_page(f"/day.html#date={DAY}", "phone-640", init_script=CANVAS_LOG)
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0")
    got = p.evaluate(OVERLAPS, moves)
    assert "error" not in got, got
    # every customer place (a dot, a ring where partly served), shop, home and the drone
    assert got["marks"] >= len(places) + len(shops) + 2, got["marks"]
    assert got["overlaps"] == [], got["overlaps"][:5]
    set_slider(p, "#time", moves // 3)
    pg.done("day-key")


def _store_empty_day(db: str, date: str) -> None:
    """A day stored as a mistyped date is: a run without orders or moves."""
    import datetime as dt

    from skyroute.delivery.store import connect, write_day

    eng = connect(db)
    now = dt.datetime(2024, 1, 1, 12)
    write_day(eng, dt.date.fromisoformat(date), {
        "started": now, "finished": now, "moves": 0, "orders_placed": 0,
        "orders_delivered": 0, "orders_invalid": 0, "money_delivered": 0,
        "money_placed": 0, "settings": {}}, [], [])
    eng.dispose()


@pytest.mark.parametrize("size", ["desktop", "phone-640"])
def test_day_page_deletes_a_day_without_a_flight(open_page, api, server, size):
    """An empty day stored by a mistyped date stayed in the day list for good: the page
    had no way to remove it (nor the API). It is deleted after a confirmation now; a
    flown day offers no delete. The focus goes to the day list, which shows the
    deleted day's neighbour."""
    mistyped = "2024-03-05" if size == "desktop" else "2024-03-06"
    _store_empty_day(server[2], mistyped)
    pg = open_page(f"/day.html#date={DAY}", size)
    p = pg.page
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{DAY}:')")
    assert not p.is_visible("#delete")  # a flown day is kept
    p.select_option("#date", mistyped)
    p.wait_for_function("document.querySelector('#status').textContent"
                        f".startsWith('{mistyped}:')")
    assert p.is_visible("#delete")
    dialogs: list[str] = []
    _answer_next_dialog(p, dialogs, accept=False)
    p.focus("#delete")
    p.keyboard.press("Enter")
    p.wait_for_function("document.activeElement.id === 'delete'")
    assert len(dialogs) == 1 and mistyped in dialogs[0], dialogs
    assert mistyped in [d["date"] for d in api.get("/days").json()]  # not confirmed: kept
    p.fill("#token", TOKEN)
    _answer_next_dialog(p, dialogs, accept=True)
    p.focus("#delete")
    p.keyboard.press("Enter")
    p.wait_for_function("document.querySelector('#status').textContent"
                        f".startsWith('Deleted {mistyped}.')")
    assert len(dialogs) == 2
    days = [d["date"] for d in api.get("/days").json()]
    assert mistyped not in days
    options = p.locator("#date option").evaluate_all("o => o.map(x => x.value)")
    assert options == days
    assert p.evaluate("document.activeElement.id") == "date"
    assert p.input_value("#date") == days[-1]  # its neighbour (the last day before it)
    assert p.evaluate("location.hash") == f"#date={days[-1]}"
    pg.done("day-deleted")


PLANNER_KEY = """() => {
  const hit = (a, b) => a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
  const log = window.canvasLog;
  const bars = log.blocks.filter(b => b.texts.some(t => / cells$/.test(t)));
  const c = document.querySelector('#map').getBoundingClientRect();
  return { bars: bars.map(b => b.box), images: log.images, marks: log.marks,
           canvas: [c.width, c.height],
           overlaps: bars.flatMap(b => [...log.images, ...log.marks].filter(m => hit(b.box, m))) };
}"""


@pytest.mark.parametrize("size", ["desktop-720", "phone-640"])
def test_planner_scale_bar_covers_no_cell(open_page, api, size):
    """The planner drew its scale bar over the map's bottom left cells (at 1280x720 and
    360x640 alike): it sits in a strip under the cells now, as on the other pages, and a
    click still picks the cell under it (a start on the free cell nearest the bottom left
    corner, its marker clear of the bar too), while a click in the strip picks none."""
    doc = api.get("/maps/den312d").json()
    width, height = doc["width"], doc["height"]
    corner = max(_free_cells(doc["rows"], doc["passable"]), key=lambda c: c[1] - c[0])
    pg = open_page("/planner.html", size, init_script=CANVAS_LOG)
    p = pg.page
    _open_map(pg, "den312d")
    click_cell(p, width, corner[0] + 0.5, corner[1] + 0.5)
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('Start')")
    assert (int(p.input_value("#sx")), int(p.input_value("#sy"))) == corner
    got = p.evaluate(PLANNER_KEY)
    assert len(got["bars"]) == 1 and len(got["images"]) == 1, got
    cells = got["images"][0]  # every cell, drawn as one image: the whole map
    cw, ch = got["canvas"]
    assert cells[:3] == pytest.approx([0, 0, cw], abs=0.01), (cells, got["canvas"])
    assert (cells[3] - cells[1]) * width == pytest.approx((cells[2] - cells[0]) * height)
    assert got["marks"], got  # the start's marker (filled, then ringed)
    assert got["overlaps"] == [], got
    assert cells[3] < got["bars"][0][1] and got["bars"][0][3] <= ch + 0.1  # in the strip
    click_cell(p, width, corner[0] + 0.5, height + 0.5)  # under the bottom row: the strip
    p.wait_for_timeout(200)
    assert (int(p.input_value("#sx")), int(p.input_value("#sy"))) == corner
    assert p.input_value("#gx") == "" and p.inner_text("#status").startswith("Start")
    pg.done("planner-key")


def _store_kept_day(db: str, date: str) -> None:
    """A day stored with a flight that delivered, whose orders are all invalid now (their
    items are on none of the site's menus): flown again, the day is kept unless
    replace."""
    import datetime as dt

    from skyroute.delivery.orders import Order
    from skyroute.delivery.site import load_site
    from skyroute.delivery.source import DirSource
    from skyroute.delivery.store import connect, import_orders, write_day

    day = dt.date.fromisoformat(date)
    tag = date.replace("-", "")[-4:]  # order numbers of 8 characters, one set a day
    orders = [Order(f"fe{tag}0{k}", day, "s0000001", "brook.boat.brick", ("Gone pie",))
              for k in range(2)]
    lon, lat = load_site(DirSource(EXAMPLE)).home
    eng = connect(db)
    import_orders(eng, orders)
    now = dt.datetime(2024, 1, 1, 12)
    write_day(eng, day, {"started": now, "finished": now, "moves": 2, "orders_placed": 2,
                         "orders_delivered": 1, "orders_invalid": 0, "money_delivered": 150,
                         "money_placed": 300, "settings": {"method": "milp"}},
              [{"order_no": orders[0].order_no, "delivered_to": orders[0].deliver_to,
                "cost_in_pence": 150}],
              [{"seq": k, "order_no": orders[0].order_no,
                "from_lon": lon + 0.00015 * k, "from_lat": lat, "angle": 0,
                "to_lon": lon + 0.00015 * (k + 1), "to_lat": lat} for k in range(2)])
    eng.dispose()


@pytest.mark.parametrize("size", ["desktop-720", "phone-640"])
def test_day_page_flies_a_stored_day_again_with_replace(open_page, api, server, size):
    """The API's deliver job takes replace; the day page had no way to send it: a day
    whose every order is invalid now failed ('...replace=true stores the day as flown
    now') and the viewer could only show that. The job form has "Replace a kept flight":
    the failure points to it, a stored day is replaced only after a confirmation (a
    dismissed one sends nothing), all by keyboard, and the box is cleared once sent."""
    if server_has_no_jobs():
        pytest.skip("skyroute.jobs is not in this tree: no jobs")
    date = "2023-12-20" if size == "desktop-720" else "2023-12-21"
    _store_kept_day(server[2], date)
    pg = open_page(f"/day.html#date={date}", size)
    p = pg.page
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{date}:"
                        " 2 moves')")
    posts: list = []
    p.on("request", lambda r: r.method == "POST" and posts.append(r.post_data_json))
    p.fill("#job-date", date)
    p.fill("#token", TOKEN)
    p.focus("#start")
    p.keyboard.press("Enter")  # without replace: the stored flight is kept, the job fails
    _wait_status_of(p, "#job-status", "error")
    said = p.inner_text("#job-status")
    assert f"{date}: every one of the day's 2 orders is invalid" in said, said
    assert said.endswith("replace=true stores the day as flown now. To store the day as "
                         "flown now, over its stored flight, tick "
                         "“Replace a kept flight” and fly it again."), said
    assert api.get(f"/days/{date}").json()["report"]["orders_delivered"] == 1
    SHOTS.mkdir(parents=True, exist_ok=True)
    p.screenshot(path=str(SHOTS / f"day-kept-{size}.png"), full_page=True)
    # the box by keyboard: Tab from the planner, Space to tick it
    p.focus("#method")
    p.keyboard.press("Tab")
    assert p.evaluate("document.activeElement.id") == "replace"
    p.keyboard.press("Space")
    assert p.is_checked("#replace")
    dialogs: list[str] = []
    _answer_next_dialog(p, dialogs, accept=False)
    p.focus("#start")
    p.keyboard.press("Enter")
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'info'")
    assert len(dialogs) == 1 and date in dialogs[0] and "replaced" in dialogs[0], dialogs
    assert p.inner_text("#job-status") == f"Not flown: the stored flight of {date} is kept."
    assert p.evaluate("document.activeElement.id") == "start" and p.is_checked("#replace")
    assert len(posts) == 1  # the refused one only
    _answer_next_dialog(p, dialogs, accept=True)
    p.keyboard.press("Enter")
    p.wait_for_function("document.querySelector('#job-status').dataset.kind === 'ok'"
                        " && !document.querySelector('#start').ariaDisabled", timeout=120_000)
    assert len(dialogs) == 2
    assert posts == [{"date": date, "method": "milp", "replace": False},
                     {"date": date, "method": "milp", "replace": True}]
    assert not p.is_checked("#replace")  # sent once; the next day flown keeps its flight
    report = api.get(f"/days/{date}").json()["report"]
    assert (report["orders_delivered"], report["orders_invalid"], report["moves"]) == (0, 2, 0)
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{date}:"
                        " the drone did not fly')")
    assert p.input_value("#date") == date
    pg.done("day-replace")


def _answer_next_dialog(page, said: list[str], *, accept: bool) -> None:
    """Answer the page's next confirm() (OK or Cancel) and keep its message in ``said``."""
    page.once("dialog", lambda d: (said.append(d.message),
                                   d.accept() if accept else d.dismiss()))


def _wait_status_of(page, selector: str, kind: str, timeout: int = 120_000) -> None:
    page.wait_for_function(f"document.querySelector('{selector}').dataset.kind === '{kind}'"
                           f" && !document.querySelector('#start').ariaDisabled",
                           timeout=timeout)


def test_fleet_replay_ends_where_the_run_ends(open_page, server):
    """A run of 0.02777798611111111 h ends at 100.001 s (hours x 3600 rounded to the
    millisecond its files write times to: report settings.end_s), but the replay's time
    slider ended at hours x 3600 = 100.00075 s, short of the run's end. It ends at the
    run's own end now."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    import sqlalchemy as sa

    from skyroute.fleet.packages import horizon_seconds
    from skyroute.fleet.scenario import preset
    from skyroute.jobs.fleet import FleetTask, RunSpec, fly_fleet

    hours = 0.02777798611111111
    run_id = fly_fleet(FleetTask(server[2], "viewer-ms-end", None,
                                 RunSpec(preset("seed-3x3").model_dump(), hours, 1)))["id"]
    try:
        end = httpx.get(f"{server[0]}/fleet/runs/{run_id}").json()["report"]["settings"]["end_s"]
        assert end == horizon_seconds(hours) == 100.001 != hours * 3600
        pg = open_page(f"/fleet.html#run={run_id}", "desktop")
        p = pg.page
        p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
        assert p.input_value("#run") == run_id
        assert float(p.get_attribute("#time", "max")) == end
        pg.close()
    finally:
        eng = sa.create_engine(server[2])
        with eng.begin() as c:
            c.execute(sa.text("DELETE FROM fleet_runs WHERE id = :id"), {"id": run_id})
        eng.dispose()


@pytest.mark.parametrize("page", ["day", "fleet"])
def test_an_empty_store_says_so_and_how_to_fill_it(open_page, page):
    """A fresh store (``skyroute db init``): the fleet page's run list was an empty box
    (its "no stored runs" replaced by the runs, none); the day page said to fly a day
    below, which on a store without orders stores an empty day. The list says there is
    nothing, and the day page says the orders come first."""
    pg = open_page(f"/{page}.html", "desktop")
    p = pg.page
    if page == "day":
        p.route("**/days", lambda r: r.fulfill(json=[]))
        p.reload()
        p.wait_for_function("document.querySelector('#status').textContent"
                            ".includes('no delivery day')")
        assert "skyroute db import DIR --db URL" in p.inner_text("#status")
        key, words = "#date", "no stored days"
    else:
        p.route(re.compile(r"/fleet/runs\?limit="), lambda r: r.fulfill(json=[]))
        p.reload()
        p.wait_for_function("document.querySelector('#status').textContent"
                            ".startsWith('No fleet run')")
        key, words = "#run", "no stored runs"
    assert p.locator(f"{key} option").all_inner_texts() == [words]
    assert p.is_disabled(key)
    assert _key_inked(p) == 0  # no scale bar or north arrow on the empty map
    pg.done(f"{page}-empty-store")


def test_a_day_flown_without_stored_orders_says_nothing_was_flown(open_page):
    """A day flown from the page when the store holds none of its orders (a fresh store,
    or a date typed wrong) is stored as a day of no orders; the job line said "The day
    is flown and stored." in green. It says nothing was flown, and why."""
    if server_has_no_jobs():
        pytest.skip("skyroute.jobs is not in this tree: no jobs")
    date = "2024-02-01"  # a stored day of no orders
    pg = open_page(f"/day.html#date={DAY}", "desktop")
    p = pg.page
    _job_routes(p, {"state": "done", "progress": 1.0, "result": {
        "from": date, "to": date, "days": 1, "days_with_orders": 0}}, kind="deliver")
    p.wait_for_function("document.querySelector('#time').max > 0")
    p.fill("#job-date", date)
    p.fill("#token", TOKEN)
    p.click("#start")
    p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{date}:')"
                        " && !document.querySelector('#start').ariaDisabled")
    text = p.inner_text("#job-status")
    assert text.startswith(f"Nothing was flown: the store holds no orders of {date}."), text
    assert "skyroute db import" in text
    assert p.evaluate("document.querySelector('#job-status').dataset.kind") == "error"
    assert p.is_visible("#delete")  # the way to take the empty day off
    pg.done("day-job-no-orders")


@pytest.mark.parametrize("page", ["day", "fleet", "planner"])
def test_a_failed_choice_leaves_the_list_on_what_is_shown(open_page, server, page):
    """A day or map chosen while the server did not answer, or a run deleted since the
    list was read: the status line said so, but the list stayed on the failed choice
    while the page showed the one before, and choosing that one again asked nothing (no
    change). The list goes back to what is shown; a deleted run goes from it."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    with contextlib.ExitStack() as stack:
        if page == "day":
            key, shown, other = "#date", DAY, "2024-02-01"
            pg = open_page(f"/day.html#date={shown}", "desktop")
            pg.page.wait_for_function("document.querySelector('#time').max > 0")
            gone = f"**/days/{other}*"
        elif page == "planner":
            key, shown, other = "#map-name", "Berlin_1_256", "den312d"
            pg = open_page("/planner.html", "desktop")
            _open_map(pg, shown)
            gone = f"**/maps/{other}"
        else:
            import sqlalchemy as sa

            key, shown, other = "#run", server[1], stack.enter_context(_copied_run(server))
            pg = open_page(f"/fleet.html#run={shown}", "desktop")
            pg.page.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
            eng = sa.create_engine(server[2])
            with eng.begin() as c:  # deleted after the page listed it
                for table, column in (("fleet_run_files", "run_id"), ("fleet_runs", "id")):
                    c.execute(sa.text(f"DELETE FROM {table} WHERE {column} = :id"), {"id": other})
            eng.dispose()
        p = pg.page
        if page != "fleet":
            p.route(gone, lambda r: r.abort())  # the server does not answer
        p.select_option(key, other)
        p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'")
        said = p.inner_text("#status")
        assert ("did not answer" if page != "fleet" else "(404)") in said, said
        assert p.input_value(key) == shown
        if page == "fleet":
            assert other not in _options(p) and shown in _options(p)
            return
        p.unroute(gone)  # the server is back: the same choice again is read
        p.select_option(key, other)
        p.wait_for_function(f"document.querySelector('#status').textContent.startsWith('{other}')",
                            timeout=WAIT)
        assert p.input_value(key) == other


# -- bad networks, empty maps, the focus order --------------------------------------------

KEY_PX = 30  # view.js KEY: the strip under a map that holds its scale bar and north arrow
INKED = """(key) => {
  const c = document.querySelector('#map');
  const h = Math.round(key * c.height / c.clientHeight);
  const d = c.getContext('2d').getImageData(0, c.height - h, c.width, h).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i] < 128 && d[i + 3] > 0) n++;
  return n;
}"""


def _key_inked(p) -> int:
    """Dark pixels in the key strip of the map canvas (the scale bar and north arrow are
    dark ink on the map's near-white)."""
    return p.evaluate(INKED, KEY_PX)


@pytest.mark.parametrize("page", ["day", "planner", "fleet"])
def test_a_server_that_never_answers_is_said_with_a_way_to_retry(open_page, server, page):
    """A server (or a proxy) that took the connection and never answered left the page
    on "Loading…" for ever: no request had a time limit, and nothing offered to ask
    again. Past the limit (45 s: the page's clock is run forward here) the status line
    names what did not load, and its Try again button asks again."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    held_url, path, what = {
        "day": (f"**/days/{DAY}", f"/day.html#date={DAY}", f"Reading {DAY}"),
        "planner": ("**/maps", "/planner.html", "Reading the bundled maps"),
        "fleet": (f"**/fleet/runs/{server[1]}/tracks.csv", f"/fleet.html#run={server[1]}",
                  "Reading the run"),
    }[page]
    pg = open_page(path, "desktop")
    p = pg.page
    # (the first load done: none of its requests is held, the reload's is)
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'",
                        timeout=WAIT)
    held = []
    p.route(held_url, lambda r: held.append(r))  # taken, never answered
    p.clock.install()
    p.reload()
    for _ in range(200):
        if held:
            break
        p.wait_for_timeout(50)
    assert held
    p.clock.fast_forward(46_000)  # past api.js's WAIT_MS
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'",
                        timeout=5_000)
    said = p.inner_text("#status")
    assert said == f"{what} failed: the server did not answer within 45 s. Try again", said
    p.unroute(held_url)  # the server answers again
    p.click("#status .retry")
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'",
                        timeout=WAIT)
    assert p.locator("#status .retry").count() == 0
    assert not pg.errors, pg.errors


EVENT = '{"t": 0.0, "kind": "spawn", "package": 0, "airport": "A"}'


@pytest.mark.parametrize(("page", "url", "answer", "said"), [
    # a proxy's sign-in page where the JSON should be: the parser's words were shown
    ("day", f"**/days/{DAY}",
     {"status": 200, "content_type": "text/html", "body": "<html><body>Sign in</body></html>"},
     f'Reading {DAY} failed: the server\'s answer is not JSON (it begins "<html><body>Sign '
     'in</body></html>"). Try again'),
    # a 500 without a problem document: its status was said twice
    ("day", f"**/days/{DAY}",
     {"status": 500, "content_type": "text/html", "body": "<h1>Internal Server Error</h1>"},
     f"Reading {DAY} failed (500): Internal Server Error Try again"),
    # events.jsonl cut short: an exception in the console, the page left on "Loading"
    ("fleet", "**/events.jsonl",
     {"status": 200, "content_type": "application/x-ndjson", "body": f'{EVENT}\n{{"t": 1.0, "ki'},
     "Reading the run failed: events.jsonl line 2 is not an event (a JSON object with a "
     "time t)."),
], ids=["proxy-page", "500-without-problem", "events-cut-short"])
def test_an_answer_that_is_not_what_was_asked_for_is_said_in_one_line(
        open_page, server, page, url, answer, said):
    """A 500 or an answer that is no JSON: one line naming what failed, no exception."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    path = f"/day.html#date={DAY}" if page == "day" else f"/fleet.html#run={server[1]}"
    pg = open_page(path, "desktop")
    p = pg.page
    p.route(url, lambda r: r.fulfill(**answer))
    p.reload()
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'",
                        timeout=WAIT)
    assert p.inner_text("#status") == said
    assert [e for e in pg.errors if "Failed to load resource" not in e] == []


def test_an_empty_map_draws_no_scale_bar(open_page):
    """A map with nothing on it (no world loaded; an empty store's day and fleet pages,
    see test_an_empty_store_says_so_and_how_to_fill_it) had a scale bar and a north
    arrow, scaling and orienting nothing; they come with the first thing drawn."""
    pg = open_page("/world.html", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#status').textContent.startsWith('Choose')")
    assert _key_inked(p) == 0
    _load_city(pg)
    assert _key_inked(p) > 0


@pytest.mark.parametrize("page", ["day", "fleet"])
def test_the_focus_follows_the_panels_on_a_wide_screen(open_page, server, page):
    """On a wide screen the job form sits under the first panel, beside the map; it came
    after the tables in the page, so Tab went from the first panel to the map, down to
    the tables at the foot, and back up to the form. The focus now visits the panels in
    the order they are seen: by rows, left to right."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    path = f"/day.html#date={DAY}" if page == "day" else f"/fleet.html#run={server[1]}"
    pg = open_page(path, "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#time').max > 0", timeout=WAIT)
    panel = ("(() => { const a = document.activeElement;"
             " const kids = [...document.querySelector('.layout').children];"
             " return kids.findIndex((k) => k.contains(a)); })()")
    visited = []
    for _ in range(80):
        p.keyboard.press("Tab")
        at = p.evaluate(panel)
        if at < 0 and visited:
            break  # out of the panels (past the last one)
        if at >= 0 and (not visited or visited[-1] != at):
            visited.append(at)
    seen = p.evaluate("""() => [...document.querySelector('.layout').children].map((k, i) => {
        const r = k.getBoundingClientRect();
        return [Math.round(r.top), Math.round(r.left), i]; })""")
    by_rows = [i for _, _, i in sorted(seen) if i in visited]
    assert visited == by_rows, (visited, seen)
    assert len(visited) == 4  # the first panel, the map's player, the job form, the tables


# -- empty maps, long run labels, answers of another shape, the site's failures -----------

NOTE_OVER_MAP = """() => {
  const note = document.querySelector('.map-empty');
  if (!note || note.hidden) return null;
  const n = note.getBoundingClientRect();
  const c = document.querySelector('#map').getBoundingClientRect();
  return { text: note.innerText, inside: n.left >= c.left - 1 && n.right <= c.right + 1
    && n.top >= c.top - 1 && n.bottom <= c.bottom + 1 && n.height > 20 };
}"""


@pytest.mark.parametrize("size", ["desktop", "phone"])
@pytest.mark.parametrize("page", ["day", "fleet", "planner", "world", "day-of-nothing"])
def test_an_empty_map_says_why(open_page, server, page, size):
    """A map with nothing on it (an empty store's day and fleet pages, the planner whose
    maps did not load, a day with no flight, no customer's place and no site) was a
    blank box with no word: it reads as a page that failed to draw. It says there is
    nothing to draw, and why, over the map; the note goes with the first thing drawn."""
    pg = open_page({"day": "/day.html", "fleet": "/fleet.html", "planner": "/planner.html",
                    "world": "/world.html", "day-of-nothing": f"/day.html#date={DAY}"}[page],
                   size)
    p = pg.page
    if page == "day":
        p.route("**/days", lambda r: r.fulfill(json=[]))
        why = "Nothing to draw: the store holds no delivery day yet."
    elif page == "fleet":
        p.route(re.compile(r"/fleet/runs\?limit="), lambda r: r.fulfill(json=[]))
        why = "Nothing to draw: no fleet run is stored yet."
    elif page == "planner":
        p.route("**/maps", lambda r: r.fulfill(status=500, body="x"))
        why = "Nothing to draw: the bundled maps could not be read."
    elif page == "world":
        why = "Nothing to draw yet: choose or paste a world file."
    else:  # a day whose orders have no place, without a flight or a site
        def nowhere(route):
            d = route.fetch().json()
            route.fulfill(json={**d, "orders": [{**o, "lonlat": None} for o in d["orders"]]})

        p.route(f"**/days/{DAY}", nowhere)
        p.route("**/flightpath.geojson", lambda r: r.fulfill(json={
            "type": "FeatureCollection", "features": [
                {"type": "Feature", "geometry": None, "properties": {"moves": 0}}]}))
        p.route("**/site.geojson", lambda r: r.fulfill(
            status=404, content_type="application/problem+json",
            body='{"detail": "no site"}'))
        why = (f"Nothing to draw: {DAY} has no flight and no customer's place, and no site "
               "is loaded.")
    p.reload()
    p.wait_for_function("(() => { const s = document.querySelector('#status');"
                        " return s.dataset.kind && s.dataset.kind !== 'busy'; })()",
                        timeout=WAIT)
    assert p.evaluate(NOTE_OVER_MAP) == {"text": why, "inside": True}
    if page != "planner":
        assert _key_inked(p) == 0  # (no scale bar under the note)
    pg.errors[:] = [e for e in pg.errors if "Failed to load resource" not in e]
    pg.done(f"empty-map-{page}")
    if page not in ("planner", "world") or size != "desktop":
        return
    # the first thing drawn takes the note away
    pg = open_page(f"/{page}.html", size)
    p = pg.page
    if page == "planner":
        p.route("**/maps", lambda r: r.fulfill(status=500, body="x"))
        p.reload()
        p.wait_for_selector("#status .retry")
        p.unroute("**/maps")
        p.click("#status .retry")
        p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'",
                            timeout=WAIT)
    else:
        _load_city(pg)
    assert p.evaluate(NOTE_OVER_MAP) is None
    assert p.is_hidden(".map-empty")


LONG_NAME = "Hamburg-Altona harbour feeder network with nine airports (winter timetable)"
FITS_THE_LIST = """() => {
  const s = document.querySelector('#run');
  const cs = getComputedStyle(s);
  const room = s.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight) - 20;
  const span = document.createElement('span');
  span.style.font = cs.font;
  span.style.whiteSpace = 'pre';
  span.style.position = 'absolute';
  document.body.append(span);
  const out = [...s.options].map((o) => {
    span.textContent = o.text;
    return span.offsetWidth <= room;
  });
  span.remove();
  return out;
}"""


@pytest.mark.parametrize("size", ["desktop", "phone"])
def test_long_run_labels_fit_the_list(open_page, server, size):
    """A run's label (when stored, scenario, hours, seed, packages delivered) is wider
    than the run list on every screen: the list showed its first 30 letters or so, and
    a long scenario name hid which run was which. Each option is the longest form of
    its label that fits the list's width, its whole label its tooltip (the list's too,
    for the run chosen), and the panel's numbers give every part of it, wrapped."""
    if server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")

    def long_runs(route):
        r = route.fetch()
        route.fulfill(response=r, json=[{**x, "scenario": LONG_NAME} for x in r.json()])

    def long_detail(route):
        r = route.fetch()
        d = r.json()
        route.fulfill(response=r, json={**d, "scenario": {**d["scenario"], "name": LONG_NAME}})

    with _copied_run(server, params={"hours": 0.25, "seed": 7}) as copy:
        pg = open_page(f"/fleet.html#run={copy}", size)
        p = pg.page
        p.route(re.compile(r"/fleet/runs\?limit="), long_runs)
        p.route(re.compile(r"/fleet/runs/[^/?]+\?limit=1$"), long_detail)
        p.reload()
        p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'"
                            " && document.querySelector('#time').max > 0", timeout=WAIT)
        assert p.evaluate(FITS_THE_LIST) == [True, True]
        texts = p.locator("#run option").all_inner_texts()
        titles = p.eval_on_selector_all("#run option", "os => os.map((o) => o.title)")
        assert len(set(texts)) == 2, texts
        whole = r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d · " + re.escape(LONG_NAME) + \
            r" · 0\.25 h · seed \d+ · \d+/\d+ delivered"
        assert all(re.fullmatch(whole, t) for t in titles), titles
        assert " · seed 7" in titles[0] and " · seed 7" in texts[0]  # the copy: newest
        assert p.get_attribute("#run", "title") == titles[0]
        assert LONG_NAME in p.inner_text("#s-scenario")
        assert re.fullmatch(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d", p.inner_text("#s-stored"))
        assert p.inner_text("#s-hours") == "0.25 h, seed 7"
        p.select_option("#run", server[1])  # the list's tooltip follows the run chosen
        p.wait_for_function(f"location.hash === '#run={server[1]}'"
                            " && document.querySelector('#status').dataset.kind === 'ok'",
                            timeout=WAIT)
        assert p.get_attribute("#run", "title") == titles[1]
        pg.done("fleet-long-labels")


DAY_GONE_WRONG = f'Reading {DAY} failed: the server\'s answer to /days/{DAY}'


@pytest.mark.parametrize(("page", "url", "body", "said"), [
    # each was the browser's TypeError ("Cannot read properties of undefined (reading
    # 'map')"), or an exception in the console and a page left on "Loading"
    ("day", f"**/days/{DAY}", {"orders": []},
     f'{DAY_GONE_WRONG} is not a stored day: "report" is not an object. Try again'),
    ("day", "**/flightpath.geojson", {"type": "FeatureCollection", "features": {}},
     f"{DAY_GONE_WRONG}/flightpath.geojson is not a day's flight (GeoJSON): \"features\" "
     "is not a list. Try again"),
    ("day", "**/days", [{"day": DAY}],
     "Reading the stored days failed: the server's answer to /days is not a list of days: "
     "\"[0].date\" is not a string. Try again"),
    ("fleet", "**/fleet.geojson", {"features": 3},
     "Reading the run failed: the server's answer to /fleet/runs/{run}/fleet.geojson is not "
     "a fleet's ground (GeoJSON): \"features\" is not a list. Try again"),
    ("fleet", re.compile(r"/fleet/runs\?limit="), [None],
     "Reading the fleet runs failed: the server's answer to /fleet/runs is not a list of "
     "runs: \"[0]\" is not an object. Try again"),
], ids=["day", "flight", "day-list", "fleet-ground", "run-list"])
def test_json_of_another_shape_is_said_in_skyroutes_words(open_page, server, page, url,
                                                          body, said):
    """JSON of another shape than the page reads (another server's, a proxy's, an older
    skyroute's) was said in the browser's words, or not at all: one line now names the
    endpoint and the field, as the other failures are said, with Try again."""
    if page == "fleet" and server[1] is None:
        pytest.skip("skyroute.jobs is not in this tree: no fleet run")
    path = f"/day.html#date={DAY}" if page == "day" else f"/fleet.html#run={server[1]}"
    pg = open_page(path, "desktop")
    p = pg.page
    p.route(url, lambda r: r.fulfill(json=body))
    p.reload()
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'error'",
                        timeout=WAIT)
    assert p.inner_text("#status") == said.replace("{run}", str(server[1]))
    assert pg.errors == []


def test_a_plan_of_another_shape_is_said_in_skyroutes_words(open_page, api):
    """POST /plan answered with JSON of another shape: the planner threw in the console
    (``a.status`` of undefined) and left its rows "planning…"."""
    doc = api.get("/maps/den312d").json()
    free = _free_cells(doc["rows"], doc["passable"])
    pg = open_page("/planner.html", "desktop")
    p = pg.page
    _open_map(pg, "den312d")
    p.route("**/plan", lambda r: r.fulfill(json={"path": []}))
    _type_cells(p, free[0], free[-1])
    p.click("#run")
    said = _wait_status(p, "error")
    assert said == ("Planning failed: the server's answer to /plan is not a plan: "
                    "\"status\" is not a string."), said
    assert p.locator("#results tbody tr .tag.bad").count() == 3
    assert pg.errors == []


SHOP_INKED = """() => {
  const c = document.querySelector('#map');
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let n = 0;  // the shops' fill, #e69f00
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - 230) < 8 && Math.abs(d[i + 1] - 159) < 8 && d[i + 2] < 20) n++;
  }
  return n;
}"""


READ = """(ends) => ends.every((end) => performance.getEntriesByType('resource')
  .some((e) => e.name.endsWith(end) && e.responseEnd > 0))"""


@pytest.mark.parametrize("how", ["busy", "never-answers", "absent"])
def test_a_site_that_fails_is_said_with_a_way_to_retry(open_page, how):
    """GET /site.geojson failing was said on the day's status line, which the day's own
    line replaced at once: nobody saw it, and nothing asked for the site again. The
    site has a line of its own under the day's, with Try again (the same time limit as
    every request: 45 s); the day is drawn without it meanwhile, and with it after."""
    pg = open_page(f"/day.html#date={DAY}", "desktop")
    p = pg.page
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'",
                        timeout=WAIT)
    assert p.evaluate(SHOP_INKED) > 0 and p.inner_text("#site-status") == ""
    held = []
    if how == "busy":
        p.route("**/site.geojson", lambda r: r.fulfill(
            status=503, content_type="application/problem+json",
            body='{"detail": "the store is busy; try again shortly"}'))
    elif how == "absent":
        p.route("**/site.geojson", lambda r: r.fulfill(
            status=404, content_type="application/problem+json",
            body='{"detail": "this server has no delivery site"}'))
    else:
        p.route("**/site.geojson", lambda r: held.append(r))  # taken, never answered
        p.clock.install()
    p.reload()
    if how == "never-answers":
        # the day is asked beside the site: its answers in before the clock runs on (else
        # they run out of time too)
        for _ in range(400):
            if held and p.evaluate(READ, [f"/days/{DAY}", "/flightpath.geojson"]):
                break
            p.wait_for_timeout(50)
        assert held
        p.wait_for_timeout(500)  # (their bodies read by the page)
        p.clock.fast_forward(46_000)  # past api.js's WAIT_MS
    p.wait_for_function("document.querySelector('#status').dataset.kind === 'ok'",
                        timeout=WAIT)
    assert p.inner_text("#status").startswith(f"{DAY}: ")  # the day, drawn without the site
    assert p.evaluate(SHOP_INKED) == 0
    said = p.inner_text("#site-status")
    if how == "absent":
        assert said == ("No site to draw (the server was started without --data or "
                        "--source): the flight is shown alone.")
        assert p.locator("#site-status .retry").count() == 0
        pg.errors[:] = [e for e in pg.errors if "Failed to load resource" not in e]
        pg.done("day-without-site")
        return
    why = (" (503): the store is busy; try again shortly." if how == "busy"
           else ": the server did not answer within 45 s.")
    assert said == f"Reading the site failed{why} The day is drawn without it. Try again", said
    assert p.evaluate("document.querySelector('#site-status').dataset.kind") == "error"
    p.unroute("**/site.geojson")  # the server answers again
    p.click("#site-status .retry")
    p.wait_for_function("document.querySelector('#site-status').textContent === ''",
                        timeout=WAIT)
    assert p.evaluate(SHOP_INKED) > 0  # the day drawn again, over its site
    assert p.inner_text("#status").startswith(f"{DAY}: ")
    pg.errors[:] = [e for e in pg.errors if "Failed to load resource" not in e]
    pg.done(f"day-site-{how}")
