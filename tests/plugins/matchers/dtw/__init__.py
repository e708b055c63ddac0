"""Tests of the dtw baseline matcher."""
