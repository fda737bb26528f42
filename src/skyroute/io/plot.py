"""PNG pictures of maps and paths (matplotlib, imported only when a plot is asked for),
and the conventions every map picture shares: start and goal drawn on top and never cut
by the frame, the legend outside the map, labels that keep out of each other's way.

From Python, :func:`draw_grid_path` draws a grid and a path onto a matplotlib Axes of
the caller's (``skyroute.io.world_out.draw_world_path`` a World's); the ``plot_*``
functions write the pictures the CLI's ``--plot`` writes. Figures are made without
pyplot (:func:`new_figure`): a picture written from a notebook or a script neither
switches its backend nor joins its pyplot figures.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Sequence
from itertools import combinations, pairwise
from pathlib import Path

import numpy as np

from skyroute.files import write_atomic
from skyroute.result import PlanResult
from skyroute.world.grid import Grid

DPI = 150
MAX_DPI = 400  # a 512x512 map: about 2,300 pixels a side
CELL_PIXELS = 4  # a grid picture gives each cell at least this many pixels, up to MAX_DPI
DOTS_UP_TO = 60  # a path's points are marked when it has at most this many
PALETTE_COLOURS = 256  # every picture is written as an 8-bit palette PNG
SNAP = 8  # a common colour replaces the palette entry within this many levels of it
BLOCKED_GREY = 1 / 1.4  # blocked cells' shade on the "Greys" map (vmax 1.4: not black)


def new_figure(figsize: tuple[float, float], nrows: int = 1, ncols: int = 1, **kw):
    """``(figure, axes)`` for a picture written to a file: a matplotlib ``Figure`` with
    an Agg canvas of its own, made without pyplot. Each writer called
    ``matplotlib.use("Agg")`` and ``pyplot.subplots``, which switched a notebook's or a
    script's backend to Agg under it (its later figures no longer showed) and was
    pyplot's global state in threads; ``kw`` goes to ``Figure.subplots``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **kw)


def renderer_of(fig):
    """A renderer to measure text with: the figure's canvas's (Agg and the interactive
    backends built on it), else a detached Agg renderer of the figure's size and dpi
    (a caller's figure on the svg or pdf backend has none)."""
    get = getattr(fig.canvas, "get_renderer", None)
    if get is not None:
        return get()
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(int(fig.bbox.width), int(fig.bbox.height), fig.dpi)


def plot_grid_path(grid: Grid, result: PlanResult, start: tuple[int, int],
                   goal: tuple[int, int], path: str | Path, *, dpi: int | None = None,
                   prune: str = "none", safety: float = 0.0) -> Path:
    """Write the PNG ``skyroute plan --plot`` writes: :func:`draw_grid_path` on a figure
    sized to the map, the legend beside it. ``dpi`` defaults to :func:`grid_dpi`: large
    maps get the pixels their cells need."""
    h, w = grid.blocked.shape
    size = 7.0
    area = (size * min(1.6, max(0.6, w / h)), size)  # the map's, inches
    dpi = grid_dpi(grid.blocked.shape, area) if dpi is None else dpi
    fig, ax = new_figure(area)
    # A line no wider than a cell (in points), so a corridor of a maze stays visible.
    cell_pt = 72 * _cell_inches(grid.blocked.shape, area)
    draw_grid_path(ax, grid, result, start, goal, prune=prune, safety=safety,
                   lw=float(np.clip(cell_pt, 0.6, 1.6)))
    legend_outside(ax)
    return save_figure(fig, path, dpi=dpi)


