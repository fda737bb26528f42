"""Shared fixtures of the picture tests."""

from __future__ import annotations

import matplotlib
import pytest

matplotlib.use("Agg")  # before pyplot: no window on a desktop either

from skyroute.io import plot as plot_mod
from skyroute.io import world_out


@pytest.fixture
def figures(monkeypatch):
    """The figures saved while the test runs (still drawn to their files)."""
    saved = []
    real = plot_mod.save_figure

    def keep(fig, path, **kw):
        saved.append(fig)
        return real(fig, path, **kw)

    monkeypatch.setattr(plot_mod, "save_figure", keep)
    monkeypatch.setattr(world_out, "save_figure", keep)  # imported there by name
    return saved
