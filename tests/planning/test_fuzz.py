"""Adversarial instances through every planner and the CLI: grids at multiples of rho,
near-duplicates, collinear and co-circular sets, large offsets and extreme radii.

Every tour must pass the checker; an input that cannot be planned must be refused with a
:class:`~dtsp_mission.errors.DtspError` (exit 2 from the CLI), never another exception.
"""

from __future__ import annotations

import math
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from click.testing import CliRunner

from conftest import assert_valid_tour
from dtsp_mission.cli.main import cli
from dtsp_mission.errors import InputError, TourInvalidError
from dtsp_mission.planning import get_planner, planners
from dtsp_mission.planning.tiling import TilingUnavailable, bead_half_length
from dtsp_mission.segments import SegmentChain
from dtsp_mission.tour import Tour, check_tour
from dtsp_mission.tour.model import tour_through_poses


def _planner(name):
    """The planner; auto with a small improvement budget (the fuzz is about the geometry, and
    the improver keeps the best peer's tour when its budget is spent)."""
    return get_planner(name, time_limit_s=0.02) if name == "auto" else get_planner(name)


PLANNERS = sorted(name for name, p in planners().items() if not isinstance(p, Exception))
RADII = st.sampled_from([1e-3, 0.37, 1.0, 80.0, 100.0, 2500.0])


@st.composite
def instances(draw):
    """(targets_m, rho_m): one of the adversarial families, offset and scaled."""
    rho = draw(RADII)
    family = draw(st.sampled_from(["grid", "near", "collinear", "circle", "uniform"]))
    n = draw(st.integers(1, 12))
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 16)))
    if family == "grid":
        side = draw(st.integers(1, 4))
        spacing = draw(st.sampled_from([1, 2, 4, 5, 6, 8])) * rho
        g = np.arange(side) * spacing
        points = np.array([(x, y) for x in g for y in g], dtype=float)
    elif family == "near":
        gap = draw(st.sampled_from([0.0, 1e-12, 1e-9, 1e-8, 1e-7, 1e-6, 1e-4])) * rho
        points = rng.normal(0.0, 1.0, (n, 2)) * gap + rng.integers(0, 2, (n, 1)) * 3 * rho
    elif family == "collinear":
        points = np.outer(np.sort(rng.uniform(0, 20 * rho, n)), [1.0, draw(st.sampled_from([0.0, 1.0, 0.3]))])
    elif family == "circle":
        r = draw(st.sampled_from([0.5, 1.0, 2.0, 7.0])) * rho
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
        points = r * np.column_stack([np.cos(angles), np.sin(angles)])
    else:
        points = rng.uniform(0, draw(st.sampled_from([1.0, 10.0, 100.0])) * rho, (n, 2))
    offset = draw(st.sampled_from([0.0, -1e3, 1e5, 1e7, 1e9, 1e12]))
    return points + offset, rho


def plan_or_refuse(name, targets, rho):
    """The planner's tour, checked; or None when it refused with a DtspError."""
    try:
        tour = _planner(name).plan(targets, rho)
    except TilingUnavailable:
        return None
    except InputError as error:
        assert "too large for a turn radius" in str(error), error
        return None
    assert_valid_tour(tour)
    assert tour.length_m >= 2 * math.pi * rho * (1 - 1e-9)
    assert len(tour.targets_m) == len(targets)
    return tour


@pytest.mark.parametrize("name", PLANNERS)
@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
@given(instance=instances())
def test_every_planner_on_adversarial_instances_returns_a_valid_tour_or_refuses(name, instance):
    targets, rho = instance
    plan_or_refuse(name, targets, rho)


# Regression cases the fuzzing found (issue 18), fixed for good.

@pytest.mark.parametrize("spacing_rho, side", [(8, 2), (6, 3), (5, 5)])
@pytest.mark.parametrize("rho", [1.0, 37.0, 100.0])
def test_grids_whose_bead_is_exactly_the_largest_plan(spacing_rho, side, rho):
    g = np.arange(side) * spacing_rho * rho
    targets = np.array([(x, y) for x in g for y in g], dtype=float)
    for name in ("auto", "rbta"):
        assert_valid_tour(_planner(name).plan(targets, rho))


