"""skyroute's version: the one place it is written (pyproject reads it from here), in
the bottom layer so that any module, a benchmark's report say, can record it."""

__version__ = "0.1.0"
