"""``python -m roverlab.slam``: the ``roverlab slam`` command on its own."""

from roverlab.slam.cli import main

main()