def draw_grid_path(ax, grid: Grid, result: PlanResult | None = None,
                   start: tuple[int, int] | None = None, goal: tuple[int, int] | None = None,
                   *, prune: str = "none", safety: float = 0.0, lw: float = 1.6):
    """Draw a grid (blocked cells dark), and a result's path with its start (green dot)
    and goal (red star) when given, onto a matplotlib Axes: what ``skyroute plan
    --plot`` draws. Returns ``ax``.

    Axes are cell coordinates: x to the right (column), y down (row), as MovingAI counts
    them and ``plan`` takes them; a cell's centre is at its (x, y) (multiply by
    ``grid.resolution`` and add ``grid.origin`` for metres, :meth:`Grid.to_world`).
    The title says the map, algorithm, cost and expansions; the artists are labelled
    for ``ax.legend()``. ``prune`` and ``safety`` are what the path and the grid were
    made with: the title says how a path was pruned ("pruned (los): 5 waypoints"), the
    legend that the blocked cells include the margin ("blocked, grown by 1.5 m").

    >>> import skyroute
    >>> from matplotlib.figure import Figure
    >>> grid = skyroute.load_map("den312d")
    >>> r = skyroute.plan(grid, (50, 76), (60, 13))
    >>> ax = draw_grid_path(Figure().subplots(), grid, r, (50, 76), (60, 13))
    >>> ax.get_title().splitlines(), ax.get_xlabel()  # the title fits the axes' width
    (['den312d.map: astar', 'cost 112.556 cells, 1,497 expanded'], 'x (column)')
    """
    from matplotlib import colormaps

    h, w = grid.blocked.shape
    ax.imshow(grid.blocked, cmap="Greys", vmin=0, vmax=1.4, interpolation="nearest",
              extent=(-0.5, w - 0.5, h - 0.5, -0.5))
    ax.plot([], [], "s", color=colormaps["Greys"](BLOCKED_GREY), ms=7,
            label="blocked" + (f", grown by {safety:g} m" if safety > 0 else ""))
    if result is not None and result.found:
        draw_path(ax, result.path, lw=lw)
    if start is not None:
        mark_ends(ax, start, goal, start_text=_cell(start),
                  goal_text="" if goal is None else _cell(goal))
    parts = [grid.name]
    if result is not None:
        parts = [f"{grid.name}: {result.algorithm}", _grid_cost(grid, result),
                 f"{result.expanded:,} expanded"]
        if prune != "none" and result.found:
            parts.append(f"pruned ({prune}): {len(result.path)} waypoints")
    set_title(ax, parts)
    ax.set_xlabel("x (column)")
    ax.set_ylabel("y (row)")
    # cells are whole numbers: a small map's ticks read 2.5, 7.5, ... (a 22x12 walls
    # raster), places no cell is
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    return ax


def set_title(ax, parts: Sequence[str], *, fontsize: float = 10):
    """The title of every picture: ``parts`` joined by ", " on as few lines as fit the
    axes' width, broken where the lines come out most even (:func:`title_lines`), so a
    long title (a pruned path's, on a narrow map) stays over the map. Returns the
    title."""
    from matplotlib.font_manager import FontProperties

    fig = ax.figure
    renderer = renderer_of(fig)
    font = FontProperties(size=fontsize)
    room = ax.get_position().width * fig.bbox.width  # pixels

    def width(text: str) -> float:
        return renderer.get_text_width_height_descent(text, font, ismath=False)[0]

    return ax.set_title("\n".join(title_lines(parts, room, width)), fontsize=fontsize)


def _grid_cost(grid: Grid, result: PlanResult) -> str:
    """The title's cost in cells (octile steps), as ``skyroute plan``'s table has it, and
    in metres too where a cell is not 1 m ("cost 10.000 cells (5.000 m)"); it read
    "cost 10.000", in no unit. The status when no path was found."""
    if not result.found:
        return result.status.value
    cost = f"cost {result.cost:,.3f} cells"
    if grid.resolution != 1:
        cost += f" ({result.cost * grid.resolution:,.3f} m)"
    return cost


def title_lines(parts: Sequence[str], room: float,
                width: Callable[[str], float] = len) -> list[str]:
    """``parts`` joined by ", " into the fewest lines no wider than ``room`` (as
    ``width`` measures a line; characters by default), cut where the longest line is
    shortest (and then the shortest longest): "a_long_map.map: theta, cost 110.179" over
    "1,587 expanded, pruned (los): 5 waypoints", not the first three parts over the
    last. A part is never cut; when no number of lines fits, the fewest lines that are
    as narrow as whole parts allow.

    >>> title_lines(["map: astar", "cost 12.5", "40 expanded", "pruned: 3 waypoints"], 32)
    ['map: astar, cost 12.5', '40 expanded, pruned: 3 waypoints']
    """
    parts = list(parts)
    best, best_width = [", ".join(parts)], math.inf
    for n in range(1, len(parts) + 1):
        splits = ([", ".join(parts[a:b]) for a, b in pairwise((0, *cuts, len(parts)))]
                  for cuts in combinations(range(1, len(parts)), n - 1))
        lines = min(splits, key=lambda ls: (max(map(width, ls)), -min(map(width, ls))))
        widest = max(map(width, lines))
        if widest <= room:
            return lines
        if widest < best_width:
            best, best_width = lines, widest
    return best


