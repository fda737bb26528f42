"""skyroute.blas_probe: numba still does linear algebra after its start-up probe is deferred."""

import subprocess
import sys

SCRIPT = """
import sys
import numpy as np
import skyroute  # installs the deferral
from numba import njit

@njit
def add(a, b):
    return a + b

add(1, 2)  # loads numba's CPU target: the probe runs, deferred
assert "numba.np.arraymath" in sys.modules
assert "scipy.linalg" not in sys.modules, "the probe imported scipy.linalg"

@njit
def product(a, b):
    return np.dot(a, b)

rng = np.random.default_rng(0)
a, b = rng.random((4, 3)), rng.random((3, 5))
assert np.allclose(product(a, b), a @ b)
assert "scipy.linalg.cython_blas" in sys.modules  # the full check ran for np.dot
print("ok")
"""


def test_numba_blas_works_and_scipy_linalg_waits_for_it():
    proc = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "ok"


def test_defer_is_a_no_op_once_arraymath_is_loaded():
    script = ("import sys, numba.np.arraymath, skyroute.blas_probe as b; n = len(sys.meta_path);"
              " b.defer(); assert len(sys.meta_path) == n; print('ok')")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
