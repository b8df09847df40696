"""``python -m homebench`` runs the command line."""

from homebench.cli import main

main()
