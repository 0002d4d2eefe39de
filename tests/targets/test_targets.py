"""Target readers: CSV (degrees or metres) and GeoJSON, random targets in a polygon."""

import json

import numpy as np
import pytest
import shapely

from dtsp_mission.errors import FileFormatError, InputError
from dtsp_mission.frame import LocalFrame
from dtsp_mission.targets import GeoTargets, Targets, random_targets, read_targets


def write(tmp_path, name, content):
    path = tmp_path / name
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    return path


def test_csv_in_degrees_with_alt_and_names_and_a_duplicate(tmp_path):
    path = write(tmp_path, "t.csv", " Latitude , LON ,alt,Name\n46.8,6.9,50,a\n46.81,6.91,60,b\n"
                                    "46.8,6.9,50,a\n")
    targets = read_targets(path)
    assert isinstance(targets, GeoTargets) and len(targets) == 2
    assert targets.names == ("a", "b") and targets.merged_duplicates == 1
    assert list(targets.altitudes_m) == [50.0, 60.0]


@pytest.mark.parametrize("second, field", [("70,a", "altitude"), ("50,c", "name")])
def test_csv_duplicates_that_disagree_are_refused_naming_both_lines(tmp_path, second, field):
    path = write(tmp_path, "t.csv", "lat,lon,alt,name\n# a comment\n46.8,6.9,50,a\n\n"
                                    f"46.81,6.91,60,b\n46.8,6.9,{second}\n")
    with pytest.raises(InputError, match=f"line 3 and line 6 are at the same position with a "
                                         f"different {field}"):
        read_targets(path)


def test_csv_lines_are_the_files_lines_and_quoted_fields_may_span_them(tmp_path):
    path = write(tmp_path, "t.csv", 'lat,lon,name\n46.8,6.9,"pole\nnorth"\n# note\n46.81,6.91,b\n'
                                    "46.82,abc,c\n")
    with pytest.raises(FileFormatError, match="line 6: lon must be a number"):
        read_targets(path)
    targets = read_targets(write(tmp_path, "u.csv", 'lat,lon,name\n46.8,6.9,"pole\nnorth"\n'
                                                    "46.81,6.91,b\n"))
    assert targets.names == ("pole\nnorth", "b")


@pytest.mark.parametrize("header, meant", [("lat,lon,atl", "alt"), ("lat,lon,nmae", "name"),
                                           ("lat,lnog", "lng"), ("lat,lon,phto", "photo")])
def test_a_misspelt_column_is_refused_naming_the_one_meant(tmp_path, header, meant):
    row = ",".join(["46.8", "6.9", "1"][:header.count(",") + 1])
    with pytest.raises(FileFormatError, match=f"did you mean '{meant}'"):
        read_targets(write(tmp_path, "t.csv", f"{header}\n{row}\n"))


def test_columns_not_read_are_named_including_xy_beside_lat_lon(tmp_path):
    targets = read_targets(write(tmp_path, "t.csv", "lat,lon,y,comment\n46.8,6.9,3,a\n"
                                                    "46.81,6.91,4,b\n"))
    assert isinstance(targets, GeoTargets) and set(targets.unused_columns) == {"y", "comment"}


def test_csv_in_metres(tmp_path):
    targets = read_targets(write(tmp_path, "t.csv", "x_m,y_m\n0,0\n10,5\n"))
    assert isinstance(targets, Targets) and targets.positions_m.tolist() == [[0, 0], [10, 5]]


@pytest.mark.parametrize("content, message", [
    ("lat,lon,x,y\n1,2,3,4\n", "either columns lat and lon"),
    ("lat,lat,lon\n1,2,3\n", "given twice"),
    ("lat,lon\n1,2,3\n", "3 fields where the header has 2"),
    ("lat,lon,alt\n46,7,0\n", "must be a number above 0"),
])
def test_csv_errors(tmp_path, content, message):
    with pytest.raises((FileFormatError, InputError), match=message):
        read_targets(write(tmp_path, "t.csv", content))


def polygon(ring):
    return {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}


SQUARE = [[6.9, 46.8], [6.96, 46.8], [6.96, 46.84], [6.9, 46.84], [6.9, 46.8]]


def test_geojson_points_multipoint_and_area(tmp_path):
    data = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "a"}, "geometry": {"type": "Point", "coordinates": [6.91, 46.81]}},
        {"type": "Feature", "properties": None, "geometry": {"type": "MultiPoint", "coordinates": [[6.92, 46.82], [6.93, 46.83]]}},
        polygon(SQUARE)]}
    targets = read_targets(write(tmp_path, "t.geojson", data))
    assert len(targets) == 3 and targets.names == ("a", "", "")
    assert targets.area_deg.shape == (5, 2) and targets.area_deg[1].tolist() == [46.8, 6.96]


