"""Flying missions in the real autopilots: ArduPlane SITL and PX4 SITL (its SIH fixed wing),
started here as processes on loopback, fed the mission by the project's own uploader, and
flown in AUTO to the end.

This is the ground truth the design and the flight model are judged by
(``benchmarks/real_flights.py``, ``tests/test_real_flights.py``): the binaries are not part
of the package; :func:`find_binaries` looks for them where the workplace keeps them.
"""

from .binaries import SitlBinaries, find_binaries
from .flight import RealFlight, TargetReport, compare_with_model, fly_real

__all__ = ["RealFlight", "SitlBinaries", "TargetReport", "compare_with_model", "find_binaries",
           "fly_real"]
