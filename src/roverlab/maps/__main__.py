"""``python -m roverlab.maps``: the ``roverlab map`` commands on their own."""

from roverlab.maps.cli import main

main()
