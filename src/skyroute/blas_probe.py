"""Defer numba's BLAS probe from start-up to the first kernel that uses BLAS.

When numba's CPU target loads its first kernel it imports ``numba.np.arraymath``, which
asks at once whether a BLAS is there by importing ``scipy.linalg`` whole: about a sixth
of a cold ``skyroute plan`` (docs/benchmarks.md section 3), for kernels that use no BLAS.
scipy is one of skyroute's dependencies, so that first answer is known: :func:`defer`
makes it a check that scipy is installed, and every later call (numba lowering a kernel
that does use ``np.dot`` and the like) runs numba's own check, scipy's import and its
integer-width test included. Nothing else in numba changes.
"""

from __future__ import annotations

import sys
from importlib.abc import MetaPathFinder
from importlib.util import find_spec

PROBING_MODULE = "numba.np.arraymath"


class _BeforeArraymath(MetaPathFinder):
    """Patches ``numba.np.linalg.ensure_blas`` just before arraymath is imported."""

    def find_spec(self, name, path=None, target=None):
        if name != PROBING_MODULE:
            return None
        sys.meta_path.remove(self)
        import numba.np.linalg as linalg

        full = linalg.ensure_blas
        answered = []

        def ensure_blas():
            if answered:
                return full()
            answered.append(True)
            if find_spec("scipy") is None:
                raise ImportError("scipy is required for linear algebra")
            return None

        linalg.ensure_blas = ensure_blas
        return None  # the usual finders import arraymath itself


def defer() -> None:
    """Install the patch for the next import of numba's arraymath (once; no-op after)."""
    if PROBING_MODULE in sys.modules or any(
            isinstance(f, _BeforeArraymath) for f in sys.meta_path):
        return
    sys.meta_path.insert(0, _BeforeArraymath())
