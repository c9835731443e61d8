"""``python -m robobore``: the same as the ``robobore`` command."""

from robobore.cli import main

main()
