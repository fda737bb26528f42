"""The package's modules are attributes, imported when first asked for, as the docs
write them (``skyroute.motion.hybrid.plan``); ``dir()`` shows the public names."""

import subprocess
import sys

import pytest

import skyroute

FRESH = """
import sys, skyroute
assert "skyroute.fleet" not in sys.modules
mod = skyroute.fleet.scenario
print(mod.__name__, callable(mod.load_scenario))
"""


def test_a_module_of_a_subpackage_is_an_attribute_in_a_fresh_interpreter():
    done = subprocess.run([sys.executable, "-c", FRESH], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["skyroute.fleet.scenario", "True"]


def test_dir_lists_the_public_names_and_the_modules_not_the_inits_own_imports():
    names = dir(skyroute)
    assert {"plan", "prepare", "Grid", "World", "motion", "fleet", "world_plan",
            "__version__"} <= set(names)
    assert not {"TYPE_CHECKING", "annotations", "defer", "exports", "_HOME"} & set(names)
    assert "hybrid" in dir(skyroute.motion)


def test_an_unknown_name_is_still_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'skyroute' has no attribute 'nope'"):
        skyroute.nope  # noqa: B018
    with pytest.raises(AttributeError, match=r"'skyroute\.motion' has no attribute 'nope'"):
        skyroute.motion.nope  # noqa: B018
