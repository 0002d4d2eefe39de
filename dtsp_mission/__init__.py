"""dtsp-mission: Dubins-TSP tours for fixed-wing UAVs, turned into MAVLink missions.

Pipeline (data flows one way): targets -> local metric frame -> tour (exact lines and arcs)
-> mission items -> file or link.  The metric core (``dubins``, ``segments``, ``tour``) works
in metres and radians and imports neither pyproj nor any MAVLink library.
"""

__version__ = "0.1.0"
