"""The docstring examples run as written."""

import doctest
import importlib

import pytest

MODULES = ["skyroute.world.grid", "skyroute.world.load", "skyroute.planner"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