def grid_dpi(shape: tuple[int, int], figsize: tuple[float, float]) -> int:
    """The resolution that gives each cell of a map of ``shape`` (rows, columns) drawn
    on a figure of ``figsize`` inches about :data:`CELL_PIXELS` pixels: :data:`DPI` for
    small maps (a 32x32 map stays a small file), up to :data:`MAX_DPI` for large ones."""
    return int(np.clip(np.ceil(CELL_PIXELS / _cell_inches(shape, figsize)), DPI, MAX_DPI))


def _cell_inches(shape: tuple[int, int], figsize: tuple[float, float]) -> float:
    """A cell's side in inches when a map of ``shape`` fills the axes (about 80%) of a
    figure of ``figsize``."""
    h, w = shape
    return min(figsize[0] * 0.8 / w, figsize[1] * 0.8 / h)


def _cell(c) -> str:
    return f"({int(c[0])}, {int(c[1])})"


def draw_path(ax, points, *, lw: float = 1.6, label: str = "path") -> None:
    """A path as a line above the map, its points marked when there are few of them
    (a densely sampled trajectory would be drawn as a thick string of beads)."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    dots = len(p) <= DOTS_UP_TO
    ax.plot(p[:, 0], p[:, 1], "-o" if dots else "-", color="tab:blue", lw=lw, ms=3,
            label=label, zorder=4)


def mark_ends(ax, start, goal, *, start_text: str = "", goal_text: str = "") -> None:
    """Start (green dot) and goal (red star) above everything else and not clipped by
    the frame (a start in a map's corner was half cut off); each legend entry names its
    point. A goal of None (a tour, which ends at its last target) draws no star."""
    ends = [(start, "o", "tab:green", 9, "start", start_text)]
    if goal is not None:
        ends.append((goal, "*", "tab:red", 14, "goal", goal_text))
    for xy, marker, colour, ms, name, text in ends:
        ax.plot(*np.asarray(xy, dtype=float)[:2], marker, color=colour, ms=ms,
                markeredgecolor="white", markeredgewidth=0.8, clip_on=False, zorder=6,
                label=f"{name} {text}".strip())


def legend_outside(ax, **kw):
    """The legend beside the axes (right, top aligned), so it never covers the map; the
    figure is widened by the legend's width, so the map keeps its size. Returns it."""
    fig = ax.figure
    legend = ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8,
                       borderaxespad=0, **kw)
    width = legend.get_window_extent(renderer_of(fig)).width / fig.dpi
    w, h = fig.get_size_inches()
    fig.set_size_inches(w + width + 0.1, h)
    return legend


def place_labels(ax, points, texts, *, avoid=(), fontsize: float = 8,
                 marker_pt: float = 4.0, **style) -> list:
    """Annotate ``points`` (data coordinates) with ``texts`` where each label overlaps
    least the labels already placed, the other points and the markers at ``avoid``, on
    a white box so a line under it stays readable.

    Eight places right beside the point are tried first (right, above, below, left);
    one that would sit nearer another of ``points`` than its own reads as that point's
    label, so it counts as half covered. When none is clear, a label may go a little further
    out with a thin leader line to its point. Call it last, once the axes' limits,
    aspect and legend are set (it lays the figure out to measure the labels). Returns
    the annotations."""
    from matplotlib.text import Text

    fig = ax.figure
    fig.tight_layout()
    ax.apply_aspect()
    renderer = renderer_of(fig)
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    others = np.asarray(avoid, dtype=float).reshape(-1, 2)
    r = marker_pt * fig.dpi / 72.0  # a marker's half width in pixels
    centre = ax.transData.transform(np.vstack([pts, others]))
    taken = [(x - r, y - r, x + r, y + r) for x, y in centre]
    box = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.75}
    style = {"fontsize": fontsize, "bbox": box, "zorder": 7, **style}
    out = []
    for k, ((x, y), text) in enumerate(zip(pts, texts, strict=True)):
        best = None
        for rank, (dx, dy, lead) in enumerate(_PLACES):
            extra = {"arrowprops": {"arrowstyle": "-", "lw": 0.6, "color": "0.3",
                                    "shrinkA": 0, "shrinkB": 2}} if lead else {}
            ann = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                              ha="left" if dx > 0 else "right" if dx < 0 else "center",
                              va="bottom" if dy > 0 else "top" if dy < 0 else "center",
                              **style, **extra)
            ann.update_positions(renderer)
            e = Text.get_window_extent(ann, renderer)  # the words, not the leader line
            bb = (e.x0, e.y0, e.x1, e.y1)
            cost = sum(_overlap(bb, t) for i, t in enumerate(taken) if i != k)
            if not lead and _nearer_other(bb, centre[:len(pts)], k, 3 * r):
                cost += 0.5 * (bb[2] - bb[0]) * (bb[3] - bb[1])
            cost += rank * 1e-6  # ties go to the nearer, more usual place
            if best is None or cost < best[0]:
                if best is not None:
                    best[1].remove()
                best = (cost, ann, bb)
            else:
                ann.remove()
            if cost < 1e-3:
                break
        taken.append(best[2])
        out.append(best[1])
    return out


