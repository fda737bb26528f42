"""Grid search: BFS, Dijkstra, A*, JPS, Theta*, Lazy Theta*, pruning; one PlanResult."""

from skyroute.lazy import exports as _exports
from skyroute.result import PlanResult, Status
from skyroute.search.grid_plan import GRID_ALGORITHMS

__all__ = ["GRID_ALGORITHMS", "PlanResult", "Status"]
__getattr__, __dir__ = _exports(__name__)  # its modules, imported when first asked for
