"""Map pictures as a user reads them, checked on matplotlib's objects and the PNG's
header, not on pixels: the legend beside the map, start and goal on top and named, a
title with the command's own numbers, units on the axes, true proportions, enough
pixels for a large grid and no more for a small one, labels that keep apart."""

from __future__ import annotations

import struct

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")  # before pyplot: no window on a desktop either
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection
from matplotlib.text import Text

import skyroute
from skyroute.io import world_out
from skyroute.io.plot import (
    PALETTE_COLOURS,
    draw_grid_path,
    draw_path,
    grid_dpi,
    place_labels,
    plot_grid_path,
    save_figure,
    title_lines,
)
from skyroute.result import PlanResult, Status
from skyroute.world.grid import Grid
from skyroute.world.load import load_world
from tests.conftest import ROOT


def png_size(path) -> tuple[int, int]:
    """(width, height) from the PNG's IHDR chunk."""
    return struct.unpack(">II", path.read_bytes()[16:24])


def drawn(fig):
    """The renderer of ``fig`` drawn again (a closed figure has lost its Agg canvas)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def boxes(fig, *artists):
    r = drawn(fig)
    return [a.get_window_extent(r) for a in artists]


def test_grid_picture_legend_beside_the_map_and_ends_named(figures, tmp_path):
    blocked = np.zeros((8, 8), dtype=bool)
    blocked[3, 1:7] = True
    grid = Grid(blocked, name="bar")
    result = skyroute.plan(grid, (0, 0), (7, 7))
    plot_grid_path(grid, result, (0, 0), (7, 7), tmp_path / "p.png")
    (fig,) = figures
    ax = fig.axes[0]
    legend = ax.get_legend()
    axes_box, legend_box = boxes(fig, ax, legend)
    assert legend_box.x0 >= axes_box.x1  # beside the map: it covers no path or goal
    texts = [t.get_text() for t in legend.get_texts()]
    assert texts == ["blocked", "path", "start (0, 0)", "goal (7, 7)"]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    for end in ("start (0, 0)", "goal (7, 7)"):  # a corner start was half cut off
        assert not lines[end].get_clip_on()
        assert lines[end].get_zorder() > lines["path"].get_zorder()
    assert ax.get_title() == (f"bar: astar, cost {result.cost:.3f} cells, "
                              f"{result.expanded:,} expanded")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (column)", "y (row)")
    assert ax.get_aspect() == 1.0


@pytest.mark.parametrize("resolution, cost", [(1.0, "cost 10.000 cells"),
                                               (0.5, "cost 10.000 cells (5.000 m)")])
def test_the_grid_title_gives_the_cost_s_unit(figures, tmp_path, resolution, cost):
    """It read "cost 10.000" with 0.5 m cells: cells or metres? As plan's table: cells,
    and metres where a cell is not 1 m."""
    grid = Grid(np.zeros((4, 12), dtype=bool), resolution=resolution, name="row")
    result = skyroute.plan(grid, (0, 1), (10, 1))
    plot_grid_path(grid, result, (0, 1), (10, 1), tmp_path / "p.png")
    assert figures[0].axes[0].get_title().replace("\n", ", ") == \
        f"row: astar, {cost}, {result.expanded:,} expanded"


@pytest.mark.parametrize("shape", [(12, 22), (4, 12), (81, 65)])
def test_grid_ticks_are_whole_cells(figures, tmp_path, shape):
    """A cell is a whole (x, y): the ticks of a small map read 2.5, 7.5, 12.5, ... (the
    22x12 raster of two 10 m walls at 0.5 m, `plan walls.csv --resolution 0.5 --plot`),
    places no cell is. Every tick is a whole number, on the map's axes."""
    grid = Grid(np.zeros(shape, dtype=bool), name="small")
    h, w = shape
    result = skyroute.plan(grid, (0, 0), (w - 1, h - 1))
    plot_grid_path(grid, result, (0, 0), (w - 1, h - 1), tmp_path / "p.png")
    ax = figures[0].axes[0]
    drawn(figures[0])
    for ticks, (lo, hi) in ((ax.get_xticks(), ax.get_xlim()),
                            (ax.get_yticks(), sorted(ax.get_ylim()))):
        shown = [t for t in ticks if lo <= t <= hi]
        assert len(shown) >= 2 and all(float(t).is_integer() for t in shown), ticks


