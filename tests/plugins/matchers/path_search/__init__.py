"""Tests of path search: its beam (k-best), its exact per-movement search, the matcher."""
