"""Tours: the model every planner returns, its checker, and its JSON form."""

from .check import TOLERANCE_RHO, CheckReport, check_tour
from .json_form import read_tour, tour_from_dict, tour_to_dict, write_tour
from .model import Tour, tour_through_poses

__all__ = ["TOLERANCE_RHO", "CheckReport", "Tour", "check_tour", "read_tour", "tour_from_dict",
           "tour_through_poses", "tour_to_dict", "write_tour"]
