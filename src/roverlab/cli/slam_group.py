"""``roverlab slam``: the offline tools of cli/slam.py with ``run`` (cli/slam_run.py) and
``mapeval`` (cli/slam_mapeval.py) mounted beside them."""

from __future__ import annotations

from roverlab.cli import slam, slam_mapeval, slam_run

__all__ = ["app"]

app = slam.app
app.command("run")(slam_run.run)
app.command("mapeval")(slam_mapeval.mapeval)
