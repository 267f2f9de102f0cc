"""Perception pages' figures and tables: coverage, detection range, single sensor frames."""