@pytest.mark.parametrize("data, message", [
    (polygon([[6.9, 46.8], [6.96, 46.84], [6.96, 46.8], [6.9, 46.84], [6.9, 46.8]]), "not valid"),
    ({"type": "FeatureCollection", "features": [polygon(SQUARE), polygon(SQUARE)]}, "second Polygon"),
    ({"type": "Point", "coordinates": [6.9]}, "coordinates must be"),
    ({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"alt": 50}, "geometry": {"type": "Point", "coordinates": [6.9, 46.8]}},
        {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [6.91, 46.8]}}]},
     "on every target or on none"),
    ({"type": "Point", "coordinates": [6.9, 95]}, "latitude 95.0"),
    ({"type": "Point", "coordinates": [6.9, 46.8, 400]}, "third coordinate"),
    ({"type": "Feature", "properties": "camera", "geometry": {"type": "Point", "coordinates": [6.9, 46.8]}},
     "must be an object"),
    ([1, 2], "not GeoJSON"),
])
def test_geojson_errors(tmp_path, data, message):
    with pytest.raises((FileFormatError, InputError), match=message):
        read_targets(write(tmp_path, "t.geojson", data))


def test_random_targets_are_inside_uniform_and_seeded():
    area = np.array(SQUARE)[:, ::-1]
    first = random_targets(area, 4000, seed=1)
    again = random_targets(area, 4000, seed=1)
    assert np.array_equal(first.latitudes_deg, again.latitudes_deg)
    assert not np.array_equal(first.latitudes_deg, random_targets(area, 4000, seed=2).latitudes_deg)
    frame = LocalFrame(46.82, 6.93)
    local = frame.to_local(first.latitudes_deg, first.longitudes_deg)
    outline = shapely.Polygon(frame.to_local(area[:, 0], area[:, 1]))
    assert shapely.contains_xy(outline, local[:, 0], local[:, 1]).all()
    # Uniform: the west half of the square holds about half the points.
    west = (first.longitudes_deg < 6.93).mean()
    assert abs(west - 0.5) < 0.03
    with pytest.raises(InputError):
        random_targets(area, 0, seed=1)


def test_the_api_refuses_bad_geotargets_with_its_own_words():
    """Not pyproj's 'Invalid latitude' or 'must be same size' from deep inside the planner."""
    import numpy as np
    import pytest

    from dtsp_mission.errors import InputError
    from dtsp_mission.targets import GeoTargets
    with pytest.raises(InputError, match=r"target 1: latitude 91.0 is not a number between -90 and 90 degrees"):
        GeoTargets(np.array([91.0, 46.0]), np.array([6.9, 6.91]))
    with pytest.raises(InputError, match="one latitude and one longitude per target: got 3 latitudes and 2"):
        GeoTargets(np.array([46.0, 46.1, 46.2]), np.array([6.9, 6.91]))
    with pytest.raises(InputError, match="target 2: longitude nan"):
        GeoTargets([46.0, 46.1], [6.9, float("nan")])
    with pytest.raises(InputError, match="2 targets but 1 names"):
        GeoTargets([46.0, 46.1], [6.9, 6.91], ("a",))


def test_targets_files_as_people_have_them(tmp_path):
    """Semicolons or tabs, # comments, extra columns kept (and listed), an empty alt cell
    meaning the mission's altitude -- each refused before."""
    import numpy as np

    from dtsp_mission.targets import read_targets
    semicolons = tmp_path / "s.csv"
    semicolons.write_text("# exported from the site survey\nname;lat;lon;alt;inspector;camera\n"
                          "A;46.80;6.94;;Ann;yes\n# a comment between rows\nB;46.81;6.95;120;Bo;no\n")
    targets = read_targets(semicolons)
    assert targets.names == ("A", "B") and targets.unused_columns == ("inspector",)
    assert targets.actions.photo.tolist() == [True, False]      # 'camera' is the photo action
    assert np.isnan(targets.altitudes_m[0]) and targets.altitudes_m[1] == 120.0
    tabs = tmp_path / "t.csv"
    tabs.write_text("lat\tlon\n46.80\t6.94\n46.81\t6.95\n")
    assert len(read_targets(tabs)) == 2 and read_targets(tabs).unused_columns == ()


def test_targets_from_standard_input():
    import subprocess
    import sys
    for text in ("lat,lon\n46.80,6.94\n46.81,6.95\n46.805,6.955\n",
                 '{"type": "FeatureCollection", "features": [' + ", ".join(
                     '{"type": "Feature", "geometry": {"type": "Point", "coordinates": [%s, %s]}, '
                     '"properties": {}}' % (lon, lat) for lat, lon in
                     ((46.80, 6.94), (46.81, 6.95), (46.805, 6.955))) + "]}"):
        result = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", "-", "--radius", "80",
                                 "--algorithm", "alternating", "--json", "-q"], input=text,
                                capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr
        assert '"targets": 3' in result.stdout
