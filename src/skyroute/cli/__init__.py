"""The ``skyroute`` command line (Typer + Rich)."""
