"""One World used from several threads at once (a researcher's thread pool over
``skyroute.plan``): GEOS's prepared geometries are not thread-safe, and shapely lets go
of the GIL while it tests them, so this crashed the interpreter. Run in a child process,
where a crash is a return code, not the end of the test session."""

import os
import subprocess
import sys

from tests.conftest import ROOT

SCRIPT = """
import threading
import numpy as np, shapely
from skyroute.world.world import World
rng = np.random.default_rng(0)
boxes = [shapely.box(x, y, x + 8, y + 8) for x in range(0, 200, 10) for y in range(0, 200, 10)]
w = World(boxes, 0, 100, (), boundary=shapely.box(-5, -5, 205, 205))
a = rng.uniform(0, 200, (1000, 2))
b = a + rng.uniform(-30, 30, (1000, 2))
free, seg = w.is_free(a), w.segments_free(a, b)
wrong = []
def work():
    for _ in range(3):
        if not (np.array_equal(w.segments_free(a, b), seg)
                and np.array_equal(w.is_free(a), free)):
            wrong.append(1)
threads = [threading.Thread(target=work) for _ in range(4)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print("ok", len(wrong))
"""


def test_a_world_tested_from_four_threads_at_once_gives_the_same_answers():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT / "src"), *filter(None, [os.environ.get("PYTHONPATH")])]))
    proc = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          env=env, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]  # -11: a segmentation fault
    assert proc.stdout.split() == ["ok", "0"]
