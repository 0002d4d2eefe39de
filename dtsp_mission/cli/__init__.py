"""The ``dtsp-mission`` command line.

Library errors (:class:`~dtsp_mission.errors.DtspError`) become one-line messages and exit
code 2 here, at the boundary, and nowhere else.
"""
