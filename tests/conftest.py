"""Shared test helpers: every tour any test builds goes through the same checker."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import settings

from dtsp_mission.tour import Tour, check_tour

settings.register_profile("ci", deadline=None, derandomize=True, print_blob=True)
settings.load_profile("ci")


def assert_valid_tour(tour: Tour) -> None:
    """Fail with the checker's own list of problems unless ``tour`` is valid."""
    report = check_tour(tour)
    assert report.ok, report.summary() + "\n" + "\n".join(report.problems)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)