def test_grid_picture_pixels_follow_the_map_size(tmp_path):
    """A 512x512 map gets about 4 pixels a cell (it was a 1,000-pixel thumbnail, 2 a
    cell, the maze's corridors lost under the path); a 32x32 map stays small."""
    rng = np.random.default_rng(0)
    for side, name in ((512, "big.png"), (32, "small.png")):
        blocked = rng.random((side, side)) < 0.1
        blocked[0, 0] = blocked[-1, -1] = False
        grid = Grid(blocked, name=name)
        result = PlanResult(Status.FOUND, np.array([[0.0, 0.0], [side - 1, side - 1]]),
                            1.0, algorithm="astar")
        plot_grid_path(grid, result, (0, 0), (side - 1, side - 1), tmp_path / name)
    w, h = png_size(tmp_path / "big.png")
    assert min(w, h) >= 4 * 512
    w, h = png_size(tmp_path / "small.png")
    assert max(w, h) <= 1300 and (tmp_path / "small.png").stat().st_size < 100_000
    assert grid_dpi((32, 32), (7, 7)) == 150 and grid_dpi((4096, 4096), (7, 7)) == 400


def test_a_graph_picture_is_a_palette_png_true_to_its_colours(figures, tmp_path):
    """A visibility graph's 2,500 thin translucent edges (already one LineCollection at
    150 dpi) blended into thousands of colours: 1.7 MB of RGBA. Written with one byte a
    pixel from a 256-colour palette, every colour within a few levels."""
    import io

    from PIL import Image

    rng = np.random.default_rng(0)
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.add_collection(LineCollection(rng.random((2500, 2, 2)), colors="tab:cyan",
                                     linewidths=0.3, alpha=0.5))
    draw_path(ax, [(0.1, 0.1), (0.9, 0.8)])
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png", dpi=150, bbox_inches="tight")  # as drawn, RGBA
    save_figure(fig, tmp_path / "g.png")
    data = (tmp_path / "g.png").read_bytes()
    assert data[25] == 3  # IHDR colour type 3: a palette image (6, RGBA, before)
    with Image.open(tmp_path / "g.png") as img, Image.open(buf) as rgba:
        assert img.mode == "P" and len(img.getcolors(256)) <= PALETTE_COLOURS
        ours = np.asarray(img.convert("RGB"), dtype=int)
        exact = np.asarray(rgba.convert("RGB"), dtype=int)
    assert ours.shape == exact.shape
    error = np.abs(ours - exact).max(axis=2)
    assert error.mean() < 3 and np.percentile(error, 99) <= 16
    assert (ours[0, 0] == 255).all()  # the common colours exact: the ground stays white


@pytest.mark.parametrize(("n", "marker"), [(60, "o"), (61, "None")])
def test_a_dense_trajectory_is_a_line_not_beads(n, marker):
    fig, ax = plt.subplots()
    draw_path(ax, np.c_[np.arange(n), np.zeros(n)])
    assert ax.get_lines()[0].get_marker() == marker
    plt.close(fig)


def test_world_picture_in_degrees_reads_plain_latitudes(figures, tmp_path):
    """``fly --vehicle step`` draws on the lon/lat plane: its latitudes were ticked as
    offsets from "+5.594e1"."""
    world = load_world(ROOT / "examples" / "city.csv", altitude=10).in_frame("degrees")
    a, b = (-3.1890, 55.9456), (-3.1850, 55.9432)
    result = skyroute.plan(world, a, b)
    world_out.plot_world_path(world, result, a, b, tmp_path / "w.png")
    (fig,) = figures
    ax = fig.axes[0]
    drawn(fig)
    assert ax.yaxis.get_major_formatter().get_offset() == ""
    assert ax.xaxis.get_major_formatter().get_offset() == ""
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("longitude (°)", "latitude (°)")
    assert ax.get_aspect() == pytest.approx(1 / np.cos(np.radians(55.944)), rel=1e-3)
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "start (lon -3.189, lat 55.9456)" in texts and "obstacles" in texts
    axes_box, legend_box = boxes(fig, ax, ax.get_legend())
    assert legend_box.x0 >= axes_box.x1
    assert ax.get_title() == f"city.csv: visibility, {result.cost:.6g} deg"


