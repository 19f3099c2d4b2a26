"""The ``roverlab`` command line (typer + rich)."""
