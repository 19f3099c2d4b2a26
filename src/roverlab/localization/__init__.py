"""Localization on a known map: :mod:`roverlab.localization.amcl` (ROS 1 ``amcl``)."""
