"""``python -m phdesign`` runs the command line."""

from phdesign.cli import run

run()
