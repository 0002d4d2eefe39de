"""Benchmarks: measured speed and memory, printed as tables (never asserted in tests)."""
