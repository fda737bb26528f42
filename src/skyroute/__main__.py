"""``python -m skyroute`` runs the CLI, as the ``skyroute`` program does."""

from skyroute.cli.app import console

console()
