"""The flight model navigating as PX4 does, against the recorded PX4 SITL flights
(``tests/data/px4-sitl``: PX4 v1.16, its SIH fixed wing, stock parameters).

The limits are what the model reaches today (``docs/px4-agreement.md``) with a margin of
about 20 %, so a change that makes it agree less with the real vehicle fails here.  The goals
(timing 2 s; track 3 m median, 10 m max; closest approach 1 m median, 3 m max) are met except
by ``dtsp_dense60``'s take-off (the document says how)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dtsp_mission.autopilot.navigation import Airframe
from dtsp_mission.autopilot.parameters import PX4_DEFAULTS, read_px4_parameters
from dtsp_mission.bench.px4_agreement import compare_px4_case

DATA = Path(__file__).resolve().parents[1] / "data" / "px4-sitl"

# case: (timing max s, track median m, track max m, closest |diff| median m,
#        closest |diff| max m) -- today's figures plus about 20 %
LIMITS = {
    "circle_t10": (1.1, 0.9, 7.6, 0.8, 2.0),
    "circle_t2": (0.9, 0.7, 7.1, 0.8, 1.5),
    "dtsp_dense60": (5.1, 0.7, 40.3, 0.8, 3.5),
    "geometry_u60": (2.2, 0.7, 4.1, 0.7, 3.0),
    "square": (0.9, 1.1, 8.2, 1.0, 1.6),
    "zigzag": (0.5, 0.8, 6.4, 0.9, 2.0),
}


def test_every_recorded_px4_flight_has_limits():
    assert sorted(LIMITS) == sorted(p.name for p in DATA.iterdir() if (p / "reached.csv").exists())


@pytest.mark.parametrize("case", sorted(LIMITS))
def test_the_model_flies_like_the_recorded_px4(case):
    # within today's figures, and the whole mission flown, about as far as the real aircraft
    assert compare_px4_case(DATA / case).beyond(LIMITS[case]) == []


def test_a_case_beyond_its_limits_is_named():
    found = compare_px4_case(DATA / "square").beyond((0.1, 0.1, 100.0, 0.1, 100.0))
    assert [f.split()[0] for f in found] == ["timing_max_s", "track_median_m", "approach_median_m"]


def test_the_model_switches_waypoints_where_px4_does():
    """PX4 switches to the next waypoint NPFG_SW_DST_MLT of the track error bound before one
    (31 m at 14 m/s with the stock values, far beyond NAV_ACC_RAD 10 m): measured in the
    recording, and the model's switch positions land on the real ones."""
    import csv
    from dataclasses import replace
    from dtsp_mission.autopilot import Autopilot
    from dtsp_mission.export import read_mission
    from dtsp_mission.sim.predict import predict_flight
    folder = DATA / "square"
    mission = replace(read_mission(folder / "mission.plan"), autopilot=Autopilot.PX4)
    flight = predict_flight(mission, Airframe.from_px4_parameters(), 0.02)
    reached = {}
    for row in csv.DictReader((folder / "reached.csv").open()):
        reached.setdefault(int(row["seq"]), float(row["time_s"]))
    rows = list(csv.DictReader((folder / "track.csv").open()))
    t = np.array([float(r["time_s"]) for r in rows])
    xy = np.array([[float(r["east_m"]), float(r["north_m"])] for r in rows])
    model = dict(flight.flight.reached)
    for seq in (1, 2, 3):
        real_at = xy[np.searchsorted(t, reached[seq])]
        model_at = flight.track[np.searchsorted(flight.track[:, 0], model[seq]), 1:3]
        assert np.hypot(*(real_at - model_at)) < 5.0


def test_px4_parameters_are_read_by_their_names(tmp_path):
    assert read_px4_parameters(DATA / "square" / "params.parm") == PX4_DEFAULTS
    path = tmp_path / "tuned.params"
    path.write_text("NPFG_PERIOD 14\nNAV_ACC_RAD,25\nFW_R_LIM 40\n")
    tuned = read_px4_parameters(path)
    assert (tuned.NPFG_PERIOD, tuned.NAV_ACC_RAD, tuned.FW_R_LIM) == (14.0, 25.0, 40.0)
    airframe = Airframe.from_px4_parameters(tuned)
    assert (airframe.autopilot, airframe.l1_period_s, airframe.wp_radius_m) == ("px4", 14.0, 25.0)
    path.write_text("FW_R_LIM 80\n")
    from dtsp_mission.errors import FileFormatError
    with pytest.raises(FileFormatError, match="FW_R_LIM 80 is out of its range"):
        read_px4_parameters(path)
