"""PNG pictures of maps and paths (matplotlib, imported only when a plot is asked for)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from skyroute.files import write_atomic
from skyroute.result import PlanResult
from skyroute.world.grid import Grid


def plot_grid_path(grid: Grid, result: PlanResult, start: tuple[int, int],
                   goal: tuple[int, int], path: str | Path, *, dpi: int = 150) -> Path:
    """Draw the grid (blocked cells dark), the path, start (green) and goal (red).

    Axes are cell coordinates (x to the right, y down, as MovingAI counts them).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h, w = grid.blocked.shape
    size = 7.0
    fig, ax = plt.subplots(figsize=(size * min(1.6, max(0.6, w / h)), size))
    ax.imshow(grid.blocked, cmap="Greys", vmin=0, vmax=1.4, interpolation="nearest",
              extent=(-0.5, w - 0.5, h - 0.5, -0.5))
    if result.found:
        p = np.asarray(result.path)
        ax.plot(p[:, 0], p[:, 1], "-", color="tab:blue", lw=1.6, label="path")
        if len(p) <= 60:
            ax.plot(p[:, 0], p[:, 1], ".", color="tab:blue", ms=4)
    ax.plot(*start, "o", color="tab:green", ms=8, label="start")
    ax.plot(*goal, "*", color="tab:red", ms=12, label="goal")
    cost = f"cost {result.cost:.3f}" if result.found else result.status.value
    ax.set_title(f"{grid.name}: {result.algorithm}, {cost}, {result.expanded} expanded",
                 fontsize=10)
    ax.set_xlabel("x (column)")
    ax.set_ylabel("y (row)")
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    return save_figure(fig, path, dpi=dpi)


def save_figure(fig, path: str | Path, *, dpi: int = 150) -> Path:
    """Render a matplotlib figure to PNG (cropped to everything drawn, legends beside the
    axes included), close it, and write the file whole."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.tight_layout()
    # "tight" takes in what tight_layout leaves out: a legend placed beside the axes
    # (fleet map.png, the day's map) was clipped at the image's right edge.
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return write_atomic(path, buf.getvalue())
