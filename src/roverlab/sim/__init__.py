"""Simulation: a planar diff-drive robot with Gazebo-plugin semantics in a 2.5-D world."""
