"""Grid search: BFS, Dijkstra, A*, JPS, Theta*, Lazy Theta*, pruning; one PlanResult."""

from skyroute.search.grid_plan import GRID_ALGORITHMS
from skyroute.search.result import PlanResult, Status

__all__ = ["GRID_ALGORITHMS", "PlanResult", "Status"]
