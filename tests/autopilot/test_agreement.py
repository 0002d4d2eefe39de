"""The flight model against the recorded ArduPlane SITL flights (``tests/data/arduplane-sitl*``:
stock parameters without wind, in wind, other tunings).

The limits are what the model reaches today (``docs/arduplane-agreement.md``) with a margin
of about 20 %, so a change that makes it agree less with the real vehicle fails here.  The
simulator issue's goals (timing 2 s; track 3 m median, 10 m max; closest approach 1 m median,
3 m max) are met except where the limits below are wider: the document says which and why
(``dtsp_u40_margin``'s 72 m is one place where ArduPlane looped back to a target it had
passed more than its 5 m acceptance radius away, which the model passed within it).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from dtsp_mission.bench.arduplane_agreement import compare_case

DATA = Path(__file__).resolve().parents[1] / "data"

# set: case: (timing max s, track median m, track max m, closest |diff| median m,
#             closest |diff| max m) -- today's figures plus about 20 %
LIMITS = {
    "arduplane-sitl": {
        "circle_t10": (1.0, 0.4, 4.1, 0.5, 1.1),
        "circle_t2": (1.0, 0.3, 4.6, 0.5, 2.1),
        "circle_t40": (1.0, 0.4, 4.1, 1.0, 1.5),
        "dtsp_dense60": (1.0, 0.8, 4.7, 0.5, 3.9),
        "dtsp_u40": (1.0, 0.3, 5.1, 0.5, 0.9),
        "dtsp_u40_margin": (2.3, 0.5, 88.1, 0.6, 1.5),
        "loiter_arcs": (1.1, 1.0, 3.9, 0.5, 0.8),
        "square": (1.0, 0.4, 4.0, 0.5, 2.4),
        "zigzag": (1.0, 0.6, 12.4, 0.5, 2.1),
    },
    "arduplane-sitl-wind": {
        "circle_t10_w6_160": (1.0, 0.3, 3.5, 0.5, 2.8),
        "circle_t10_w9_40": (1.0, 0.3, 11.6, 0.5, 0.6),
        "dtsp_u40_w6_160": (1.6, 0.3, 17.6, 0.5, 2.6),
        "guide_u60": (1.0, 0.4, 7.4, 0.5, 1.8),
        "guide_u60_w6_160": (1.1, 0.4, 13.8, 0.5, 5.2),
        "guide_u60_w9_40": (2.1, 0.4, 27.3, 0.5, 26.8),
        "loiter_arcs_w6_160": (1.1, 1.0, 17.1, 0.6, 4.6),
        "loiter_arcs_w9_40": (1.1, 0.5, 11.6, 0.5, 1.1),
        "square_w6_160": (1.0, 0.3, 3.4, 1.1, 2.6),
        "square_w9_40": (1.0, 0.4, 11.4, 0.5, 1.2),
        "zigzag_w6_160": (1.0, 2.1, 16.4, 0.9, 2.8),
        "zigzag_w9_40": (1.0, 0.4, 11.6, 0.5, 1.7),
    },
    "arduplane-sitl-tuned": {
        "circle_t10_p12": (1.0, 0.4, 3.4, 0.5, 0.6),
        "circle_t10_p18": (1.0, 0.4, 3.8, 0.5, 0.6),
        "guide_u60_p12": (1.0, 0.5, 10.0, 0.5, 4.2),
        "guide_u60_p18": (1.0, 0.4, 7.7, 0.5, 2.8),
        "loiter_arcs_p12": (1.0, 0.8, 4.2, 0.5, 1.1),
        "loiter_arcs_p18": (1.1, 1.0, 3.4, 0.6, 1.4),
        "square_p12": (1.0, 0.6, 3.9, 0.6, 0.8),
        "square_p18": (1.0, 0.4, 4.0, 0.5, 7.8),
        "zigzag_p12": (1.0, 1.2, 11.6, 0.5, 0.6),
        "zigzag_p18": (1.0, 0.5, 11.7, 1.5, 1.8),
    },
}
CASES = [(group, case) for group, limits in LIMITS.items() for case in sorted(limits)]


@pytest.mark.parametrize("group", sorted(LIMITS))
def test_every_recorded_case_has_limits(group):
    assert sorted(LIMITS[group]) == sorted(p.name for p in (DATA / group).iterdir()
                                           if (p / "track.csv").exists())


@pytest.mark.parametrize("group,case", CASES)
def test_the_model_flies_like_the_recorded_arduplane(group, case):
    # within today's figures, and the whole mission flown, about as far as the real aircraft
    assert compare_case(DATA / group / case).beyond(LIMITS[group][case]) == []


def test_the_model_counts_the_targets_a_real_arduplane_missed_in_wind_and_tuned():
    """The planned 60-target mission (designed for calm air and stock parameters) flown by a
    real ArduPlane in 9 m/s of wind and with a tighter tuning: the model, given the wind and
    the parameters, predicts about as many targets beyond 5 m as the real flight had."""
    import numpy as np
    from dtsp_mission.autopilot.navigation import closest_approach_m
    from dtsp_mission.bench.arduplane_agreement import _rows, fly_recorded_mission
    for folder, real_beyond in ((DATA / "arduplane-sitl-wind" / "guide_u60_w9_40", 24),
                                (DATA / "arduplane-sitl-tuned" / "guide_u60_p12", 8)):
        flight, model, frame = fly_recorded_mission(folder)
        rows = _rows(folder / "misses.csv")
        real = np.array([float(r["miss_m"]) for r in rows])
        xy = frame.to_local(np.array([float(r["lat"]) for r in rows]),
                            np.array([float(r["lon"]) for r in rows]))
        predicted = closest_approach_m(model[model[:, 0] >= dict(flight.reached)[1], 1:3], xy)
        assert (real > 5).sum() == real_beyond
        assert abs(int((predicted > 5).sum()) - real_beyond) <= 3


@pytest.mark.parametrize("case", sorted(p.name for p in (DATA / "arduplane-sitl").iterdir()
                                         if (p / "params.parm").exists()))
def test_every_recorded_parameter_set_is_the_one_missions_are_designed_for(case):
    """The guidance design predicts with ArduPlane's defaults; every parameter set the real
    ArduPlane flew with reads to exactly those (so a mission designed for the defaults is
    designed for each of them, and `--vehicle-params` with any of them changes nothing)."""
    from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS, read_parameters
    assert read_parameters(DATA / "arduplane-sitl" / case / "params.parm").differing(ARDUPLANE_DEFAULTS) == []