def test_world_picture_names_ned_points_by_their_axes(figures, tmp_path):
    world = load_world(ROOT / "examples" / "city.csv", altitude=10, frame="ned")
    start, goal = (0.0, 0.0), (120.0, -180.0)
    result = PlanResult(Status.FOUND, np.array([start, goal]), 216.3, algorithm="lattice")
    world_out.plot_world_path(world, result, start, goal, tmp_path / "w.png")
    ax = figures[0].axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "goal (north 120 m, east -180 m)" in texts
    # drawn in the plane: east to the right, north up
    goal_line = next(ln for ln in ax.get_lines() if ln.get_label().startswith("goal"))
    assert goal_line.get_xydata().tolist() == [[-180.0, 120.0]]
    assert ax.get_aspect() == 1.0 and ax.get_xlabel() == "east (m)"


def test_labels_of_close_points_keep_apart():
    """Five shops a few metres apart (the ILP data's): no name covers another, and none
    sits nearer another shop than its own."""
    pts = np.array([(-3.191065, 55.945626), (-3.191257, 55.945626), (-3.186103, 55.944656),
                    (-3.185236, 55.944709), (-3.185332, 55.944656), (-3.185300, 55.944680)])
    names = ["Rudis", "Greggs", "The Nile Valley", "The Picnic Basket", "Bing Tea", "Soup"]
    fig, ax = plt.subplots(figsize=(10, 6))
    ax.set_xlim(-3.1929, -3.1839)
    ax.set_ylim(55.9424, 55.9464)
    ax.plot(pts[:, 0], pts[:, 1], "s")
    anns = place_labels(ax, pts, names, fontsize=7)
    r = drawn(fig)
    bb = [Text.get_window_extent(a, r) for a in anns]  # the words, not a leader line
    for i in range(len(bb)):
        for j in range(i):
            assert not bb[i].overlaps(bb[j]), (names[i], names[j])
    centre = ax.transData.transform(pts)
    for k, (a, b) in enumerate(zip(anns, bb, strict=True)):
        if a.arrow_patch is not None:  # a leader line says whose label it is
            continue
        d = [np.hypot(max(b.x0 - x, 0, x - b.x1), max(b.y0 - y, 0, y - b.y1))
             for x, y in centre]
        assert int(np.argmin(d)) == k or d[k] == min(d), names[k]
    plt.close(fig)


def title_fits(fig, ax) -> list[str]:
    """The title's lines, once checked to lie within the figure's width."""
    title = ax.title
    box = Text.get_window_extent(title, drawn(fig))
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width, title.get_text()
    return title.get_text().split("\n")


def test_pruned_grid_path_says_so_in_the_title(figures, tmp_path):
    grid = skyroute.load_map("den312d")
    result = skyroute.plan(grid, (50, 76), (60, 13), algorithm="theta", prune="los")
    plot_grid_path(grid, result, (50, 76), (60, 13), tmp_path / "p.png", prune="los")
    fig = figures[0]
    lines = title_fits(fig, fig.axes[0])
    # balanced: it read "...cost 110.179, 1,587 expanded" over "pruned (los): 5 waypoints"
    assert lines == [f"den312d.map: theta, cost {result.cost:.3f} cells",
                     f"{result.expanded:,} expanded, pruned (los): {len(result.path)} waypoints"]


