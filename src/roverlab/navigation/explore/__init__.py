"""Frontier exploration as explore_lite (m-explore): the frontier search (pure, compiled)
and the ``explore`` node (:mod:`.node`) that sends frontiers to move_base."""

from roverlab.navigation.explore.frontiers import Frontier, FrontierSearch, occupancy_to_costs

__all__ = ["Frontier", "FrontierSearch", "occupancy_to_costs"]
