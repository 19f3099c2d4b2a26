"""``python -m roverlab.teleop``: the ``roverlab teleop`` command on its own."""

from roverlab.teleop.cli import main

main()