def test_a_long_title_on_a_narrow_map_takes_two_lines_within_the_figure(figures, tmp_path):
    blocked = np.zeros((60, 8), dtype=bool)  # tall and narrow: the narrowest figure
    grid = Grid(blocked, name="a_rather_long_name_for_a_narrow_map.map")
    result = skyroute.plan(grid, (0, 0), (7, 59), prune="collinear")
    plot_grid_path(grid, result, (0, 0), (7, 59), tmp_path / "p.png", prune="collinear")
    fig = figures[0]
    lines = title_fits(fig, fig.axes[0])
    # no two lines fit over the map: three even ones, not the name over all the rest
    assert lines == ["a_rather_long_name_for_a_narrow_map.map: astar",
                     f"cost {result.cost:.3f} cells, {result.expanded:,} expanded",
                     f"pruned (collinear): {len(result.path)} waypoints"]


@pytest.mark.parametrize(("room", "lines"), [
    (80, ["den312d.map: theta, cost 110.179, 1,587 expanded, pruned (los): 5 waypoints"]),
    # the cut nearest the middle, not as much as fits on the first line
    (50, ["den312d.map: theta, cost 110.179", "1,587 expanded, pruned (los): 5 waypoints"]),
    (41, ["den312d.map: theta, cost 110.179", "1,587 expanded, pruned (los): 5 waypoints"]),
    (40, ["den312d.map: theta", "cost 110.179, 1,587 expanded", "pruned (los): 5 waypoints"]),
    (28, ["den312d.map: theta", "cost 110.179, 1,587 expanded", "pruned (los): 5 waypoints"]),
    # narrower than any part: the fewest lines as narrow as whole parts allow
    (10, ["den312d.map: theta", "cost 110.179", "1,587 expanded", "pruned (los): 5 waypoints"]),
])
def test_title_lines_are_balanced(room, lines):
    parts = ["den312d.map: theta", "cost 110.179", "1,587 expanded", "pruned (los): 5 waypoints"]
    assert title_lines(parts, room) == lines


def test_title_lines_keep_the_timeline_sentence_whole():
    parts = ["seed-9x9: seed dispatch", "layers airspace", "1 h", "seed 0",
             "63 of 109 packages delivered after the 6 min warm-up; 66 of 124 in the whole run"]
    assert title_lines(parts, 100) == [", ".join(parts[:4]), parts[4]]
    assert title_lines(["Delivery day 03 Jan 2022: 4/4 orders", "100.0% of the money",
                        "220 moves"], 40) == ["Delivery day 03 Jan 2022: 4/4 orders",
                                              "100.0% of the money, 220 moves"]
    assert title_lines(["a", "b"], 1, width=lambda t: 0) == ["a, b"]


def test_grid_legend_says_the_blocked_cells_are_grown_by_the_safety_margin(figures, tmp_path):
    grid = skyroute.load_map("den312d", safety=1.5)
    result = skyroute.plan(grid, (61, 77), (20, 3))
    plot_grid_path(grid, result, (61, 77), (20, 3), tmp_path / "p.png", safety=1.5)
    texts = [t.get_text() for t in figures[0].axes[0].get_legend().get_texts()]
    assert texts[0] == "blocked, grown by 1.5 m"
    assert figures[0].axes[0].get_title().count("\n") == 0  # not pruned: one line


@pytest.mark.parametrize(("altitude", "safety", "frame", "label"), [
    (10, 2, "ned", "obstacles at 10 m, grown by 2 m"),
    (10.5, 0, "lonlat", "obstacles at 10.5 m"),
    (None, 0, "enu", "obstacles at all altitudes"),
    (None, 2e-05, "degrees", "obstacles at all altitudes, grown by 2e-05 deg"),
])
def test_obstacles_label_names_altitude_and_margin(altitude, safety, frame, label):
    assert world_out.obstacles_label(altitude, safety, frame) == label


def _legend(fig) -> list[str]:
    return [t.get_text() for t in fig.axes[0].get_legend().get_texts()]


CITY = str(ROOT / "examples" / "city.csv")