def test_bead_half_length_at_the_boundary_is_the_largest_bead():
    assert bead_half_length(8 * 100.0 ** 2 * 2 * 4, 4, 100.0) == 200.0
    with pytest.raises(TilingUnavailable):
        bead_half_length(8 * 100.0 ** 2 * 2 * 4 * 1.001, 4, 100.0)


def test_targets_nanometres_apart_are_merged_and_reported():
    targets = np.array([[0.0, 0.0], [1e-9, 0.0], [0.0, 1e-9]])
    for name in PLANNERS:
        if name == "rbta":
            continue
        tour = _planner(name).plan(targets, 80.0)
        assert_valid_tour(tour)
        assert tour.length_m == pytest.approx(2 * math.pi * 80.0)
        assert tour.report["merged_targets"] == 2


def test_the_checker_rejects_a_closed_tour_shorter_than_a_circle():
    targets = np.array([[0.0, 0.0], [1e-9, 0.0], [0.0, 1e-9]])
    tour = tour_through_poses(targets, np.arange(3), np.zeros(3), 80.0)
    report = check_tour(tour)
    assert not report.ok
    assert any("at least 2 pi rho" in p for p in report.problems)
    with pytest.raises(TourInvalidError):
        report.raise_if_invalid()


def test_the_checker_rejects_a_leg_shorter_than_its_dubins_distance():
    # A 100 m straight from A to B flown as 1000 pieces, each 0.09 mm short of the next start:
    # every joint is within the tolerance (0.1 mm at rho 100 m), yet A to B is 9 cm shorter
    # than any path between their poses. The return from B to A is an exact Dubins path.
    rho = 100.0
    targets = np.array([[0.0, 0.0], [100.0, 0.0]])
    exact = tour_through_poses(targets, np.arange(2), np.zeros(2), rho)
    back = exact.chain.offsets_m[:-1] >= 100.0 - 1e-9     # the segments of B to A
    pieces = 1000
    starts = np.column_stack([np.arange(pieces) * 0.1, np.zeros(pieces), np.zeros(pieces)])
    chain = SegmentChain(np.vstack([starts, exact.chain.starts[back]]),
                         np.concatenate([np.full(pieces, 0.1 - 9e-5), exact.chain.lengths_m[back]]),
                         np.concatenate([np.zeros(pieces), exact.chain.curvatures_1_m[back]]))
    cheat = Tour(chain, rho, targets, np.array([0.0, pieces * (0.1 - 9e-5)]))
    problems = check_tour(cheat).problems
    assert len(problems) == 1 and "shorter than the exact Dubins distance" in problems[0], problems


@pytest.mark.parametrize("offset, rho", [(1e7, 1e-3), (1e12, 100.0)])
def test_coordinates_double_precision_cannot_hold_are_refused_with_the_reason(offset, rho):
    targets = np.random.default_rng(1).uniform(0, 50 * rho, (20, 2)) + offset
    with pytest.raises(InputError, match="too large for a turn radius"):
        _planner("auto").plan(targets, rho)


@pytest.mark.parametrize("offset, rho", [(3e6, 1e-3), (1e11, 100.0), (1e9, 100.0)])
def test_large_offsets_are_planned_around_the_targets_centre(offset, rho):
    local = np.random.default_rng(2).uniform(0, 50 * rho, (30, 2))
    near = get_planner("headings").plan(local, rho)
    far = get_planner("headings").plan(local + offset, rho)
    assert_valid_tour(far)
    # the same tour, up to the rounding of the offset targets themselves
    assert far.length_m == pytest.approx(near.length_m, rel=1e-5)


# The CLI through the same strategies: exit 0 or 2, never a traceback.

@settings(max_examples=40, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(instance=instances(), algorithm=st.sampled_from(["auto", "rbta", "lanes"]))
def test_the_cli_exits_0_or_2_on_adversarial_instances(tmp_path_factory, instance, algorithm):
    targets, rho = instance
    folder = tmp_path_factory.mktemp("fuzz")
    csv = folder / "t.csv"
    csv.write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in targets))
    result = CliRunner().invoke(cli, ["plan", str(csv), "--radius", repr(rho), "--algorithm",
                                      algorithm, "--time-limit", "0.02", "-o", str(folder / "t.json")])
    assert result.exit_code in (0, 2), result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    if result.exit_code == 0:
        assert (folder / "t.json").exists()
    else:
        assert "Error:" in result.output and not (folder / "t.json").exists()