_NEAR, _FAR = 5, 16  # points from the marker to its label (_FAR: with a leader line)
_PLACES = tuple((dx * d, dy * d, d == _FAR) for d in (_NEAR, _FAR)
                for dx, dy in ((1, 1), (1, -1), (0, 1.4), (0, -1.4), (-1, 1), (-1, -1),
                               (1.4, 0), (-1.4, 0)))


def _nearer_other(bb, centre: np.ndarray, k: int, within: float) -> bool:
    """Whether another point lies within ``within`` pixels of box ``bb`` and nearer to
    it than point ``k``: a reader would take the label for that point's."""
    dx = np.maximum(np.maximum(bb[0] - centre[:, 0], centre[:, 0] - bb[2]), 0)
    dy = np.maximum(np.maximum(bb[1] - centre[:, 1], centre[:, 1] - bb[3]), 0)
    d = np.hypot(dx, dy)
    own = d[k]
    d[k] = np.inf
    return bool((d < within).any() and d.min() < own + 1.0)


def _overlap(a, b) -> float:
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > 0 and h > 0 else 0.0


def save_figure(fig, path: str | Path, *, dpi: int = DPI) -> Path:
    """Render a matplotlib figure to PNG (cropped to everything drawn, legends beside the
    axes included) and write the file whole, as a palette image (:func:`palette_png`).
    The figure is :func:`new_figure`'s, in no pyplot list: nothing to close."""
    buf = io.BytesIO()
    fig.tight_layout()
    # "tight" takes in what tight_layout leaves out: a legend placed beside the axes
    # (fleet map.png, the day's map) was clipped at the image's right edge.
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return write_atomic(path, palette_png(buf.getvalue()))


def palette_png(png: bytes) -> bytes:
    """An opaque PNG as an 8-bit palette PNG of at most :data:`PALETTE_COLOURS` colours.

    Thin anti-aliased lines over a map (a visibility graph's 2,500 edges, a fleet's
    tracks) blend into thousands of colours, a few pixels each, which zlib packs badly
    in 4 bytes a pixel: 1.7 MB for a 6x6-block city. Matplotlib already draws the edges
    as one collection at 150 dpi; it is the pixels, not the artists, that cost. One byte
    a pixel from an adaptive palette (Pillow's fast octree, no dithering) makes such a
    picture 3-5 times smaller, within a few levels of every colour; the most common
    colours (the white ground, the greys, the markers' colours) stay exact."""
    from PIL import Image

    with Image.open(io.BytesIO(png)) as img:
        rgb = img.convert("RGB")
    small = rgb.quantize(PALETTE_COLOURS, method=Image.Quantize.FASTOCTREE,
                         dither=Image.Dither.NONE)
    small.putpalette(_exact_palette(small.getpalette()[:3 * PALETTE_COLOURS],
                                    rgb.getcolors(rgb.width * rgb.height)))
    out = io.BytesIO()
    small.save(out, format="png")
    return out.getvalue()


def _exact_palette(palette: list[int], colours: list[tuple[int, tuple]]) -> list[int]:
    """``palette`` (flat RGB) with each of the most common ``colours`` ((count, rgb), as
    Pillow counts them) put in place of the entry nearest it, where that entry is its
    octree average (within :data:`SNAP` levels): the octree's mean of white and its
    anti-aliased neighbours was (254, 254, 254), a grey frame round every picture."""
    pal = np.array(palette, dtype=float).reshape(-1, 3)
    taken = np.zeros(len(pal), dtype=bool)
    for _, rgb in sorted(colours, key=lambda c: -c[0])[:PALETTE_COLOURS // 4]:
        d = np.abs(pal - rgb).max(axis=1)
        d[taken] = np.inf
        k = int(d.argmin())
        if d[k] <= SNAP:
            pal[k], taken[k] = rgb, True
    return pal.astype(int).ravel().tolist()
