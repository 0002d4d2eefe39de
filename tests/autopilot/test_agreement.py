"""The flight model against the recorded ArduPlane SITL flights (``tests/data/arduplane-sitl``).

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

DATA = Path(__file__).resolve().parents[1] / "data" / "arduplane-sitl"

# case: (timing max s, track median m, track max m, closest |diff| median m, closest |diff| max m)
LIMITS = {
    "square": (1.2, 1.5, 4.5, 1.2, 2.0),
    "zigzag": (1.5, 2.5, 7.5, 1.6, 2.2),
    "circle_t2": (1.4, 0.8, 4.5, 0.6, 5.0),
    "circle_t10": (1.3, 1.9, 7.0, 1.5, 7.5),
    "circle_t40": (1.5, 0.9, 4.0, 0.8, 2.8),
    "loiter_arcs": (2.3, 2.0, 9.5, 3.6, 4.0),
    "dtsp_u40": (2.1, 1.3, 5.0, 1.0, 3.5),
    "dtsp_u40_margin": (2.8, 1.3, 75.0, 1.1, 4.8),
    "dtsp_dense60": (2.8, 0.8, 4.8, 1.0, 4.5),
}


def test_every_recorded_case_has_limits():
    assert sorted(LIMITS) == sorted(p.name for p in DATA.iterdir() if (p / "track.csv").exists())


@pytest.mark.parametrize("case", sorted(LIMITS))
def test_the_model_flies_like_the_recorded_arduplane(case):
    result = compare_case(DATA / case)
    timing, track_median, track_max, closest_median, closest_max = LIMITS[case]
    print(result)
    assert result.items_timed >= 3
    assert result.timing_max_s <= timing
    assert result.track_median_m <= track_median
    assert result.track_max_m <= track_max
    assert result.approach_median_m <= closest_median
    assert result.approach_max_m <= closest_max
    # the model flies the whole mission, about as far as the real aircraft did
    assert result.model_length_m == pytest.approx(result.real_length_m, rel=0.02)


@pytest.mark.parametrize("case", sorted(p.name for p in DATA.iterdir() if (p / "params.parm").exists()))
def test_every_recorded_parameter_set_is_the_one_missions_are_designed_for(case):
    """The guidance design predicts with ArduPlane's defaults; every parameter set the real
    ArduPlane flew with reads to exactly those (so a mission designed for the defaults is
    designed for each of them, and `--vehicle-params` with any of them changes nothing)."""
    from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS, read_parameters
    assert read_parameters(DATA / case / "params.parm").differing(ARDUPLANE_DEFAULTS) == []