def test_plan_world_plot_names_altitude_and_safety(monkeypatch, capsys, figures, tmp_path):
    from tests.cli.test_cli import run

    code, _, err = run(monkeypatch, capsys, "plan-world", CITY, "--frame", "ned", "--start",
                       "0,0", "--goal", "120,-180", "--altitude", "10", "--safety", "2",
                       "--algorithm", "astar", "--resolution", "2", "--plot",
                       str(tmp_path / "w.png"))
    assert code == 0, err
    (fig,) = figures
    assert _legend(fig)[0] == "obstacles at 10 m, grown by 2 m"
    assert title_fits(fig, fig.axes[0]) == [fig.axes[0].get_title()]


def test_fly_step_plot_gives_the_margin_in_metres(monkeypatch, capsys, figures, tmp_path):
    """The step drone flies on the lon/lat plane, but --safety grew the city in metres."""
    from tests.cli.test_cli import run

    code, _, err = run(monkeypatch, capsys, "fly", CITY, "--vehicle", "step",
                       "--start=-3.1890,55.9456", "--goal=-3.1850,55.9432", "--safety", "2",
                       "--plot", str(tmp_path / "s.png"))
    assert code == 0, err
    assert _legend(figures[0])[0] == "obstacles at all altitudes, grown by 2 m"


def test_plan_prune_plot_from_the_command_line(monkeypatch, capsys, figures, tmp_path):
    from tests.cli.test_cli import run

    code, _, err = run(monkeypatch, capsys, "plan", "den312d", "--start", "50,76", "--goal",
                       "60,13", "--algorithm", "theta", "--prune", "los", "--plot",
                       str(tmp_path / "p.png"))
    assert code == 0, err
    assert figures[0].axes[0].get_title().endswith("expanded, pruned (los): 5 waypoints")


@pytest.mark.parametrize("vehicle, args", [
    # the step drone stops within a step (0.00015 degrees) of the goal, the lattice at
    # the centre of the free cell nearest it: the star was drawn there and named so
    ("step", ["--start=-3.1890,55.9456", "--goal=-3.1850,55.9432"]),
    ("lattice", ["--frame", "ned", "--start", "0,0", "--goal", "120,-180", "--resolution",
                 "5"]),
])
def test_fly_plot_marks_the_goal_as_typed(monkeypatch, capsys, figures, tmp_path, vehicle,
                                          args):
    from tests.cli.test_cli import run

    code, _, err = run(monkeypatch, capsys, "fly", CITY, "--vehicle", vehicle, "--altitude",
                       "10", "--safety", "2", *args, "--plot", str(tmp_path / "f.png"))
    assert code == 0, err
    goal = [t for t in _legend(figures[0]) if t.startswith("goal")]
    assert goal == (["goal (lon -3.185, lat 55.9432)"] if vehicle == "step" else
                    ["goal (north 120 m, east -180 m)"])
    star = [ln for ln in figures[0].axes[0].get_lines() if ln.get_label().startswith("goal")]
    if vehicle == "step":  # drawn on the lon/lat plane
        world = skyroute.load_world(CITY, altitude=10, safety=2).in_frame("degrees")
        typed = (-3.185, 55.9432)
    else:
        world, typed = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned"), (120, -180)
    np.testing.assert_allclose(np.ravel(star[0].get_xydata())[:2],
                               world.to_plane(np.array([typed], dtype=float))[0], atol=1e-9)


def test_fly_tour_plot_numbers_the_targets_and_draws_no_goal(monkeypatch, capsys, figures,
                                                             tmp_path):
    """A tour has no goal: its last target was drawn as one ("goal (north -60 m, ...)"),
    and the others not at all."""
    from tests.cli.test_cli import run

    targets = tmp_path / "t.csv"
    targets.write_text("north,east\n60,30\n-60,60\n0,-120\n")
    code, _, err = run(monkeypatch, capsys, "fly", CITY, "--frame", "ned", "--vehicle",
                       "dubins", "--altitude", "10", "--safety", "2", "--radius", "8",
                       "--start", "0,0,0", "--targets", str(targets), "--plot",
                       str(tmp_path / "t.png"))
    assert code == 0, err
    legend = _legend(figures[0])
    assert "targets (3), numbered as given" in legend
    assert not [t for t in legend if t.startswith("goal")]
    ax = figures[0].axes[0]
    assert sorted(t.get_text() for t in ax.texts) == ["1", "2", "3"]
    (marks,) = [ln for ln in ax.get_lines() if ln.get_label().startswith("targets")]
    world = skyroute.load_world(CITY, altitude=10, safety=2, frame="ned")
    np.testing.assert_allclose(marks.get_xydata(),
                               world.to_plane(np.array([[60, 30], [-60, 60], [0, -120]])))


