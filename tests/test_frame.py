"""The local metric frame: exact round trip, true distances, and a refusal when too large."""

import numpy as np
import pytest
from pyproj import Geod

from dtsp_mission.errors import InputError
from dtsp_mission.frame import MAX_SCALE_ERROR, LocalFrame, mission_centre

GEOD = Geod(ellps="WGS84")


@pytest.mark.parametrize("origin", [(47.4, 8.5), (-33.9, 151.2), (0.0, 0.0), (78.2, 15.6),
                                    (-64.8, -62.9), (52.0, 179.95)])
def test_round_trip_within_a_centimetre_over_30_km(origin, rng):
    frame = LocalFrame(*origin)
    positions = rng.uniform(-30_000, 30_000, (2000, 2))
    latitudes, longitudes = frame.to_geodetic(positions)
    assert np.all(np.abs(longitudes) <= 180)
    back = frame.to_local(latitudes, longitudes)
    assert np.max(np.hypot(*(back - positions).T)) < 0.01
    # Distances from the centre are geodesic distances on the ellipsoid (to a millimetre).
    _, _, distance = GEOD.inv(np.full(len(positions), origin[1]), np.full(len(positions), origin[0]),
                              longitudes, latitudes)
    assert np.max(np.abs(distance - np.hypot(*positions.T))) < 1e-3


def test_scale_error_grows_with_distance_and_the_limit_is_about_150_km():
    frame = LocalFrame(46.8, 6.95)
    errors = [float(frame.scale_error(*frame.to_geodetic([[d * 1e3, 0.0]]))[0])
              for d in (0.0, 30.0, 100.0, 140.0, 160.0)]
    assert errors == sorted(errors) and errors[0] < 1e-9
    assert errors[3] < MAX_SCALE_ERROR < errors[4]
    latitudes, longitudes = frame.to_geodetic([[0, 0], [140e3, 0]])
    frame.check_extent(latitudes, longitudes)
    latitudes, longitudes = frame.to_geodetic([[0, 0], [160e3, 0]])
    with pytest.raises(InputError, match="too large an area.*160 km from the mission centre"):
        frame.check_extent(latitudes, longitudes)


def test_centre_of_a_mission_across_the_antimeridian():
    latitude, longitude = mission_centre([10.0, 10.2], [179.9, -179.9])
    assert latitude == pytest.approx(10.1) and abs(abs(longitude) - 180.0) < 1e-9
    frame = LocalFrame.around([10.0, 10.2], [179.9, -179.9])
    positions = frame.to_local([10.0, 10.2], [179.9, -179.9])
    assert np.all(np.abs(positions) < 25_000)


@pytest.mark.parametrize("latitude, longitude", [(91, 0), (0, -181), (float("nan"), 0)])
def test_invalid_origin_is_refused(latitude, longitude):
    with pytest.raises(InputError, match="frame origin"):
        LocalFrame(latitude, longitude)
