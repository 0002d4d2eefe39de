"""The tour model, its checker (accepting and rejecting), and its JSON form."""

import json
import math
from dataclasses import replace
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import assert_valid_tour
from dtsp_mission.errors import FileAccessError, FileFormatError, TourInvalidError
from dtsp_mission.segments import SegmentChain
from dtsp_mission.tour import (Tour, check_tour, read_tour, tour_from_dict, tour_through_poses,
                               tour_to_dict, write_tour)

SCHEMA = json.loads((Path(__file__).parents[2] / "dtsp_mission/schemas/tour.schema.json").read_text())


@pytest.fixture
def tour(rng) -> Tour:
    targets = rng.uniform(0, 2000, (40, 2))
    return tour_through_poses(targets, rng.permutation(40), rng.uniform(0, 2 * np.pi, 40), 80.0,
                              "random order", {"seed": 1})


def test_tour_through_poses_is_valid_and_visits_in_order(tour):
    assert_valid_tour(tour)
    order = tour.visit_order
    assert np.all(np.diff(tour.visit_s_m[order]) > 0)
    assert np.allclose(tour.visit_poses()[:, :2], tour.targets_m, atol=1e-9)


@given(st.lists(st.tuples(st.floats(-500, 500), st.floats(-500, 500), st.floats(0, 7)),
                min_size=1, max_size=12),
       st.floats(1.0, 300.0))
def test_any_order_and_headings_give_a_valid_tour(points, rho):
    """Including coincident targets and targets closer than rho."""
    data = np.array(points)
    tour = tour_through_poses(data[:, :2], np.arange(len(data)), data[:, 2], rho)
    assert_valid_tour(tour)


def _broken(tour: Tour, **chain_changes) -> Tour:
    chain = tour.chain
    fields = {"starts": chain.starts.copy(), "lengths_m": chain.lengths_m.copy(),
              "curvatures_1_m": chain.curvatures_1_m.copy()}
    for name, change in chain_changes.items():
        change(fields[name])
    return replace(tour, chain=SegmentChain(**fields))


def test_checker_rejects_a_gap(tour):
    broken = _broken(tour, starts=lambda a: a.__setitem__((5, 0), a[5, 0] + 1e-3))
    report = check_tour(broken)
    assert not report.ok and "C1" in report.problems[0]
    with pytest.raises(TourInvalidError, match="C1"):
        report.raise_if_invalid()


def test_checker_rejects_a_heading_jump(tour):
    report = check_tour(_broken(tour, starts=lambda a: a.__setitem__((7, 2), a[7, 2] + 1e-4)))
    assert any("C1" in p for p in report.problems)


def test_checker_rejects_a_turn_tighter_than_rho(tour):
    arc = int(np.flatnonzero(tour.chain.curvatures_1_m)[0])
    report = check_tour(_broken(tour, curvatures_1_m=lambda a: a.__setitem__(arc, a[arc] * 1.001)))
    assert any("tighter than rho" in p for p in report.problems)


def test_checker_rejects_an_open_tour(tour):
    report = check_tour(_broken(tour, lengths_m=lambda a: a.__setitem__(-1, a[-1] * 0.5)))
    assert any("not closed" in p for p in report.problems)


def test_checker_rejects_a_missed_target(tour):
    moved = tour.targets_m.copy()
    moved[3] += [0.0, 1e-3]
    report = check_tour(replace(tour, targets_m=moved))
    assert any("not on the path" in p and "target 3" in p for p in report.problems)
    assert report.max_target_miss_m == pytest.approx(1e-3, rel=1e-3)


def test_checker_rejects_a_visit_beyond_the_end(tour):
    visits = tour.visit_s_m.copy()
    visits[0] = tour.length_m * 2
    assert any("outside" in p for p in check_tour(replace(tour, visit_s_m=visits)).problems)


def test_checker_rejects_non_finite_geometry_and_empty_tours(tour):
    report = check_tour(_broken(tour, lengths_m=lambda a: a.__setitem__(0, math.nan)))
    assert any("non-finite" in p for p in report.problems)
    empty = Tour(SegmentChain.empty(), 80.0, tour.targets_m, tour.visit_s_m)
    assert any("no segments" in p for p in check_tour(empty).problems)


def test_json_round_trip_is_exact_and_matches_the_schema(tour, tmp_path):
    data = tour_to_dict(tour)
    jsonschema.validate(data, SCHEMA)
    path = write_tour(tour, tmp_path / "tour.json")
    again = read_tour(path)
    assert np.array_equal(again.chain.starts, tour.chain.starts)
    assert np.array_equal(again.chain.lengths_m, tour.chain.lengths_m)
    assert np.allclose(again.chain.curvatures_1_m, tour.chain.curvatures_1_m, rtol=1e-15, atol=0)
    assert np.array_equal(again.visit_s_m, tour.visit_s_m)
    assert np.array_equal(again.targets_m, tour.targets_m)
    assert (again.planner, again.parameters) == ("random order", {"seed": 1})
    assert_valid_tour(again)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tour.json"]   # no temporary left


BROKEN = [
    (lambda d: d.update(format="something"), "not a tour"),
    (lambda d: d.update(version=2), "version 2 is not supported"),
    (lambda d: d.update(rho_m=-1), "'rho_m' must be positive"),
    (lambda d: d.update(rho_m="80"), "'rho_m' must be a finite number"),
    (lambda d: d["segments"][0].update(type="spiral"), "segments\\[0\\]: 'type'"),
    (lambda d: d["segments"][1].pop("heading_rad"), "segments\\[1\\]: 'heading_rad'"),
    (lambda d: d["segments"][0].update(length_m=-3.0), "'length_m' must be at least 0"),
    (lambda d: d["visits"].pop(), "has no visit"),
    (lambda d: d["visits"].append(dict(d["visits"][0])), "visited twice"),
    (lambda d: d["visits"][0].update(target=999), "'target' must be a target index"),
    (lambda d: d.update(targets={}), "'targets' must be a list"),
]


@pytest.mark.parametrize("corrupt, message", BROKEN)
def test_broken_tour_files_are_rejected_with_a_clear_message(tour, corrupt, message):
    data = tour_to_dict(tour)
    arcs = [s for s in data["segments"] if s["type"] == "arc"]
    assert arcs
    corrupt(data)
    with pytest.raises(FileFormatError, match=message):
        tour_from_dict(data)


def test_unreadable_files(tmp_path):
    with pytest.raises(FileAccessError, match="no such file"):
        read_tour(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(FileFormatError, match="not valid JSON"):
        read_tour(tmp_path / "bad.json")
    (tmp_path / "binary.json").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(FileAccessError, match="not a UTF-8"):
        read_tour(tmp_path / "binary.json")


def test_a_single_pose_gives_one_full_circle():
    tour = tour_through_poses(np.array([[10.0, 20.0]]), [0], [0.5], 40.0)
    assert_valid_tour(tour)
    assert tour.length_m == pytest.approx(2 * math.pi * 40.0)
    assert len(tour.chain) == 1