def test_writing_a_picture_keeps_the_callers_backend_and_figures(tmp_path):
    """Each picture writer called ``matplotlib.use("Agg")``: from a notebook (its inline
    backend) or a script on another backend, writing a --plot picture from Python
    switched the caller's backend to Agg, and its later figures no longer showed.
    (Every writer makes its figure by ``new_figure``; the grid's stands for them.)"""
    old = matplotlib.get_backend()
    plt.switch_backend("svg")  # stands for a notebook's or a desktop's backend
    try:
        mine = plt.figure()
        figures = plt.get_fignums()
        grid = Grid(np.zeros((4, 4), dtype=bool), name="open")
        plot_grid_path(grid, skyroute.plan(grid, (0, 0), (3, 3)), (0, 0), (3, 3),
                       tmp_path / "grid.png")
        assert matplotlib.get_backend() == "svg"
        assert plt.get_fignums() == figures  # skyroute's figure never joined pyplot's
    finally:
        plt.close(mine)
        plt.switch_backend(old)
    assert min(png_size(tmp_path / "grid.png")) > 100


def test_a_grid_and_its_path_drawn_on_the_callers_axes():
    """What ``plan --plot`` draws, onto an Axes of the caller's (one panel of several,
    on a backend with no renderer of its own), the figure's size left alone."""
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure

    blocked = np.zeros((6, 9), dtype=bool)
    blocked[1:5, 4] = True
    grid = Grid(blocked, name="wall")
    r = skyroute.plan(grid, (1, 3), (7, 3))
    fig = Figure(figsize=(8, 3))
    FigureCanvasSVG(fig)
    left, right = fig.subplots(1, 2)
    assert draw_grid_path(right, grid, r, (1, 3), (7, 3)) is right
    assert tuple(fig.get_size_inches()) == (8, 3) and not left.has_data()
    np.testing.assert_array_equal(right.images[0].get_array(), blocked)  # [row, column]
    lines = {ln.get_label(): ln for ln in right.get_lines()}
    np.testing.assert_array_equal(np.c_[lines["path"].get_data()], r.path)  # (x, y) cells
    assert {"start (1, 3)", "goal (7, 3)", "blocked"} <= set(lines)
    assert right.get_title().replace("\n", ", ") == \
        f"wall: astar, cost {r.cost:.3f} cells, {r.expanded:,} expanded"
    assert right.get_ylim() == (5.5, -0.5)  # y (row) down, as MovingAI counts
    bare = draw_grid_path(left, grid)  # the map alone
    assert bare.get_title() == "wall" and [ln.get_label() for ln in bare.get_lines()] == \
        ["blocked"]


def test_a_world_path_drawn_on_the_callers_axes_is_in_its_plane():
    """A "ned" world's (north, east) path is drawn as (east, north) metres, true
    proportions, start and goal named as typed."""
    from matplotlib.figure import Figure

    world = load_world(str(ROOT / "examples" / "city.csv"), altitude=10, safety=2,
                       frame="ned")
    r = skyroute.plan(world, (0, 0), (120, -180))
    ax = world_out.draw_world_path(Figure().subplots(), world, r, (0, 0), (120, -180))
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    np.testing.assert_allclose(np.c_[lines["path"].get_data()], r.path[:, ::-1])
    assert "goal (north 120 m, east -180 m)" in lines
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_aspect()) == ("east (m)", "north (m)",
                                                                   1.0)
    assert ax.get_legend() is None  # the caller's to place
