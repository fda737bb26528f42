"""How large a PRM roadmap may be: :mod:`skyroute.roadmap.prm` checks ``samples``
against these, and the service's ``POST /plan`` declares the same bounds in its schema
(this module imports nothing heavy, so the service reads them without scipy)."""

from __future__ import annotations

MIN_SAMPLES = 2  # a roadmap needs two points to join; one was refused after sampling
MAX_SAMPLES = 10**7  # 160 MB of points and far more of edges: past it, a MemoryError
