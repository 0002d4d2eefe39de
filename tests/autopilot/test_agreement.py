"""The flight model against the recorded ArduPlane SITL flights (``tests/data/arduplane-sitl``).

The limits are what the model reaches today (``docs/arduplane-agreement.md``) with a small
margin, so a change that makes it agree less with the real vehicle fails here.  They are not
yet the simulator issue's goals (timing 2 s; track 3 m median, 10 m max; closest approach 1 m
median, 3 m max) everywhere: the rows that miss them are listed in that document.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from dtsp_mission.bench.arduplane_agreement import compare_case

DATA = Path(__file__).resolve().parents[1] / "data" / "arduplane-sitl"

# case: (timing max s, track median m, track max m, closest |diff| median m, closest |diff| max m)
LIMITS = {
    "square": (1.5, 2.5, 18.0, 1.2, 3.8),
    "zigzag": (2.2, 5.5, 24.0, 2.0, 3.0),
    "circle_t2": (1.8, 4.0, 5.5, 4.2, 5.2),
    "circle_t10": (1.6, 2.4, 5.5, 1.0, 2.3),
    "circle_t40": (1.5, 3.5, 10.0, 1.1, 1.6),
    "loiter_arcs": (2.7, 8.5, 18.0, 3.8, 4.3),
    "dtsp_u40": (2.8, 5.2, 20.0, 4.4, 14.5),
    "dtsp_u40_margin": (3.0, 6.0, 75.0, 6.0, 16.0),
    "dtsp_dense60": (3.9, 6.2, 20.0, 3.7, 18.0),
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
    assert result.model_length_m == pytest.approx(result.real_length_m, rel=0.06)
