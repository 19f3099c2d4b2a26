"""Autonomy: the seeds' pieces put together into runs a newcomer starts with one command.

* :mod:`.stack`: a simulated robot with SLAM, move_base and explore_lite in one context
  (robot_navigation's explore.launch), sized to the robot;
* :mod:`.monitor`: what a run records while it goes: ground-truth path, known area over
  time, contacts with the world;
* :mod:`.explore_run`: one exploration episode, headless (``roverlab explore``);

The algorithms stay in :mod:`roverlab.navigation` and :mod:`roverlab.slam`; this package
only wires nodes and measures.
"""
