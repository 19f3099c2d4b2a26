"""teb_local_planner: :class:`TebPlanner`, :class:`TebParams`, :class:`FootprintModel`."""

from roverlab.navigation.controllers.teb.band import TimedElasticBand
from roverlab.navigation.controllers.teb.params import FOOTPRINT_MODELS, FootprintModel, TebParams
from roverlab.navigation.controllers.teb.planner import TebPlanner

__all__ = ["FOOTPRINT_MODELS", "FootprintModel", "TebParams", "TebPlanner", "TimedElasticBand"]
