"""Deprecated location of :mod:`skyroute.result` (kept for one release)."""

from skyroute.result import (  # noqa: F401
    BUDGET_EXHAUSTED,
    FOUND,
    NO_PATH,
    STATUS_OF_CODE,
    PlanResult,
    Status,
    stop_code,
)
