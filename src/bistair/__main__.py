"""``python -m bistair``: the command line."""

from .app.cli import main

main()
