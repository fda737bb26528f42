"""The result vocabulary every planner shares: :class:`Status`, the compiled kernels'
status codes, and :class:`PlanResult` (grid and world paths).

Other planners keep their own result types for their own fields (a step-drone
``Flight``, a lattice ``LatticeResult``, a potential-field ``FieldRun``, a Dubins
``DubinsPath``), and every one of them carries ``status`` from this enum.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
from numba import njit


class Status(StrEnum):
    """How a search ended. Finding no path is a status, not an exception."""

    FOUND = "found"
    NO_PATH = "no_path"
    BUDGET_EXHAUSTED = "budget_exhausted"
    #: a reactive method (potential field, waypoint following) stopped short of the goal
    #: with no way on; a path may still exist
    STUCK = "stuck"


_new = object.__new__

# Kernel status codes, shared by every compiled search (index into STATUS_OF_CODE).
FOUND, NO_PATH, BUDGET_EXHAUSTED, STUCK = 0, 1, 2, 3
STATUS_OF_CODE = (Status.FOUND, Status.NO_PATH, Status.BUDGET_EXHAUSTED, Status.STUCK)


@njit(cache=True)
def stop_code(c, goal, expanded, max_expansions):
    """A kernel's stop test when it takes node c: FOUND, BUDGET_EXHAUSTED, or -1 (go on)."""
    if c == goal:
        return FOUND
    if expanded >= max_expansions:
        return BUDGET_EXHAUSTED
    return -1


@dataclass(frozen=True, eq=False)
class PlanResult:
    """What a planner found and what it cost to find it.

    ``path`` is a (K, 2) float array of points, empty unless ``status`` is ``found``: on
    a grid, (x, y) cells (cell centres, as MovingAI counts them); on a World, points in
    the world's frame (``extra["frame"]``), with ``path_lonlat`` the same points as
    (lon, lat) where the world has a home. ``cost`` is the path's length (cells, with
    diagonal steps sqrt 2, on a grid; plane units, metres or degrees, on a World);
    ``inf`` when no path was found; a start equal to the goal is a path of that one point,
    cost 0, from every planner. ``expanded`` counts nodes taken off the open list and
    expanded (for PRM: roadmap nodes Dijkstra settled up to the goal), ``max_frontier``
    the largest open list, ``los_checks`` line-of-sight (segment) tests, and ``seconds``
    the wall time of the search itself.

    Results compare and hash by identity (each is the record of one run, and two runs
    differ in ``seconds`` anyway): compare ``status``, ``cost`` and ``path`` instead.
    """

    status: Status
    path: np.ndarray
    cost: float
    expanded: int = 0
    max_frontier: int = 0
    los_checks: int = 0
    seconds: float = 0.0
    algorithm: str = ""
    extra: dict = field(default_factory=dict)
    path_lonlat: np.ndarray | None = None

    @classmethod
    def of_search(cls, status: Status, path: np.ndarray, cost: float, expanded: int,
                  max_frontier: int, los_checks: int, seconds: float, algorithm: str,
                  extra: dict) -> PlanResult:
        """A grid query's result, its fields written straight into the instance's
        ``__dict__``: the frozen ``__init__`` sets each through ``object.__setattr__``,
        about a microsecond, a tenth of a small map's query. Same type, same fields, the
        same object ``__init__`` would make."""
        r = _new(cls)
        d = r.__dict__  # item by item: no keyword dict to build first (about 0.1 us less)
        d["status"] = status
        d["path"] = path
        d["cost"] = cost
        d["expanded"] = expanded
        d["max_frontier"] = max_frontier
        d["los_checks"] = los_checks
        d["seconds"] = seconds
        d["algorithm"] = algorithm
        d["extra"] = extra
        d["path_lonlat"] = None
        return r

    def __repr__(self) -> str:
        """A summary: the status, cost, path size and the statistics (``path`` holds
        the points)."""
        cost = f", cost {self.cost:.6g}" if self.status is Status.FOUND else ""
        checks = f", {self.los_checks} line-of-sight checks" if self.los_checks else ""
        return (f"<PlanResult {self.status.value}{cost}, {len(self.path)} points, "
                f"{self.algorithm or 'planner'}: {self.expanded} expanded, "
                f"frontier {self.max_frontier}{checks}, {self.seconds * 1e3:.3g} ms>")

    @property
    def found(self) -> bool:
        """True when a path was found."""
        return self.status is Status.FOUND

    def to_dict(self) -> dict:
        """Plain JSON-ready data, in the CLI's ``--json`` field order."""
        return {
            "status": self.status.value,
            "cost": float(self.cost) if self.found else None,
            "path": self.path.tolist(),
            "expanded": int(self.expanded),
            "max_frontier": int(self.max_frontier),
            "los_checks": int(self.los_checks),
            "seconds": float(self.seconds),
            "algorithm": self.algorithm,
            **({"path_lonlat": self.path_lonlat.tolist()}
               if self.path_lonlat is not None else {}),
        }

