"""Grid search: BFS, Dijkstra, A*, JPS, Theta*, Lazy Theta*, pruning; one PlanResult."""

from skyroute.result import PlanResult, Status
from skyroute.search.grid_plan import GRID_ALGORITHMS

__all__ = ["GRID_ALGORITHMS", "PlanResult", "Status"]
