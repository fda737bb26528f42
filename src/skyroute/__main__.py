"""``python -m skyroute`` runs the CLI."""

from skyroute.cli.app import main

main()
