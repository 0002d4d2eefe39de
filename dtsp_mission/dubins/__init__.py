"""Exact shortest Dubins paths, one at a time or in vectorised batches.

``shortest_length(starts, goals, rho_m)`` is the hot entry point of every planner.
"""

from .path import (WORDS, DubinsPath, chain_of_paths, check_radius, shortest_length,
                   shortest_path, shortest_words)

__all__ = ["WORDS", "DubinsPath", "chain_of_paths", "check_radius", "shortest_length", "shortest_path",
           "shortest_words"]
